//! Converged GE stability onset in a steady wind, flutter included
//! (issue 21), on the thesis tether (ρA = 0.078 kg/m, F = 1000 N,
//! m = 10 kg, d = 5 mm, C_n = 1.2, C_D A = 0.9 m², EA = 10⁶ N,
//! EI = 1 N m², solid-section I_ρ), uniform wind, critical payout rate
//! at 1000 m.

use tetherplan::numerics::ge::air_load::AirLoads;
use tetherplan::numerics::ge::element::TipLoad;
use tetherplan::numerics::ge::qs_wind::branch_equilibrium;
use tetherplan::numerics::ge::quasi_static::{
    QsConfig, divergence_indicator, state_at, wind_matrices,
};
use tetherplan::numerics::ge::stability::{StateMotion, spectrum_of};
use tetherplan::numerics::ge::{GeModel, Section, TipBody};
use tetherplan::numerics::params::Kinematics;
use tetherplan::numerics::qep::Spectrum;
use tetherplan::numerics::tether::WindProfile;

const RHO_A: f64 = 0.078;
const F: f64 = 1000.0;
const G: f64 = 9.81;
const D: f64 = 0.005;
const LENGTH: f64 = 1000.0;

fn model(ei: f64, elements: usize) -> GeModel {
    let s = Section::new(1e6, 1e6, ei, RHO_A, RHO_A * D * D / 16.0).unwrap();
    let mut m = GeModel::new(
        s,
        elements,
        TipBody {
            mass_kg: 10.0,
            link_length_m: 0.0,
        },
        G,
    )
    .unwrap();
    m.slow_spectrum = true;
    m
}

fn air(u: f64) -> AirLoads {
    AirLoads {
        wind: WindProfile::uniform(u),
        air_density_kg_m3: 1.225,
        cable_diameter_m: D,
        cable_normal_drag_coefficient: 1.2,
        aerostat_drag_area_m2: 0.9,
        aerostat_lift_area_m2: 0.0,
    }
}

fn load() -> TipLoad {
    TipLoad {
        force_n: [F, 0.0],
        moment_n_m: 0.0,
    }
}

fn kin(rate: f64) -> Kinematics {
    Kinematics {
        length_m: LENGTH,
        rate_m_s: rate,
        acceleration_m_s2: 0.0,
    }
}

/// The dense QEP at `rate` on the branch (Newton from `near`): the
/// spectrum, the equilibrium, and the det K parity.
fn dense_at(
    m: &GeModel,
    a: &AirLoads,
    rate: f64,
    near: Option<&[f64]>,
) -> (Spectrum, Vec<f64>, usize) {
    let q = branch_equilibrium(m, kin(rate), load(), a, &QsConfig::default(), near)
        .unwrap_or_else(|| panic!("no branch state at {rate} m/s ({} elements)", m.elements));
    let c = divergence_indicator(m, kin(rate), load(), a, &q).map_or(7, |x| x.0);
    let st = state_at(m, kin(rate), load(), a, StateMotion::AtRest, q.clone()).unwrap();
    let s = spectrum_of(m, wind_matrices(m, kin(rate), load(), a, &st)).unwrap();
    (s, q, c)
}

fn unstable(s: &Spectrum) -> bool {
    s.max_real > s.tolerance()
}

