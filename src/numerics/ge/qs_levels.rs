//! The converged quasi-static onset's settings and answers, and the
//! arithmetic of its nested mesh levels (the levels' root tolerance,
//! prolongation of a state to the next level, Richardson on first-order
//! levels, the summary of the roots): shared by the divergence search of
//! [`super::qs_converged`] and the tracked wind onset of
//! [`super::qs_wind_onset`], below both.

use super::GeModel;
use super::element::node;
use super::qs_critical::{OnsetState, QsOnset};
use crate::numerics::params::InvalidInput;

/// Relative tolerance of a converged onset unless the caller asks another.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-3;
/// Tightest and loosest tolerances accepted.
pub const MIN_RELATIVE_TOLERANCE: f64 = 1e-6;
pub const MAX_RELATIVE_TOLERANCE: f64 = 0.05;
/// Elements of the coarsest mesh.
pub const BASE_ELEMENTS: usize = 20;
/// Finest mesh of a converged search.
pub const MAX_CONVERGED_ELEMENTS: usize = 1280;
/// How near (relative) a known equilibrium must be to start a Newton from
/// it in wind (see `Level::equilibrium`).
pub const NEAR: f64 = 0.05;
/// Loosest relative width of a level's root ([`level_rtol`]).
pub const ROOT_RTOL: f64 = 1e-7;

/// Settings of a converged search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConvergenceConfig {
    pub relative_tolerance: f64,
    pub base_elements: usize,
    pub max_elements: usize,
    /// In wind: the first of divergence and flutter on every level
    /// ([`super::qs_wind_onset`]). Off: the divergence alone (a caller
    /// that checks flutter elsewhere, as the plan's schedule check does).
    pub qep_in_wind: bool,
    /// In calm air: meshes graded toward the guide, sized by the closed
    /// form's bending layer ([`calm_guess`]), and the closed form's root
    /// as the base level's first guess. Off: uniform meshes (as in wind).
    pub graded_in_calm_air: bool,
    /// In wind with `qep_in_wind`: the converged first of divergence and
    /// flutter of [`super::qs_wind_onset`] (off by default: a length
    /// search in 10 m/s costs 2.6 s there against 34–45 ms, the states
    /// continued along the whole range on every level); off: the
    /// divergence levels and the base mesh's QEP check.
    pub tracked_wind_onset: bool,
}

impl Default for ConvergenceConfig {
    fn default() -> Self {
        Self {
            relative_tolerance: DEFAULT_RELATIVE_TOLERANCE,
            base_elements: BASE_ELEMENTS,
            max_elements: MAX_CONVERGED_ELEMENTS,
            qep_in_wind: true,
            graded_in_calm_air: true,
            tracked_wind_onset: false,
        }
    }
}

impl ConvergenceConfig {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        if !(MIN_RELATIVE_TOLERANCE..=MAX_RELATIVE_TOLERANCE).contains(&self.relative_tolerance) {
            return Err(InvalidInput::new(
                "stability.relative_tolerance_nondim",
                format!(
                    "must be between {MIN_RELATIVE_TOLERANCE} and {MAX_RELATIVE_TOLERANCE}, got {}",
                    self.relative_tolerance
                ),
            ));
        }
        if self.base_elements < 2 || self.max_elements < 4 * self.base_elements {
            return Err(InvalidInput::new(
                "stability.elements",
                format!(
                    "the converged search needs at least 2 base elements and 3 levels, got {} to {}",
                    self.base_elements, self.max_elements
                ),
            ));
        }
        Ok(())
    }
}

impl ConvergenceConfig {
    /// The converged search a request asks for: none when it gives a mesh
    /// (`elements_given`), else one to `relative_tolerance` (default
    /// [`DEFAULT_RELATIVE_TOLERANCE`]); a tolerance beside a mesh is
    /// refused (the fields are `stability.elements` and
    /// `stability.relative_tolerance_nondim`).
    pub fn requested(
        elements_given: bool,
        relative_tolerance: Option<f64>,
    ) -> Result<Option<Self>, InvalidInput> {
        match (elements_given, relative_tolerance) {
            (true, Some(_)) => Err(InvalidInput::new(
                "stability.relative_tolerance_nondim",
                "applies to converged answers only: omit stability.elements to converge them",
            )),
            (true, None) => Ok(None),
            (false, tol) => {
                let c = Self {
                    relative_tolerance: tol.unwrap_or(DEFAULT_RELATIVE_TOLERANCE),
                    ..Self::default()
                };
                c.validate()?;
                Ok(Some(c))
            }
        }
    }
}

/// A converged onset (length in m, or rate in m/s).
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergedOnset {
    /// Best estimate of the continuum value (Richardson).
    pub value: f64,
    /// Estimated bound on `|value − continuum value|` (≥ 0).
    pub error_estimate: f64,
    /// The safe side: `value − error_estimate`, and at most the lowest root.
    pub safe_value: f64,
    /// Whether the tolerance was met within the finest mesh.
    pub converged: bool,
    /// Observed order of the last three levels (NaN with fewer).
    pub order: f64,
    /// `(elements, divergence root)` per level.
    pub levels: Vec<(usize, f64)>,
    /// Length on `ζ` of each level's element at the guide (`1/n` on a
    /// uniform mesh, less on a graded one).
    pub first_elements: Vec<f64>,
    /// The equilibrium at the safe value on the finest mesh.
    pub at_safe: OnsetState,
    /// Which eigenvalue crosses: a real one (divergence, always in calm
    /// air) or a complex pair (flutter, in wind).
    pub kind: OnsetKind,
    /// For a flutter onset, the crossing frequency `|Im λ|` on the finest
    /// level (rad/s).
    pub frequency_rad_s: Option<f64>,
}

