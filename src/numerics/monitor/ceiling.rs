//! The payout-rate check's reference: the stability ceiling at the current
//! tether length in the measured wind, by the plan's own criterion
//! ([`crate::numerics::plan::air`]: `T_eff(L, v, 0) ≥ ε(1 − r)F` with the
//! aerostat's ascent drag). One equilibrium costs far more than the 20 µs
//! the monitor may spend on a sample, so the edge evaluates the criterion
//! once per flight on a grid of lengths × wind speeds and the monitor
//! interpolates it ([`CeilingTable`], bilinear). Any other source can
//! stand in through [`RateCeiling`].

/// The largest stable payout rate at a length in a measured wind.
pub trait RateCeiling {
    /// The ceiling (m/s, ≥ 0) at `length_m` with the wind measured at
    /// the anemometer `wind_m_s`.
    fn ceiling_m_s(&self, length_m: f64, wind_m_s: f64) -> f64;
}

/// Ceilings on a grid of lengths × wind speeds, interpolated bilinearly;
/// outside the grid the nearest edge (the edge must therefore cover the
/// flight: lengths from 0 to beyond the target, winds to beyond the
/// operating limits, where the wind check has stopped the flight already).
#[derive(Clone, Debug, PartialEq)]
pub struct CeilingTable {
    lengths_m: Vec<f64>,
    winds_m_s: Vec<f64>,
    /// Row-major: `ceilings[i * winds.len() + j]` at `(lengths[i], winds[j])`.
    ceilings_m_s: Vec<f64>,
}

/// Why a table cannot be built.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TableError(pub &'static str);

fn increasing(x: &[f64]) -> bool {
    !x.is_empty() && x.iter().all(|v| v.is_finite()) && x.windows(2).all(|w| w[0] < w[1])
}

impl CeilingTable {
    pub fn new(
        lengths_m: Vec<f64>,
        winds_m_s: Vec<f64>,
        ceilings_m_s: Vec<f64>,
    ) -> Result<Self, TableError> {
        if !increasing(&lengths_m) || !increasing(&winds_m_s) {
            return Err(TableError("grid axes must be finite and increasing"));
        }
        if ceilings_m_s.len() != lengths_m.len() * winds_m_s.len() {
            return Err(TableError("one ceiling per grid point"));
        }
        if ceilings_m_s.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(TableError("ceilings must be finite and non-negative"));
        }
        Ok(Self {
            lengths_m,
            winds_m_s,
            ceilings_m_s,
        })
    }

    /// Builds the table by evaluating `f(length, wind)` at every point.
    pub fn tabulate(
        lengths_m: Vec<f64>,
        winds_m_s: Vec<f64>,
        f: impl Fn(f64, f64) -> f64,
    ) -> Result<Self, TableError> {
        let mut c = Vec::with_capacity(lengths_m.len() * winds_m_s.len());
        for &l in &lengths_m {
            for &w in &winds_m_s {
                c.push(f(l, w).max(0.0));
            }
        }
        Self::new(lengths_m, winds_m_s, c)
    }

    pub fn lengths_m(&self) -> &[f64] {
        &self.lengths_m
    }

    pub fn winds_m_s(&self) -> &[f64] {
        &self.winds_m_s
    }

    pub fn ceilings_m_s(&self) -> &[f64] {
        &self.ceilings_m_s
    }
}

/// The cell `i` with `x[i] ≤ v ≤ x[i + 1]` and the weight of `x[i + 1]`,
/// clamped to the ends.
fn locate(x: &[f64], v: f64) -> (usize, f64) {
    if x.len() == 1 || !(v > x[0]) {
        return (0, 0.0);
    }
    let last = x.len() - 1;
    if v >= x[last] {
        return (last - 1, 1.0);
    }
    let i = x.partition_point(|&xi| xi <= v) - 1;
    (i, (v - x[i]) / (x[i + 1] - x[i]))
}

impl RateCeiling for CeilingTable {
    fn ceiling_m_s(&self, length_m: f64, wind_m_s: f64) -> f64 {
        let nw = self.winds_m_s.len();
        let (i, a) = locate(&self.lengths_m, length_m);
        let (j, b) = locate(&self.winds_m_s, wind_m_s);
        let at = |i: usize, j: usize| {
            let i = i.min(self.lengths_m.len() - 1);
            let j = j.min(nw - 1);
            self.ceilings_m_s[i * nw + j]
        };
        (1.0 - a) * ((1.0 - b) * at(i, j) + b * at(i, j + 1))
            + a * ((1.0 - b) * at(i + 1, j) + b * at(i + 1, j + 1))
    }
}
