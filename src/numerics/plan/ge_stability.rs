//! The plan's stability criterion from the quasi-static geometrically
//! exact (GE) model of the tether (issue 13: "a plan with wind and
//! quasi-static GE stability"), and the check of a finished schedule by
//! the local GE QEP at its samples.
//!
//! **The model.** [`crate::numerics::ge::tether_system::ge_tether_system`]
//! of the plan's equilibrium problem with the **reserve** buoyancy
//! `(1 − r)F` (the tether described as for the static equilibrium, `EI`
//! and a mesh added), one model for every length (an inextensible
//! tether's `EA` is set from the longest length of the table).
//!
//! **The table.** The QS GE maximum safe length `L_max` (the critical
//! length of a payout at a vanishing rate `v₀ = 10⁻³ v_cap`,
//! [`crate::numerics::ge::qs_critical::critical_length`], stable end of
//! its bracket), then `n` lengths evenly spaced on `[L_lo, L_max]` and at
//! each the largest stable constant rate
//! [`crate::numerics::ge::qs_critical::critical_rate`] (stable end of its
//! bracket; `v_cap` when every rate up to the cap is stable; 0 and
//! unstable when not even the slowest rate is). A rate `v*` is turned into
//! the effective tension at rest the speed-profile pass works with,
//! `S = ρA v*²` (so the pass's ceiling at zero acceleration is `v*`, and
//! acceleration is taken off as the string criterion does:
//! `T_eff = S − (m + ρA L) L̈ − ρA L̇²`).
//!
//! **Conservative interpolation.** Between table lengths `S` is the calm
//! string's closed form `S₀(L) = (1 − r)F − ρA g L` plus the deviation
//! `D = S − S₀` of the **lower** of the two neighbouring nodes (exact at
//! the nodes). In calm air `D` is the bending offset (nearly constant);
//! in wind it varies slowly with the blow-down. Between the nodes the
//! rule is at or below the chord of `D`; a smooth `D` departs from its
//! chord by at most `h² max|D''|/8`, estimated by an eighth of the
//! larger second difference of `D` at the interval's nodes and **taken
//! off** the interpolated `S` ([`GeTable::curvature_margins_n`]), so the rule errs on
//! the safe side; the stated bound [`GeTable::interpolation_error_n`] is
//! the largest jump `|D_{i+1} − D_i|` (the most the rule takes off) plus
//! the interval's margin (ρA g of it is one metre of critical length). Past `L_max`
//! the deviation at `L_max` continues (`S ≈ ρA g (L_max − L) < 0`:
//! unstable).
//!
//! **Where the error matters.** The pass keeps `S − (m + ρA L) L̈ − ρA L̇²
//! ≥ ε(1 − r)F` with `|L̇| ≤ v_max`, `|L̈| ≤ a_max`. Where even the
//! rule's `S` (below the table's) exceeds `(m + ρA L) a_max + ρA v_max² +
//! ε(1 − r)F` over a whole interval (checked at its longer end, where `S`
//! is least and the demand largest), the stability constraint is inactive
//! there for every admissible state, so what the rule takes off cannot
//! change the schedule. The stated bound [`GeTable::interpolation_error_n`]
//! is over the other intervals; the bound over all of them is kept beside
//! it. (In calm air the bending offset `D` falls from about 200 N at 1 m
//! to 7 N at 114 m on the thesis tether with a 6 mm braid's EI, so the
//! first interval's jump would otherwise be the whole bound, at rates
//! above 100 m/s.)
//!
//! **Converged** ([`GeStabilityOptions::converge`], issue 21): `L_max`
//! and every row's rate are the safe sides of the converged divergence
//! onsets of [`crate::numerics::ge::qs_converged`] (nested meshes from
//! `elements` up, Richardson, best estimate minus its error), with their
//! error estimates in the table. In wind (unless `tracked_wind_onset`)
//! the rows are the string criterion's rates of the continuum tether
//! ([`crate::numerics::ge::wind_criterion`]) and the plan's `S(L)` is that
//! criterion itself, mean and gust, with no interpolation
//! ([`GeCriterion::string_in_wind`]): the GE divergence levels in wind were
//! not physical (a row of 13.18 ± 63 m/s at 332 m between 78 and 76 m/s
//! made the benchmark's log-law plan infeasible).
//!
//! **The check.** At schedule samples the local QEP of the GE model at
//! `(L, L̇, L̈)` with the reserve buoyancy
//! ([`crate::numerics::ge::quasi_static::wind_stability`]): paying out,
//! stable iff `max Re λ ≤ tol`; hauling in (always flutter-unstable:
//! negative damping) no divergence, i.e. no real eigenvalue above `tol`,
//! and the growth rate is reported.

