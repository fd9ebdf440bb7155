//! The nested-mesh ladder of the linear string's converged answers: the
//! graded mesh families (toward the roller, and at the roller for a
//! constant rate), the values of their levels, Richardson extrapolation of
//! the known first order with its error estimate and observed order
//! ([`Ladder`]), and the refinement loop that stops at the tolerance in the
//! asymptotic range ([`climb`]). The answers built on it are in
//! [`super::converged`].

use std::sync::{Arc, Mutex, OnceLock};

use crate::numerics::mesh::Mesh;
use crate::numerics::params::InvalidInput;
use crate::numerics::string::operators::StringOperators;

/// Relative tolerance of a converged answer unless the caller asks another.
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-4;
/// Tightest and loosest relative tolerances accepted.
pub const MIN_RELATIVE_TOLERANCE: f64 = 1e-8;
pub const MAX_RELATIVE_TOLERANCE: f64 = 1e-2;
/// Elements of the graded meshes away from the roller.
pub const BULK_ELEMENTS: usize = 16;
/// Most refinement levels (first element `2^-40/16 ≈ 6e-14`).
pub const MAX_LEVELS: usize = 40;
/// Relative floor of an error estimate: the bisections stop at 1e-12.
const ERROR_FLOOR: f64 = 1e-11;

/// A converged scalar: the extrapolated value, its estimated error and how
/// it was reached.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Converged {
    /// Best estimate of the continuum value.
    pub value: f64,
    /// Estimated bound on `|value − continuum value|` (≥ 0).
    pub error_estimate: f64,
    /// Elements of the finest mesh used.
    pub elements: usize,
    /// Observed order of convergence in the first-element size (NaN if it
    /// could not be measured).
    pub order: f64,
    /// Meshes solved.
    pub levels: usize,
    /// Whether the tolerance was met within [`MAX_LEVELS`].
    pub converged: bool,
}

impl Converged {
    /// `value − error_estimate`.
    pub fn lower(&self) -> f64 {
        self.value - self.error_estimate
    }

    /// `value + error_estimate`.
    pub fn upper(&self) -> f64 {
        self.value + self.error_estimate
    }

    /// `error_estimate / |value|`.
    pub fn relative_error(&self) -> f64 {
        self.error_estimate / self.value.abs()
    }

    /// Maps the value and its error through an increasing affine map
    /// `x ↦ offset + scale·x` (`scale > 0`).
    pub fn affine(&self, offset: f64, scale: f64) -> Self {
        Self {
            value: offset + scale * self.value,
            error_estimate: scale * self.error_estimate,
            ..*self
        }
    }
}

/// Error estimate of a fixed mesh's value against the converged one:
/// `|mesh − converged| + converged error` (the triangle inequality).
pub fn mesh_error_estimate(mesh_value: f64, converged: &Converged) -> f64 {
    (mesh_value - converged.value).abs() + converged.error_estimate
}

/// Checks a relative tolerance against the accepted range.
pub fn validate_tolerance(field: &str, tolerance: f64) -> Result<f64, InvalidInput> {
    if !(MIN_RELATIVE_TOLERANCE..=MAX_RELATIVE_TOLERANCE).contains(&tolerance) {
        return Err(InvalidInput::new(
            field,
            format!(
                "must be between {MIN_RELATIVE_TOLERANCE} and {MAX_RELATIVE_TOLERANCE}, got {tolerance}"
            ),
        ));
    }
    Ok(tolerance)
}

/// Operators of refinement level `level` (shared, built once per process).
pub fn graded_operators(level: usize) -> Arc<StringOperators> {
    static CACHE: OnceLock<Mutex<Vec<Arc<StringOperators>>>> = OnceLock::new();
    level_operators(&CACHE, level, |first| Mesh::graded(first, BULK_ELEMENTS))
}

/// Operators of the two-element mesh `[0, h₁, 1]` with the first element of
/// refinement level `level` ([`Mesh::roller_element`]). For constant-rate
/// lengthening (and the safe rate, and a state of zero acceleration) the
/// pencil is diagonal in the element slopes and the roller element is the
/// critical one, so these give exactly the graded meshes' values at a tenth
/// of the cost (checked in the tests).
pub fn roller_operators(level: usize) -> Arc<StringOperators> {
    static CACHE: OnceLock<Mutex<Vec<Arc<StringOperators>>>> = OnceLock::new();
    level_operators(&CACHE, level, Mesh::roller_element)
}