/// Along the rate at 1000 m, on the branch continued in the rate (4 %
/// steps from 1 m/s, then 2 m/s steps from `lo`): the first rate at
/// which the dense QEP is unstable (bisected to 10⁻⁶, with the crossing
/// `|Im λ|` and det K parity), `None` up to `hi` or the end of the
/// branch; and the rate at which the aerostat has come down by 5 % of
/// its low-rate altitude (the blow-down of the imperfect bifurcation).
fn dense_onset(
    m: &GeModel,
    a: &AirLoads,
    (lo, step, hi): (f64, f64, f64),
) -> (Option<(f64, f64, usize)>, Option<f64>, f64) {
    let mut q = branch_equilibrium(m, kin(1.0), load(), a, &QsConfig::default(), None).unwrap();
    let z0 = LENGTH + tetherplan::numerics::ge::element::node(&q, m.elements)[0];
    let mut v = 1.0;
    while v < lo {
        v = (v * 1.04).min(lo);
        q = branch_equilibrium(m, kin(v), load(), a, &QsConfig::default(), Some(&q))
            .unwrap_or_else(|| panic!("no branch state at {v} m/s"));
    }
    let (s0, q0, _) = dense_at(m, a, lo, Some(&q));
    q = q0;
    assert!(!unstable(&s0));
    let mut collapse = None;
    let bad = loop {
        let w = v + step;
        if w > hi {
            return (None, collapse, v);
        }
        let Some(qq) = branch_equilibrium(m, kin(w), load(), a, &QsConfig::default(), Some(&q))
        else {
            return (None, collapse, v);
        };
        let (s, qq, _) = dense_at(m, a, w, Some(&qq));
        let z = LENGTH + tetherplan::numerics::ge::element::node(&qq, m.elements)[0];
        if collapse.is_none() && z < 0.95 * z0 {
            collapse = Some(w);
        }
        if unstable(&s) {
            break w;
        }
        (v, q) = (w, qq);
    };
    let (mut x, mut y) = (v, bad);
    let mut last = None;
    while y - x > 1e-6 * y {
        let mid = 0.5 * (x + y);
        let (s, qq, c) = dense_at(m, a, mid, Some(&q));
        if unstable(&s) {
            y = mid;
            let e = s
                .eigenvalues
                .iter()
                .copied()
                .max_by(|p, r| p.re.total_cmp(&r.re))
                .unwrap();
            last = Some((e.im.abs(), c));
        } else {
            (x, q) = (mid, qq);
        }
    }
    let (w, c) = last.unwrap_or((f64::NAN, 9));
    (Some((0.5 * (x + y), w, c)), collapse, y)
}

#[test]
#[ignore = "measurement (dense QEP on 20 … 80 elements): run with --ignored --nocapture"]
fn measure_dense_onsets() {
    for u in [8.0, 2.0, 0.5, 0.1] {
        let a = air(u);
        for n in [20, 40, 80] {
            let t = std::time::Instant::now();
            let (o, collapse, end) = dense_onset(&model(1.0, n), &a, (30.0, 1.0, 190.0));
            eprintln!(
                "U = {u} m/s, {n} elements: QEP onset (rate, |Im λ|, det parity) {o:?}, \
                 altitude −5 % at {collapse:?} m/s, searched to {end:.2} m/s ({:.1} s)",
                t.elapsed().as_secs_f64()
            );
        }
    }
}

#[test]
#[ignore = "measurement: the scan along the rate on 20 elements"]
fn measure_scan() {
    for u in [8.0, 2.0] {
        let a = air(u);
        let m = model(1.0, 20);
        let mut q =
            branch_equilibrium(&m, kin(1.0), load(), &a, &QsConfig::default(), None).unwrap();
        let mut v: f64 = 1.0;
        while v < 190.0 {
            v = (v * 1.04).min(190.0);
            let Some(qq) =
                branch_equilibrium(&m, kin(v), load(), &a, &QsConfig::default(), Some(&q))
            else {
                eprintln!("U = {u}: no branch state at {v:.2} m/s");
                break;
            };
            q = qq;
            let (s, _, c) = dense_at(&m, &a, v, Some(&q));
            let e = s
                .eigenvalues
                .iter()
                .copied()
                .max_by(|p, r| p.re.total_cmp(&r.re))
                .unwrap();
            let t = m.elements;
            let top = tetherplan::numerics::ge::element::node(&q, t);
            eprintln!(
                "U = {u}, {v:7.2} m/s: max Re {:+.3e} (Im {:.4}), tol {:.1e}, det parity {c}, tip ({:.1}, {:.1})",
                e.re,
                e.im,
                s.tolerance(),
                LENGTH + top[0],
                top[1]
            );
        }
    }
}