use std::sync::{Arc, OnceLock};

use rayon::prelude::*;

use crate::numerics::ge::GeModel;
use crate::numerics::ge::air_load::AirLoads;
use crate::numerics::ge::element::TipLoad;
use crate::numerics::ge::qs_converged::{
    ConvergedOutcome, ConvergenceConfig, converged_critical_length, converged_critical_rate,
};
use crate::numerics::ge::qs_critical::lift_limit_length_m;
use crate::numerics::ge::qs_wind::{airborne_length_m, branch_equilibrium, continuum_start};
use crate::numerics::ge::quasi_static::{
    QsConfig, stiffness_negative_count, wind_equilibrium, wind_stability,
};
use crate::numerics::ge::stability::StateMotion;
use crate::numerics::ge::tether_system::{GeTetherOptions, ge_tether_system};
use crate::numerics::ge::wind_criterion;
use crate::numerics::params::{AerostatSystem, InvalidInput, Kinematics};
use crate::numerics::plan::{PlanProblem, STABILITY_MARGIN};
use crate::numerics::tether::EquilibriumProblem;

/// Fewest and most table lengths.
pub const MIN_TABLE_LENGTHS: usize = 3;
pub const MAX_TABLE_LENGTHS: usize = 400;
/// Fewest and most GE elements.
pub const MIN_GE_ELEMENTS: usize = 4;
pub const MAX_GE_ELEMENTS: usize = 2000;
/// Most elements of the QEP check (a dense eigenproblem of 6(n + 1)).
pub const MAX_GE_CHECK_ELEMENTS: usize = 100;

/// What the GE criterion needs beyond the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeStabilityOptions {
    /// Bending stiffness `EI` (N m²).
    pub bending_stiffness_n_m2: f64,
    /// Finite elements over the tether (table and divergence check).
    pub elements: usize,
    /// Finite elements of the QEP check of the schedule (flutter).
    pub check_elements: usize,
    /// Lengths of the critical-rate table (≥ 3).
    pub table_lengths: usize,
    /// Shortest length of the table (m).
    pub min_length_m: f64,
    /// Converge the table (issue 21): the maximum safe length and each
    /// row's critical rate are the safe sides of converged onsets
    /// ([`crate::numerics::ge::qs_converged`], divergence only, from
    /// `elements` up); `None`: on the `elements` mesh as given.
    pub converge: Option<ConvergenceConfig>,
}

impl GeStabilityOptions {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        if !(MIN_GE_ELEMENTS..=MAX_GE_ELEMENTS).contains(&self.elements) {
            return Err(InvalidInput::new(
                "stability.elements",
                format!(
                    "must be between {MIN_GE_ELEMENTS} and {MAX_GE_ELEMENTS}, got {}",
                    self.elements
                ),
            ));
        }
        if !(MIN_GE_ELEMENTS..=MAX_GE_CHECK_ELEMENTS).contains(&self.check_elements) {
            return Err(InvalidInput::new(
                "stability.check_elements",
                format!(
                    "must be between {MIN_GE_ELEMENTS} and {MAX_GE_CHECK_ELEMENTS}, got {}",
                    self.check_elements
                ),
            ));
        }
        if !(MIN_TABLE_LENGTHS..=MAX_TABLE_LENGTHS).contains(&self.table_lengths) {
            return Err(InvalidInput::new(
                "stability.table_samples",
                format!(
                    "must be between {MIN_TABLE_LENGTHS} and {MAX_TABLE_LENGTHS}, got {}",
                    self.table_lengths
                ),
            ));
        }
        Ok(())
    }
}

