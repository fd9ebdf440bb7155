//! Request and response bodies of `POST /api/v1/bands` (SI; the
//! percentiles of a quantity sit under its name, so `max_elevation_m.p05`
//! is in metres).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::contract::system::grid::BandsRateGridInput;
use crate::contract::system::input::SystemInput;

/// `POST /api/v1/bands`: the deployment chart of one system under
/// uncertain inputs, as 5/50/95 % bands with their sampling error.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[schema(example = json!({
    "cable": {"mass_per_length_kg_m": 0.078},
    "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
    "initial_length_m": 1.0,
    "rates_m_s": [5.0, 10.0, 20.0, 30.0],
    "target_elevation_m": 1200.0,
    "uncertainty": {
        "samples": 1000,
        "seed": 7,
        "inputs": [
            {"field": "aerostat.net_buoyancy_n", "distribution": "normal", "mean": 1000.0, "std_dev": 50.0},
            {"field": "cable.mass_per_length_kg_m", "distribution": "normal", "mean": 0.078, "std_dev": 0.002}
        ]
    }
}))]
pub struct BandsRequest {
    #[serde(flatten)]
    pub system: SystemInput,
    #[serde(flatten)]
    pub params: BandsParams,
}

/// The fields of a bands request besides the system.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct BandsParams {
    /// Rates of the chart (m/s): a list (1 to 1000 rates), or an evenly
    /// spaced grid `{min, max, count}`.
    pub rates_m_s: BandsRateGridInput,
    /// The uncertain inputs and the sampling.
    pub uncertainty: UncertaintyInput,
    /// Elevation to reach (m): each point then gives the probability that
    /// it is unsafe at that rate (`h* < target`), with its sampling error.
    #[serde(default)]
    #[schema(example = 1200.0, exclusive_minimum = 0.0)]
    pub target_elevation_m: Option<f64>,
}

/// Monte Carlo over uncertain inputs.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct UncertaintyInput {
    /// Number of samples (each one a full chart).
    #[serde(default = "default_samples")]
    #[schema(example = 1000, minimum = 1, maximum = 100000)]
    pub samples: usize,
    /// Seed: the same seed gives the identical answer on any machine and
    /// thread count.
    #[serde(default)]
    #[schema(example = 7, minimum = 0, maximum = 9007199254740991_u64)]
    pub seed: u64,
    /// The uncertain inputs (1 to 16), each a numeric field of the system
    /// and its distribution. Fields not listed keep the request's value.
    pub inputs: Vec<UncertainInput>,
}

fn default_samples() -> usize {
    1000
}

/// One uncertain input: `field` is the request path of a numeric field of
/// the system (`aerostat.net_buoyancy_n`, `aerostat.mass_kg`,
/// `cable.mass_per_length_kg_m`, `cable.density_kg_m3`, `cable.area_m2`,
/// `initial_length_m`, `gravity_m_s2`), in the field's own unit.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(tag = "distribution", rename_all = "snake_case", deny_unknown_fields)]
pub enum UncertainInput {
    /// Gaussian: `mean`, `std_dev` (≥ 0).
    Normal {
        #[schema(example = "aerostat.net_buoyancy_n")]
        field: String,
        #[schema(example = 1000.0)]
        mean: f64,
        #[schema(example = 50.0, minimum = 0.0)]
        std_dev: f64,
    },
    /// Uniform on `[low, high]`.
    Uniform { field: String, low: f64, high: f64 },
    /// Lognormal given by the **mean and standard deviation of the
    /// variable itself** (not of its logarithm): always positive.
    Lognormal {
        field: String,
        #[schema(exclusive_minimum = 0.0)]
        mean: f64,
        #[schema(minimum = 0.0)]
        std_dev: f64,
    },
}

impl UncertainInput {
    pub fn field(&self) -> &str {
        match self {
            Self::Normal { field, .. }
            | Self::Uniform { field, .. }
            | Self::Lognormal { field, .. } => field,
        }
    }
}