/// The kind of a converged onset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnsetKind {
    Divergence,
    Flutter,
}

impl ConvergedOnset {
    /// The error estimate of the root on an `elements` mesh: its distance
    /// above the safe value (FE roots converge from above), 0 below it.
    pub fn error_at(&self, root: f64) -> f64 {
        (root - self.safe_value).max(0.0)
    }
}

/// The outcome of a converged search.
#[derive(Clone, Debug, PartialEq)]
pub enum ConvergedOutcome {
    /// First unstable at the converged onset.
    During(ConvergedOnset),
    /// Unstable at the lower end of the range on the base mesh.
    Immediate,
    /// Stable up to the upper end on every level searched.
    Never { up_to: f64 },
    /// No equilibrium (or stiffness) at the lower end.
    Failed { at: f64 },
    /// Stopped by the caller.
    Cancelled,
}

/// A converged search and, in wind, the base mesh's QEP search.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergedSearch {
    pub outcome: ConvergedOutcome,
    /// In wind without [`ConvergenceConfig::tracked_wind_onset`]: the
    /// base-mesh QEP onset when it is not the divergence (a flutter onset
    /// first, or no onset found by the QEP); `None` in calm air, when
    /// confirmed, or with the tracked search (its `outcome` is the first
    /// of divergence and flutter on every level).
    pub flutter: Option<QsOnset>,
    pub equilibria: usize,
}

/// Relative width of each level's root at a relative tolerance `tol`:
/// Richardson weighs the roots by at most 6 in its error estimate, so
/// `10⁻⁴ tol` keeps the roots' own error out of it (at most
/// [`ROOT_RTOL`], at least `10⁻¹²`).
pub fn level_rtol(tol: f64) -> f64 {
    (1e-4 * tol).clamp(1e-12, ROOT_RTOL)
}

/// Coarse nodal values linearly interpolated onto the mesh of twice the
/// elements (nested: the coarse nodes are every other fine node).
pub(super) fn prolong(q: &[f64], coarse_elements: usize) -> Vec<f64> {
    let mut out = vec![0.0; 6 * coarse_elements];
    for k in 1..=2 * coarse_elements {
        let v = if k % 2 == 0 {
            node(q, k / 2)
        } else {
            let (a, b) = (node(q, k / 2), node(q, k / 2 + 1));
            [
                0.5 * (a[0] + b[0]),
                0.5 * (a[1] + b[1]),
                0.5 * (a[2] + b[2]),
            ]
        };
        out[GeModel::dof(k, 0)..GeModel::dof(k, 0) + 3].copy_from_slice(&v);
    }
    out
}

/// `model` with `elements` elements ([`GeModel::with_elements`]).
pub fn with_elements(model: &GeModel, elements: usize) -> Result<GeModel, InvalidInput> {
    model.with_elements(elements)
}

/// Richardson on first-order levels: `(value, error, order)` of the last.
pub fn richardson(levels: &[f64]) -> (f64, f64, f64) {
    let k = levels.len();
    match k {
        0 => (f64::NAN, f64::INFINITY, f64::NAN),
        1 => (levels[0], f64::INFINITY, f64::NAN),
        2 => (
            2.0 * levels[1] - levels[0],
            (levels[1] - levels[0]).abs(),
            f64::NAN,
        ),
        _ => {
            let r = |i: usize| 2.0 * levels[i] - levels[i - 1];
            let (q0, q1, q2) = (levels[k - 3], levels[k - 2], levels[k - 1]);
            let order = ((q0 - q1) / (q1 - q2)).log2();
            (r(k - 1), (r(k - 1) - r(k - 2)).abs(), order)
        }
    }
}

pub(super) fn summarise(
    roots: &[(usize, f64)],
    config: &ConvergenceConfig,
    met: bool,
) -> ConvergedOnset {
    let values: Vec<f64> = roots.iter().map(|r| r.1).collect();
    let (value, err, order) = richardson(&values);
    let finest = *values.last().unwrap_or(&f64::NAN);
    // With fewer than three levels the estimate is the last step.
    let err = if err.is_finite() {
        err
    } else {
        finest.abs() * config.relative_tolerance.max(0.05)
    };
    // At most the lowest root (the finest, when the levels fall as in calm air).
    let lowest = values.iter().copied().fold(finest, f64::min);
    ConvergedOnset {
        value,
        error_estimate: err,
        safe_value: (value - err).min(lowest),
        converged: met,
        order,
        levels: roots.to_vec(),
        at_safe: OnsetState::default(),
        first_elements: Vec::new(),
        kind: OnsetKind::Divergence,
        frequency_rad_s: None,
    }
}