/// One length of the table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableRow {
    pub length_m: f64,
    /// Largest stable constant rate (m/s); the cap when `capped`.
    pub critical_rate_m_s: f64,
    /// Every rate up to the cap was stable.
    pub capped: bool,
    /// Not even the slowest rate was stable (or no equilibrium / spectrum).
    pub unstable: bool,
    /// `S = ρA v*²` (N), `−(1 − r)F` when unstable.
    pub stability_tension_n: f64,
}

/// The critical-rate table of one plan.
#[derive(Clone, Debug)]
pub struct GeTable {
    pub rows: Vec<TableRow>,
    /// QS GE maximum safe length at a vanishing rate (m).
    pub max_safe_length_m: f64,
    /// The rate cap of the searches (m/s).
    pub rate_cap_m_s: f64,
    /// `(1 − r)F` the table was made for (N).
    pub reserve_buoyancy_n: f64,
    /// Bound on the interpolation error where it can change the plan (N):
    /// over the intervals where the rule's `S` can limit a schedule (module
    /// docs, "Where the error matters"), the largest jump of the deviation
    /// `D` between neighbouring rows (the most the lower-neighbour rule
    /// takes off between nodes) plus the curvature margin taken off on the
    /// safe side ([`GeTable::curvature_margin_n`]); 0 where it binds nowhere.
    pub interpolation_error_n: f64,
    /// The same bound over every interval of the table, including short
    /// lengths where the bending offset changes fast but the ceiling is far
    /// above the winch's rate (N).
    pub interpolation_error_all_lengths_n: f64,
    /// Largest of the per-interval curvature margins (N).
    pub curvature_margin_n: f64,
    /// Taken off `S` inside each interval between rows (N): an eighth of
    /// the larger second difference of `D` at the interval's two nodes,
    /// the bound `h² max|D''|/8` of the departure of a smooth `D` from its
    /// chord (0 at the nodes).
    pub curvature_margins_n: Vec<f64>,
    /// Converged table: per row the estimated discretisation error of its
    /// critical rate (m/s) (empty unless converged).
    pub rate_error_m_s: Vec<f64>,
    /// Converged table: the estimated error of the maximum safe length (m).
    pub max_safe_length_error_m: Option<f64>,
    /// Searches run and QEPs solved.
    pub qep_solves: usize,
    pub equilibria: usize,
    /// `ρA`, `g` of the closed form `S₀`.
    rho_a: f64,
    gravity: f64,
    deviation: Vec<f64>,
}

impl GeTable {
    fn closed_form(&self, length_m: f64) -> f64 {
        self.reserve_buoyancy_n - self.rho_a * self.gravity * length_m
    }

    /// `S(L)` by the lower-neighbour rule (module docs) (N).
    pub fn stability_tension_n(&self, length_m: f64) -> f64 {
        let n = self.rows.len();
        let d = if length_m >= self.rows[n - 1].length_m {
            self.deviation[n - 1]
        } else if length_m <= self.rows[0].length_m {
            self.deviation[0]
        } else {
            let i = self.rows.partition_point(|r| r.length_m <= length_m) - 1;
            let li = self.rows[i].length_m;
            if (length_m - li).abs() <= 1e-12 * li.abs().max(1.0) {
                self.deviation[i]
            } else {
                self.deviation[i].min(self.deviation[i + 1])
                    - self.curvature_margins_n.get(i).copied().unwrap_or(0.0)
            }
        };
        self.closed_form(length_m) + d
    }
}

/// The GE model of a plan in its air, with the reserve buoyancy.
#[derive(Clone, Debug)]
pub struct GePlanModel {
    /// The model of the table and of the divergence check.
    pub model: GeModel,
    /// The coarser model whose QEP checks for flutter (None: divergence only).
    pub check_model: Option<GeModel>,
    pub air: AirLoads,
    pub reserve_buoyancy_n: f64,
}

impl GePlanModel {
    fn load(&self) -> TipLoad {
        TipLoad {
            force_n: [self.reserve_buoyancy_n, 0.0],
            moment_n_m: 0.0,
        }
    }
}