/// 5, 50 and 95 % points of one quantity, each with its sampling error:
/// the distribution-free 95 % order-statistic interval `[pXX_low,
/// pXX_high]` and `pXX_error`, the larger distance from the estimate to an
/// end of it. Ends are null when there are too few samples to bound that
/// tail (fewer than 72 for the 5 and 95 % points). Same unit as the
/// quantity.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PercentileBand {
    pub p05: f64,
    pub p50: f64,
    pub p95: f64,
    pub p05_error: Option<f64>,
    pub p50_error: Option<f64>,
    pub p95_error: Option<f64>,
    pub p05_low: Option<f64>,
    pub p05_high: Option<f64>,
    pub p50_low: Option<f64>,
    pub p50_high: Option<f64>,
    pub p95_low: Option<f64>,
    pub p95_high: Option<f64>,
    /// Sample mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub std_dev: f64,
}

/// The probability that the target elevation is unsafe at a rate
/// (`h* < target`), among the valid samples.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct UnsafeProbabilityOutput {
    /// Fraction of valid samples whose `h*` is below the target.
    pub probability_nondim: f64,
    /// Its standard error `√(p(1 − p)/n)`.
    pub standard_error_nondim: f64,
    /// Wilson 95 % interval.
    pub low_nondim: f64,
    pub high_nondim: f64,
    /// Samples below the target.
    pub unsafe_samples: usize,
}

/// One rate of the banded chart.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct BandPointOutput {
    /// Deployment rate (m/s).
    pub rate_m_s: f64,
    /// `h*` (m) across the samples.
    pub max_elevation_m: PercentileBand,
    /// `t*` (s) across the samples (0 when unstable at once).
    pub critical_time_s: PercentileBand,
    /// `h*` (m) of the request's own (nominal) values.
    pub nominal_max_elevation_m: f64,
    /// `t*` (s) of the nominal values.
    pub nominal_critical_time_s: f64,
    /// Samples unstable at once (rate at or above their wave speed, or
    /// the start already beyond the limit): `h* = L0`, `t* = 0`.
    pub immediate_samples: usize,
    /// Largest discretisation error estimate of `h*` among the samples
    /// (m): converged answers are on the safe side of it. Null with
    /// `model.elements` (a fixed mesh's values are not error-estimated per
    /// sample: omit `model.elements` for converged bands).
    pub max_elevation_error_m: Option<f64>,
    /// Largest discretisation error estimate of `t*` among the samples (s).
    pub critical_time_error_s: Option<f64>,
    /// With `target_elevation_m`: the probability that it is unsafe.
    pub probability_unsafe: Option<UnsafeProbabilityOutput>,
}

/// Draws that fell outside a field's physical range (a negative mass, a
/// non-positive buoyancy…): counted here, left out of every percentile
/// and probability (which are conditional on a valid draw).
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct RejectedSamplesOutput {
    /// The uncertain input whose draw was invalid.
    pub field: String,
    /// How many samples.
    pub count: usize,
    /// Why.
    pub reason: String,
}

#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct BandsResponse {
    /// One entry per rate, in the order asked.
    pub points: Vec<BandPointOutput>,
    /// Samples drawn.
    pub samples: usize,
    /// Samples with every draw in range (the percentiles are over these).
    pub valid_samples: usize,
    /// Samples left out, by input (empty when none).
    pub rejected_samples: Vec<RejectedSamplesOutput>,
    pub seed: u64,
    /// The uncertain inputs, as given.
    pub inputs: Vec<UncertainInput>,
    pub target_elevation_m: Option<f64>,
    /// Confidence level of every interval (0.95).
    pub confidence_level_nondim: f64,
    /// `monte_carlo`: independent draws, sample `i` from its own
    /// counter-based stream of `(seed, i)`.
    pub method: String,
    /// Uniform elements, or (converged) those of the coarsest graded mesh.
    pub elements: usize,
    /// Whether every chart point is converged (`model.elements` omitted).
    pub converged: bool,
}
