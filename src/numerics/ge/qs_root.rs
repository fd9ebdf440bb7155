//! The divergence root along one parameter (a tether length or a payout
//! rate), shared by the quasi-static GE searches ([`super::qs_critical`],
//! [`super::qs_converged`]): an even scan for the first point whose
//! stiffness inertia differs from the lower end's ([`scan_change`]), and
//! the root in that bracket by Illinois regula falsi on `det K`,
//! safeguarded by the count and by bisection ([`refine_root`]).

/// Cap on bisection steps of either kind (here and in the QEP verdict's
/// bisection of [`super::qs_critical`]).
pub(super) const MAX_BISECTIONS: usize = 200;

/// The end of an even scan of `(lo, hi]`.
pub(super) enum Scan {
    /// `(last point like the lower end, first point not like it)`;
    /// `failed`: the second point had no state at all.
    Bracket {
        a: f64,
        b: f64,
        failed: bool,
    },
    /// Like the lower end up to `hi`.
    Unchanged,
    Cancelled,
}

/// Scans `(lo, hi]` at `n` even steps for the first point where `like`
/// (like the lower end: `Some(true)`, not: `Some(false)`, no state: `None`)
/// is not `Some(true)`.
pub(super) fn scan_change(
    (lo, hi): (f64, f64),
    n: usize,
    mut like: impl FnMut(f64) -> Option<bool>,
    cancel: &dyn Fn() -> bool,
) -> Scan {
    let mut prev = lo;
    for k in 1..=n {
        if cancel() {
            return Scan::Cancelled;
        }
        let p = lo + (hi - lo) * k as f64 / n as f64;
        match like(p) {
            Some(true) => prev = p,
            other => {
                return Scan::Bracket {
                    a: prev,
                    b: p,
                    failed: other.is_none(),
                };
            }
        }
    }
    Scan::Unchanged
}

/// The divergence root between `a` (the lower-end count, `fa = (count,
/// ln |det|)`) and `b` (another count, `fb`) to relative width `rtol`:
/// Illinois regula falsi on the determinant `(−1)^count exp(ln |det|)`
/// (smooth through a simple root), safeguarded by the count (the bracket
/// keeps the lower-end count at `a` only) and by bisection when the
/// determinant does not change sign. `eval` gives the indicator of a
/// state; the final bracket, `None` when cancelled.
pub(super) fn refine_root(
    (mut a, mut b): (f64, f64),
    (ia, ib): (Option<(usize, f64)>, Option<(usize, f64)>),
    rtol: f64,
    mut eval: impl FnMut(f64) -> Option<(usize, f64)>,
    cancel: &dyn Fn() -> bool,
) -> Option<(f64, f64)> {
    let c_a = ia.map(|x| x.0);
    let reference = ia.map_or(0.0, |x| x.1);
    let signed = |x: Option<(usize, f64)>| -> f64 {
        match x {
            Some((c, ld)) => {
                let mag = (ld - reference).clamp(-700.0, 700.0).exp();
                if c % 2 == 0 { mag } else { -mag }
            }
            None => f64::NAN,
        }
    };
    let tol = rtol * b.abs().max(a.abs()).max(1e-300);
    let (mut fa, mut fb) = (signed(ia), signed(ib));
    let mut side = 0i8;
    for _ in 0..MAX_BISECTIONS {
        let w = b - a;
        if w <= tol {
            break;
        }
        if cancel() {
            return None;
        }
        let mut m = if fa * fb < 0.0 && fa.is_finite() && fb.is_finite() {
            (a * fb - b * fa) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        if !(m > a && m < b) {
            m = 0.5 * (a + b);
        }
        // keep off the ends so that the bracket closes
        let eps = 0.5 * tol;
        if m - a < eps {
            m = a + eps.min(0.5 * w);
        } else if b - m < eps {
            m = b - eps.min(0.5 * w);
        }
        let im = eval(m);
        let fm = signed(im);
        if c_a.is_some() && im.map(|x| x.0) == c_a {
            a = m;
            fa = fm;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = m;
            fb = fm;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    Some((a, b))
}