/// The QS GE criterion of a plan: options, the table (made once, on first
/// use, shared by clones) and an offset taken off `S` when a checked
/// schedule had to be tightened.
#[derive(Clone, Debug)]
pub struct GeCriterion {
    pub options: GeStabilityOptions,
    /// Taken off `S` (N) (0 unless tightened).
    pub offset_n: f64,
    table: Arc<OnceLock<Result<(GeTable, GePlanModel), String>>>,
}

/// What the criterion is converged in wind ([`GeCriterion::string_in_wind`]), for the answer.
pub const QS_GE_WIND_CRITERION: &str = "quasi-static GE stability, converged, in wind: the string criterion of the blown-down tether with the reserve buoyancy in this wind (its smallest tension less (m + ρA L)L̈ + ρA L̇² must stay ≥ ε(1−r)F, mean and gust), because the local GE onset in wind is an imperfect bifurcation with no usable limit (the blow-down grows as T/(T − ρA v²)); it is below the GE onset (bending only lifts it) and the schedule is then checked by the local GE QEP at its samples";

/// What the criterion is, for the answer.
pub const QS_GE_CRITERION: &str = "quasi-static geometrically exact stability of the tether with the reserve \
buoyancy: the largest stable constant payout rate v*(L) of the local GE QEP about the blown-down equilibrium \
(critical_rate), tabulated on a length grid and taken between rows from the lower neighbour's deviation from the \
calm string's closed form; the pass keeps ρA v*² − (m + ρA L)L̈ − ρA L̇² ≥ ε(1−r)F, and the schedule is then \
checked by the local GE QEP at its samples with their rate and acceleration";

/// Rates (or lengths) of the scan of one search.
pub const SCAN_POINTS: usize = 12;
/// Bisection steps of one search (relative width `2⁻¹⁶` of the scan interval).
pub const BISECTIONS: usize = 16;

/// The verdict at one state: `(stable, max Re λ, tolerance)`. Unstable
/// when the QEP grows (`max Re λ > tol`), when the symmetric part of the
/// stiffness has a negative eigenvalue (a divergence: just past it the
/// real eigenvalue grows more slowly than the roundoff tolerance), or
/// when no equilibrium or spectrum is found. Hauling in (`L̇ < 0`) only a
/// divergence counts (the flutter growth is reported, not judged).
pub fn judge(gm: &GePlanModel, kin: Kinematics) -> (bool, f64, f64) {
    let load = gm.load();
    // Divergence on the fine mesh: equilibrium and the inertia of K (O(n)).
    // In wind: the branch reached by paying out (`qs_wind`), not a
    // wrapped equilibrium of the straight tether's continuation.
    let q = if gm.air.is_calm() {
        wind_equilibrium(&gm.model, kin, load, &gm.air, &QsConfig::default(), None)
            .ok()
            .map(|e| e.q)
    } else {
        branch_equilibrium(&gm.model, kin, load, &gm.air, &QsConfig::default(), None)
    };
    let Some(q) = q else {
        return (false, f64::NAN, 0.0);
    };
    let count = stiffness_negative_count(&gm.model, kin, load, &gm.air, &q);
    if count != Some(0) {
        return (false, f64::NAN, 0.0);
    }
    let Some(check) = &gm.check_model else {
        return (true, f64::NAN, 0.0);
    };
    // Flutter on the check mesh: the QEP (in wind from the branch's start).
    let start = if gm.air.is_calm() {
        None
    } else {
        continuum_start(check, &gm.air, gm.reserve_buoyancy_n, kin.length_m).map(|s| s.0)
    };
    let Ok(w) = wind_stability(
        check,
        kin,
        load,
        &gm.air,
        StateMotion::AtRest,
        &QsConfig::default(),
        start.as_deref(),
    ) else {
        return (false, f64::NAN, 0.0);
    };
    let tol = w.spectrum.tolerance();
    // A real eigenvalue above zero without a negative stiffness
    // eigenvalue is the roundoff splitting of a slow pair (near the lift
    // limit the first mode's frequency tends to zero and the QEP splits it
    // into ±O(√ε ρ)): with the symmetric part of K positive and damping
    // that dissipates (paying out, aerodynamic drag), λ²m + λc + k = 0 has
    // no positive real root. Growth is judged on the complex eigenvalues.
    let growth = w
        .spectrum
        .eigenvalues
        .iter()
        .filter(|e| e.im != 0.0)
        .map(|e| e.re)
        .fold(f64::NEG_INFINITY, f64::max);
    let ok = kin.rate_m_s < 0.0 || growth <= tol;
    (ok, growth, tol)
}