/// The operators of a family's level from its process-wide cache, the
/// levels up to it built on first use: `mesh(h₁)` with the first element
/// `h₁ = 2^{-k}/BULK_ELEMENTS` of level `k`.
fn level_operators(
    cache: &OnceLock<Mutex<Vec<Arc<StringOperators>>>>,
    level: usize,
    mesh: impl Fn(f64) -> Mesh,
) -> Arc<StringOperators> {
    let cache = cache.get_or_init(|| Mutex::new(Vec::new()));
    let mut levels = cache.lock().unwrap_or_else(|e| e.into_inner());
    while levels.len() <= level {
        let k = levels.len() as i32;
        let first = 0.5f64.powi(k) / BULK_ELEMENTS as f64;
        levels.push(Arc::new(StringOperators::on_mesh(mesh(first))));
    }
    levels[level].clone()
}

/// A family of meshes indexed by refinement level.
pub(super) type Family = fn(usize) -> Arc<StringOperators>;

/// Values on the levels so far, and the estimate they give.
#[derive(Clone, Debug, Default)]
pub struct Ladder {
    /// `q_k`, coarse to fine.
    pub values: Vec<f64>,
    elements: usize,
}

impl Ladder {
    fn push(&mut self, value: f64, elements: usize) {
        self.values.push(value);
        self.elements = elements;
    }

    /// The estimate from the last three levels (fewer: the last value,
    /// with the last difference as the error).
    pub fn estimate(&self, converged: bool) -> Converged {
        let v = &self.values;
        let n = v.len();
        let (value, mut error, order) = match n {
            0 => (f64::NAN, f64::INFINITY, f64::NAN),
            1 => (v[0], f64::INFINITY, f64::NAN),
            2 => (2.0 * v[1] - v[0], (v[1] - v[0]).abs(), f64::NAN),
            _ => {
                let (a, b, c) = (v[n - 3], v[n - 2], v[n - 1]);
                let r = 2.0 * c - b;
                let r_prev = 2.0 * b - a;
                let ratio = (a - b) / (b - c);
                let order = if ratio > 0.0 && ratio.is_finite() {
                    ratio.log2()
                } else {
                    f64::NAN
                };
                (r, (r - r_prev).abs(), order)
            }
        };
        if !converged && n >= 1 {
            // outside the asymptotic range the finest mesh is all we trust
            error = error.max((v[n - 1] - value).abs());
        }
        Converged {
            value,
            error_estimate: error.max(ERROR_FLOOR * value.abs()),
            elements: self.elements,
            order,
            levels: n,
            converged,
        }
    }

    /// Tolerance met, in the asymptotic range?
    fn done(&self, tolerance: f64) -> bool {
        if self.values.len() < 3 {
            return false;
        }
        let e = self.estimate(true);
        let asymptotic = e.order.is_nan() && e.error_estimate <= ERROR_FLOOR * e.value.abs()
            || (0.7..=1.3).contains(&e.order);
        asymptotic && e.error_estimate <= 0.5 * tolerance * e.value.abs()
    }

    /// The coarsest level whose value is within `rel` of the estimate
    /// (the finest level if none is).
    pub(super) fn first_level_within(&self, value: f64, rel: f64) -> usize {
        self.values
            .iter()
            .position(|q| (q - value).abs() <= rel * value.abs())
            .unwrap_or(self.values.len().saturating_sub(1))
    }
}

/// Refines level by level until `eval` converges. `eval(level, model_ops,
/// previous)` gives the level's value, or `None` when there is none (the
/// ladder stops and `Err(level)` says where).
pub(super) fn climb<E>(
    tolerance: f64,
    family: Family,
    mut eval: impl FnMut(usize, &Arc<StringOperators>, Option<f64>) -> Result<Option<f64>, E>,
) -> Result<Result<(Converged, Ladder), usize>, E> {
    let mut ladder = Ladder::default();
    for level in 0..MAX_LEVELS {
        let ops = family(level);
        let prev = ladder.values.last().copied();
        match eval(level, &ops, prev)? {
            Some(q) if q.is_finite() => ladder.push(q, ops.dim()),
            _ => return Ok(Err(level)),
        }
        if ladder.done(tolerance) {
            return Ok(Ok((ladder.estimate(true), ladder)));
        }
    }
    Ok(Ok((ladder.estimate(false), ladder)))
}