/// The base mesh's earlier flutter figure (59.58 m/s at 8 m/s wind): the
/// QEP search of `qs_critical` (plain Newton from the continuum start,
/// then from the previous state) against the branch continued in rate.
#[test]
#[ignore = "measurement: where the 20-element flutter figure came from"]
fn measure_old_flutter_state() {
    use tetherplan::numerics::ge::qs_critical::{QsSearchConfig, critical_rate_from};
    use tetherplan::numerics::ge::qs_wind::{continuum_start, on_branch};
    use tetherplan::numerics::ge::quasi_static::wind_equilibrium;
    let a = air(8.0);
    let m = model(1.0, 20);
    let (start, tip) = continuum_start(&m, &a, F, LENGTH).unwrap();
    let s = critical_rate_from(
        &m,
        F,
        &a,
        LENGTH,
        150.0,
        StateMotion::AtRest,
        &QsSearchConfig::default(),
        &|| false,
        Some(&start),
    )
    .unwrap();
    eprintln!(
        "qs_critical rate search: {:?}, divergence {}",
        s.onset, s.divergence
    );
    if let tetherplan::numerics::ge::qs_critical::QsOnset::During { at } = s.onset {
        let q = wind_equilibrium(&m, kin(at), load(), &a, &QsConfig::default(), Some(&start))
            .unwrap()
            .q;
        let top = tetherplan::numerics::ge::element::node(&q, 20);
        eprintln!(
            "plain Newton from the continuum start at {at:.3} m/s: on branch {}, tip ({:.1}, {:.1}) vs continuum ({:.1}, {:.1})",
            on_branch(&m, LENGTH, &q, tip),
            LENGTH + top[0],
            top[1],
            tip[0],
            tip[1]
        );
    }
}

/// The matrices of the state at `rate` on the branch continued from 1 m/s.
fn matrices_at(
    m: &GeModel,
    a: &AirLoads,
    rate: f64,
) -> tetherplan::numerics::ge::solver::SystemMatrices {
    let mut q = branch_equilibrium(m, kin(1.0), load(), a, &QsConfig::default(), None).unwrap();
    let mut v = 1.0;
    while v < rate {
        v = (v * 1.04).min(rate);
        q = branch_equilibrium(m, kin(v), load(), a, &QsConfig::default(), Some(&q)).unwrap();
    }
    let st = state_at(m, kin(rate), load(), a, StateMotion::AtRest, q).unwrap();
    wind_matrices(m, kin(rate), load(), a, &st)
}