/// The last stable value of `p` in `[lo, hi]` by a scan of
/// [`SCAN_POINTS`] and [`BISECTIONS`] bisections of the first unstable
/// interval: `Ok(p)`, or `Err(true)` when stable up to `hi`, `Err(false)`
/// when unstable at `lo`. Every state is solved afresh (no warm start).
fn last_stable(lo: f64, hi: f64, stable: impl Fn(f64) -> bool + Sync) -> Result<f64, bool> {
    if !stable(lo) {
        return Err(false);
    }
    let pts: Vec<f64> = (1..=SCAN_POINTS)
        .map(|k| lo + (hi - lo) * k as f64 / SCAN_POINTS as f64)
        .collect();
    let mut a = lo;
    let mut b = None;
    for &p in &pts {
        if stable(p) {
            a = p;
        } else {
            b = Some(p);
            break;
        }
    }
    let Some(mut b) = b else { return Err(true) };
    for _ in 0..BISECTIONS {
        let m = 0.5 * (a + b);
        if stable(m) {
            a = m;
        } else {
            b = m;
        }
    }
    Ok(a)
}

/// What the criterion needs of the steady wind it is made in (implemented
/// by [`super::air::SteadyWind`], which holds the criterion).
pub trait GeWind {
    /// The equilibrium problem at a length with a net buoyancy.
    fn problem(&self, s: &AerostatSystem, buoyancy_n: f64, length_m: f64) -> EquilibriumProblem;
    /// The air density (kg/m³).
    fn air_density_kg_m3(&self) -> f64;
    /// The mean wind speed at height `z_m` (m/s).
    fn speed_m_s(&self, z_m: f64) -> f64;
}

impl GeCriterion {
    pub fn new(options: GeStabilityOptions) -> Self {
        Self {
            options,
            offset_n: 0.0,
            table: Arc::default(),
        }
    }

    /// The same criterion (same table) with `S` lowered by `offset_n`.
    pub fn with_offset(&self, offset_n: f64) -> Self {
        Self {
            offset_n,
            ..self.clone()
        }
    }

    /// The table and model, made on first use for `p` in `wind`.
    pub fn table(
        &self,
        wind: &dyn GeWind,
        p: &PlanProblem,
    ) -> Result<&(GeTable, GePlanModel), &str> {
        self.table
            .get_or_init(|| build(wind, p, &self.options))
            .as_ref()
            .map_err(|e| e.as_str())
    }

    /// Whether `S(L)` is the string criterion in `wind` itself, not the
    /// table: converged in wind (`wind_criterion`), where the table's rows
    /// are that criterion's rates and interpolating them would only lose.
    pub fn string_in_wind(&self, wind: &dyn GeWind) -> bool {
        self.options.converge.is_some_and(|c| !c.tracked_wind_onset)
            && wind.air_density_kg_m3() > 0.0
            && [1.0, 10.0, 100.0, 1e3, 1e4]
                .iter()
                .any(|&z| wind.speed_m_s(z) != 0.0)
    }

    /// The table if it was made.
    pub fn made_table(&self) -> Option<&(GeTable, GePlanModel)> {
        self.table.get().and_then(|r| r.as_ref().ok())
    }

    /// `S(L)` (N); `−(1 − r)F` (unstable) when the table could not be made
    /// or was made for another reserve.
    pub fn stability_tension_n(&self, wind: &dyn GeWind, p: &PlanProblem, length_m: f64) -> f64 {
        let b = p.reserve_buoyancy_n();
        match self.table(wind, p) {
            Ok((t, _)) if t.reserve_buoyancy_n == b => {
                t.stability_tension_n(length_m) - self.offset_n
            }
            _ => -b,
        }
    }

    /// Upper end of the lift-limit search (m): past the table's last row.
    pub fn search_upper_m(&self, wind: &dyn GeWind, p: &PlanProblem) -> Option<f64> {
        self.table(wind, p).ok().map(|(t, _)| t.max_safe_length_m)
    }
}

/// Makes the table (module docs).
fn build(
    wind: &dyn GeWind,
    p: &PlanProblem,
    options: &GeStabilityOptions,
) -> Result<(GeTable, GePlanModel), String> {
    options.validate().map_err(|e| e.to_string())?;
    let s = &p.system;
    let b = p.reserve_buoyancy_n();
    let rho_a = s.mass_per_length_kg_m;
    let string_limit = b / (rho_a * s.gravity_m_s2);
    // The model: EA of an inextensible tether from the longest length.
    let probe = wind.problem(s, b, string_limit);
    let sys = ge_tether_system(
        &probe,
        &GeTetherOptions {
            bending_stiffness_n_m2: options.bending_stiffness_n_m2,
            aerostat_mass_kg: s.aerostat_mass_kg,
            elements: options.elements,
        },
    )
    .map_err(|e| e.to_string())?;
    let search_hi = 1.25 * lift_limit_length_m(&sys.model, b, &sys.air).max(string_limit);
    let probe = wind.problem(s, b, search_hi);
    let sys = ge_tether_system(
        &probe,
        &GeTetherOptions {
            bending_stiffness_n_m2: options.bending_stiffness_n_m2,
            aerostat_mass_kg: s.aerostat_mass_kg,
            elements: options.elements,
        },
    )
    .map_err(|e| e.to_string())?;
    let check_sys = ge_tether_system(
        &probe,
        &GeTetherOptions {
            bending_stiffness_n_m2: options.bending_stiffness_n_m2,
            aerostat_mass_kg: s.aerostat_mass_kg,
            elements: options.check_elements,
        },
    )
    .map_err(|e| e.to_string())?;
    // The table judges divergence only (the inertia of K, O(n) per state);
    // the schedule's check adds the QEP on the check mesh.
    let gm = GePlanModel {
        model: sys.model,
        check_model: None,
        air: sys.air,
        reserve_buoyancy_n: b,
    };
    let cap = (2.0 * p.winch.max_rate_m_s).max(1.2 * (b / rho_a).sqrt());
    let lo = options.min_length_m.max(1e-3).min(0.5 * string_limit);
    let evaluations = std::sync::atomic::AtomicUsize::new(0);
    let stable = |l: f64, v: f64| {
        evaluations.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        judge(
            &gm,
            Kinematics {
                length_m: l,
                rate_m_s: v,
                acceleration_m_s2: 0.0,
            },
        )
        .0
    };
    let never = || false;
    // In wind every level follows the branch reached by paying out
    // (`qs_wind`) and the length search ends at the continuum tether's
    // ground contact; the rate rows' levels are not yet reliable in wind
    // (issue 21): three levels there, the safe side below each.
    let conv = options.converge.map(|c| ConvergenceConfig {
        base_elements: options.elements,
        max_elements: if gm.air.is_calm() {
            c.max_elements.max(4 * options.elements)
        } else {
            4 * options.elements
        },
        qep_in_wind: false,
        ..c
    });
    // Converged in wind: the string criterion of the continuum tether in
    // the wind (`wind_criterion`: the GE onset there is an imperfect
    // bifurcation, not a limit).
    let string_in_wind = conv.is_some_and(|c| !c.tracked_wind_onset) && !gm.air.is_calm();
    let search_hi = if conv.is_some() && !gm.air.is_calm() {
        airborne_length_m(&gm.model, &gm.air, b, (lo, search_hi))
    } else {
        search_hi
    };
    // The maximum safe length: at rest.
    let mut max_len_error = None;
    let max_len = match &conv {
        None => match last_stable(lo, search_hi, |l| stable(l, 0.0)) {
            Ok(l) => l,
            Err(true) => search_hi,
            Err(false) => lo,
        },
        Some(c) => {
            let r = if string_in_wind {
                wind_criterion::critical_length(&gm.model, b, &gm.air, 0.0, (lo, search_hi))
            } else {
                converged_critical_length(&gm.model, b, &gm.air, 0.0, c, (lo, search_hi), &never)
            }
            .map_err(|e| e.to_string())?;
            evaluations.fetch_add(r.equilibria, std::sync::atomic::Ordering::Relaxed);
            match r.outcome {
                ConvergedOutcome::During(o) => {
                    max_len_error = Some(o.error_estimate);
                    o.safe_value.max(lo)
                }
                ConvergedOutcome::Never { .. } => search_hi,
                _ => lo,
            }
        }
    };
    let n = options.table_lengths;
    let lengths: Vec<f64> = (0..n)
        .map(|i| {
            if i + 1 == n {
                max_len
            } else {
                lo + (max_len - lo) * i as f64 / (n - 1) as f64
            }
        })
        .collect();
    let found: Vec<(Result<f64, bool>, f64)> = lengths[..n - 1]
        .par_iter()
        .map(|&l| {
            if max_len <= lo {
                return (Err(false), 0.0);
            }
            let Some(c) = &conv else {
                return (last_stable(0.0, cap, |v| stable(l, v)), 0.0);
            };
            let r = if string_in_wind {
                wind_criterion::critical_rate(&gm.model, b, &gm.air, l, cap)
            } else {
                converged_critical_rate(&gm.model, b, &gm.air, l, cap, c, &never, None)
            };
            match r {
                Ok(r) => {
                    evaluations.fetch_add(r.equilibria, std::sync::atomic::Ordering::Relaxed);
                    match r.outcome {
                        ConvergedOutcome::During(o) => {
                            (Ok(o.safe_value.max(0.0)), o.error_estimate)
                        }
                        ConvergedOutcome::Never { .. } => (Err(true), 0.0),
                        _ => (Err(false), 0.0),
                    }
                }
                Err(_) => (Err(false), 0.0),
            }
        })
        .collect();
    let rate_error_m_s: Vec<f64> = if conv.is_some() {
        found.iter().map(|f| f.1).collect()
    } else {
        Vec::new()
    };
    let found: Vec<Result<f64, bool>> = found.into_iter().map(|f| f.0).collect();
    let mut rows = Vec::with_capacity(n);
    for (&l, f) in lengths.iter().zip(&found) {
        let (v, capped, unstable) = match f {
            Ok(v) => (*v, false, false),
            Err(true) => (cap, true, false),
            Err(false) => (0.0, false, true),
        };
        rows.push(TableRow {
            length_m: l,
            critical_rate_m_s: v,
            capped,
            unstable,
            stability_tension_n: if unstable { -b } else { rho_a * v * v },
        });
    }
    // The last row: the maximum safe length, stable only at rest.
    let last_unstable = max_len <= lo;
    rows.push(TableRow {
        length_m: max_len,
        critical_rate_m_s: 0.0,
        capped: false,
        unstable: last_unstable,
        stability_tension_n: if last_unstable { -b } else { 0.0 },
    });
    let qep_solves = evaluations.load(std::sync::atomic::Ordering::Relaxed);
    let equilibria = qep_solves;
    let closed = |l: f64| b - rho_a * s.gravity_m_s2 * l;
    let deviation: Vec<f64> = rows
        .iter()
        .map(|r| r.stability_tension_n - closed(r.length_m))
        .collect();
    let usable = |r: &TableRow| !r.capped && !r.unstable;
    // second differences at the interior nodes (None where a row is not usable)
    let second: Vec<Option<f64>> = (0..rows.len())
        .map(|k| {
            if k == 0 || k + 1 >= rows.len() || !rows[k - 1..=k + 1].iter().all(usable) {
                return None;
            }
            Some((deviation[k + 1] - 2.0 * deviation[k] + deviation[k - 1]).abs() / 8.0)
        })
        .collect();
    let curvature_margins_n: Vec<f64> = (0..rows.len().saturating_sub(1))
        .map(|i| {
            second[i]
                .unwrap_or(0.0)
                .max(second.get(i + 1).copied().flatten().unwrap_or(0.0))
        })
        .collect();
    let curvature_margin_n = curvature_margins_n.iter().copied().fold(0.0, f64::max);
    // Per interval between usable rows: the most the rule takes off, and
    // whether the rule's `S` can limit a schedule there at all (module
    // docs, "Where the error matters").
    let intervals: Vec<(f64, bool)> = rows
        .windows(2)
        .zip(deviation.windows(2))
        .zip(&curvature_margins_n)
        .filter(|((r, _), _)| usable(&r[0]) && usable(&r[1]))
        .map(|((r, d), m)| {
            let l = r[1].length_m;
            let rule = closed(l) + d[0].min(d[1]) - m;
            let demand = (s.aerostat_mass_kg + rho_a * l) * p.winch.max_acceleration_m_s2
                + rho_a * p.winch.max_rate_m_s.powi(2)
                + STABILITY_MARGIN * b;
            ((d[1] - d[0]).abs() + m, rule < demand)
        })
        .collect();
    // Converged in wind `S` is the string criterion itself, not
    // interpolated (`GeCriterion::string_in_wind`): no interpolation error.
    let worst = |binding_only: bool| {
        if string_in_wind {
            return 0.0;
        }
        intervals
            .iter()
            .filter(|&&(_, binds)| binds || !binding_only)
            .map(|&(e, _)| e)
            .fold(0.0, f64::max)
    };
    let interpolation_error_n = worst(true);
    let interpolation_error_all_lengths_n = worst(false);
    Ok((
        GeTable {
            rows,
            max_safe_length_m: max_len,
            rate_cap_m_s: cap,
            reserve_buoyancy_n: b,
            interpolation_error_n,
            interpolation_error_all_lengths_n,
            curvature_margin_n,
            curvature_margins_n,
            rate_error_m_s,
            max_safe_length_error_m: max_len_error,
            qep_solves,
            equilibria,
            rho_a,
            gravity: s.gravity_m_s2,
            deviation,
        },
        GePlanModel {
            // The check keeps the full spectrum (its `judge` already
            // discounts the roundoff splitting of slow real pairs).
            check_model: Some(GeModel {
                slow_spectrum: false,
                ..check_sys.model
            }),
            ..gm
        },
    ))
}