/// The tracked eigenvalue (Newton on the eigenpair, complex band LU,
/// O(n)) equals the dense QEP's (companion, faer) on 20 and 40 elements:
/// the three least damped pairs, started 10⁻⁴ off, to 10⁻⁷ of `|λ|`,
/// with a residual `‖T(λ)x‖/‖T‖` below the dense pair's (measured:
/// 10⁻¹⁸ against 10⁻¹² … 10⁻¹⁰; the dense `Re λ` is off by up to
/// 1.6·10⁻⁶ 1/s, more than its stability tolerance 2.5·10⁻⁷ 1/s); and on
/// 40 elements the fundamental from the 20-element one prolonged.
#[test]
fn tracked_eigenvalue_equals_the_dense_one() {
    use tetherplan::numerics::ge::qs_flutter::{C64, prolong_vector, refine_eigenpair, residual};
    let a = air(8.0);
    let mut coarse: Option<(C64, Vec<C64>)> = None;
    for n in [20, 40] {
        let m = model(1.0, n);
        let sys = matrices_at(&m, &a, 20.0);
        let copy = tetherplan::numerics::ge::solver::SystemMatrices {
            mass: sys.mass.clone(),
            damping: sys.damping.clone(),
            stiffness: sys.stiffness.clone(),
        };
        let dense = spectrum_of(&m, copy).unwrap();
        let mut modes: Vec<_> = dense
            .eigenvalues
            .iter()
            .copied()
            .filter(|e| e.im > 0.0)
            .collect();
        modes.sort_by(|p, r| r.re.total_cmp(&p.re));
        for e in modes.iter().take(3) {
            let start = C64::new(e.re, e.im) * C64::new(1.0 + 1e-4, 1e-4);
            let p = refine_eigenpair(&sys, start, None).expect("no pair");
            let near = dense
                .eigenvalues
                .iter()
                .map(|d| (C64::new(d.re, d.im) - p.lambda).norm())
                .fold(f64::INFINITY, f64::min);
            // the dense pair's residual (its vector by inverse iteration at its λ)
            let lu =
                tetherplan::numerics::ge::qs_flutter::ComplexBand::qep(&sys, C64::new(e.re, e.im))
                    .factor()
                    .unwrap();
            let mut x: Vec<C64> = (0..m.dofs())
                .map(|i| C64::new(1.0, (i as f64).sin()))
                .collect();
            for _ in 0..3 {
                lu.solve_in_place(&mut x);
                let s = x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
                x.iter_mut().for_each(|z| *z /= s);
            }
            let dense_residual = residual(
                &sys,
                &tetherplan::numerics::ge::qs_flutter::EigenPair {
                    lambda: C64::new(e.re, e.im),
                    vector: x,
                },
            );
            eprintln!(
                "{n} elements: tracked {:.10} (residual {:.1e}), dense {:.10}+{:.10}i (residual {dense_residual:.1e})",
                p.lambda,
                residual(&sys, &p),
                e.re,
                e.im
            );
            assert!(residual(&sys, &p) <= dense_residual.max(1e-13));
            assert!(
                (p.lambda - C64::new(e.re, e.im)).norm() <= 1e-7 * e.abs(),
                "{n}: tracked {} vs dense {e:?} (nearest dense {near:e})",
                p.lambda
            );
        }
        // the fundamental (the slowest oscillation) from mesh to mesh
        let lead = dense
            .eigenvalues
            .iter()
            .copied()
            .filter(|e| e.im > 1e-6)
            .min_by(|p, r| p.im.total_cmp(&r.im))
            .unwrap();
        if let Some((lambda, x)) = coarse.take() {
            let x: Vec<C64> = prolong_vector(&x, n / 2);
            let p = refine_eigenpair(&sys, lambda, Some(&x)).unwrap();
            assert!(
                (p.lambda - C64::new(lead.re, lead.im)).norm() <= 1e-7 * lead.abs() + 1e-6,
                "prolonged: {} vs {lead:?}",
                p.lambda
            );
        }
        let p = refine_eigenpair(&sys, C64::new(lead.re, lead.im), None)
            .unwrap_or_else(|| panic!("{n}: no pair at the fundamental {lead:?}"));
        coarse = Some((p.lambda, p.vector));
    }
}

/// What the converged search of `qs_converged` answers today for the
/// critical rate at 1000 m (divergence levels, base-mesh QEP check).
#[test]
#[ignore = "measurement: the converged rate search in wind"]
fn measure_converged_rate_search() {
    use tetherplan::numerics::ge::qs_converged::{ConvergenceConfig, converged_critical_rate};
    for u in [8.0, 2.0, 0.5, 0.1] {
        let c = converged_critical_rate(
            &model(1.0, 20),
            F,
            &air(u),
            LENGTH,
            150.0,
            &ConvergenceConfig {
                tracked_wind_onset: true,
                ..Default::default()
            },
            &|| false,
            None,
        )
        .unwrap();
        eprintln!("U = {u} m/s: {:?}\n    flutter {:?}", c.outcome, c.flutter);
    }
}

fn wind_rate(
    u: f64,
    config: &tetherplan::numerics::ge::qs_converged::ConvergenceConfig,
) -> tetherplan::numerics::ge::qs_converged::ConvergedSearch {
    tetherplan::numerics::ge::qs_converged::converged_critical_rate(
        &model(1.0, 20),
        F,
        &air(u),
        LENGTH,
        150.0,
        &tetherplan::numerics::ge::qs_converged::ConvergenceConfig {
            tracked_wind_onset: true,
            ..*config
        },
        &|| false,
        None,
    )
    .unwrap()
}