/// The check of one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleCheck {
    pub time_s: f64,
    pub kinematics: Kinematics,
    /// `max Re λ` of the local QEP (1/s); NaN when it failed.
    pub max_real_1_s: f64,
    /// Its roundoff tolerance (1/s).
    pub tolerance_1_s: f64,
    /// Stable (paying out or at rest) or free of divergence (hauling in).
    pub ok: bool,
}

/// The check of a schedule.
#[derive(Clone, Debug, PartialEq)]
pub struct ScheduleCheck {
    pub samples: Vec<SampleCheck>,
    /// The sample with the largest `max Re λ` among the payout ones (or all).
    pub worst: Option<SampleCheck>,
    pub failed: usize,
}

/// The verdict of [`judge`] at each `(t, L, L̇, L̈)` (on rayon).
pub fn check_samples(gm: &GePlanModel, samples: &[(f64, Kinematics)]) -> ScheduleCheck {
    let checks: Vec<SampleCheck> = samples
        .par_iter()
        .map(|&(t, kin)| {
            let (ok, max_real_1_s, tolerance_1_s) = judge(gm, kin);
            SampleCheck {
                time_s: t,
                kinematics: kin,
                max_real_1_s,
                tolerance_1_s,
                ok,
            }
        })
        .collect();
    let failed = checks.iter().filter(|c| !c.ok).count();
    let payout: Vec<&SampleCheck> = checks
        .iter()
        .filter(|c| c.kinematics.rate_m_s >= 0.0)
        .collect();
    let pool: Vec<&SampleCheck> = if payout.is_empty() {
        checks.iter().collect()
    } else {
        payout
    };
    let worst = pool
        .into_iter()
        .max_by(|a, b| {
            let key = |c: &SampleCheck| {
                if c.max_real_1_s.is_nan() {
                    f64::INFINITY
                } else {
                    c.max_real_1_s
                }
            };
            key(a).total_cmp(&key(b))
        })
        .copied();
    ScheduleCheck {
        samples: checks,
        worst,
        failed,
    }
}