/// Wind → 0 (0.1 m/s): the converged wind onset (uniform meshes, the
/// tracked critical eigenvalue, continued in the rate) is a divergence
/// between the string's criterion (54.87 m/s) and the calm-air converged
/// GE onset (graded meshes, inertia of K: 55.181 ± 0.005 m/s); the
/// estimate at each level bounds its distance from the calm limit; the
/// safe value is below every level. Measured: 58.537 / 56.822 / 56.121 /
/// 55.625 / 55.364 m/s at 20 … 320 elements, 55.103 ± 0.026 m/s (order
/// 0.93); at 0.05 m/s 55.111 ± 0.015 (1280 elements); at 0.02 m/s the
/// levels wander (56.79 / 56.69 / 56.59 / 56.41 / 56.49 m/s at 40 … 640).
#[test]
fn near_calm_wind_meets_the_calm_onset() {
    use tetherplan::numerics::ge::qs_converged::{
        ConvergedOutcome, ConvergenceConfig, OnsetKind, converged_critical_rate,
    };
    let c = wind_rate(0.1, &ConvergenceConfig::default());
    let ConvergedOutcome::During(w) = c.outcome else {
        panic!("{:?}", c.outcome)
    };
    let calm = converged_critical_rate(
        &model(1.0, 20),
        F,
        &AirLoads::calm(),
        LENGTH,
        150.0,
        &ConvergenceConfig::default(),
        &|| false,
        None,
    )
    .unwrap();
    let ConvergedOutcome::During(k) = calm.outcome else {
        panic!("{:?}", calm.outcome)
    };
    eprintln!(
        "0.1 m/s: {:.4} ± {:.4} (safe {:.4}, {:?}) levels {:?}; calm {:.4} ± {:.4}",
        w.value, w.error_estimate, w.safe_value, w.kind, w.levels, k.value, k.error_estimate
    );
    assert!(w.converged && w.kind == OnsetKind::Divergence);
    assert!(w.frequency_rad_s.is_none());
    // Between the string's `√(T_guide/ρA)` (T_guide = F − ρA g L) and the
    // calm GE onset: the uniform levels (h = 3 m at 320 elements) do not
    // resolve the bending layer `(EI/ρA g)^(1/3)` = 1.1 m, so the
    // extrapolation misses part of the bending lift (module docs of
    // `qs_converged`): on the safe side of the calm onset.
    let string = ((F - RHO_A * G * LENGTH) / RHO_A).sqrt();
    assert!(
        w.value - w.error_estimate >= string && w.value <= k.value + k.error_estimate,
        "{} ± {} vs string {string}, calm {} ± {}",
        w.value,
        w.error_estimate,
        k.value,
        k.error_estimate
    );
    assert!(w.safe_value <= k.safe_value);
    for &(n, r) in &w.levels {
        assert!(w.safe_value <= r, "{n}: safe {} above {r}", w.safe_value);
        assert!(
            w.error_at(r) + w.error_estimate >= (r - k.value).abs(),
            "{n}: estimate {} below the true error {}",
            w.error_at(r),
            (r - k.value).abs()
        );
    }
    // first order from above, as in calm air
    for p in w.levels.windows(2) {
        assert!(p[1].1 < p[0].1, "{:?}", w.levels);
    }
}

/// In 2 m/s the levels (the tracked real eigenvalue's limit point on the
/// blown-down branch: 115.92 / 114.87 / 122.76 m/s at 20 / 40 / 80
/// elements) disagree by more than the tolerance: the search says so
/// (`converged: false`) and its safe value is below every level.
#[test]
fn disagreeing_wind_levels_are_not_converged() {
    use tetherplan::numerics::ge::qs_converged::{ConvergedOutcome, ConvergenceConfig};
    let c = wind_rate(
        2.0,
        &ConvergenceConfig {
            max_elements: 80,
            ..Default::default()
        },
    );
    let ConvergedOutcome::During(o) = c.outcome else {
        panic!("{:?}", c.outcome)
    };
    eprintln!("2 m/s: {o:?}");
    let (lo, hi) = o
        .levels
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |m, l| {
            (m.0.min(l.1), m.1.max(l.1))
        });
    assert!(hi - lo > 1e-3 * lo, "{:?}", o.levels);
    assert!(!o.converged);
    assert!(o.safe_value <= lo);
}
