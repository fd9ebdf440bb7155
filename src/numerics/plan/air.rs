//! What the air does to a plan: the static loads at one tether length, at
//! rest, that the speed-profile pass ([`super::schedule`]) needs, in calm
//! air (closed forms) or in a steady wind (the tether equilibrium of
//! [`crate::numerics::tether::equilibrium`]).
//!
//! The pass adds the kinematic terms to the loads at rest (quasi-static:
//! the tether pays out along its own shape, so every point of it has the
//! tangential acceleration `L̈`):
//!
//! ```text
//! T_eff(L, L̇, L̈)   = S(L) − (m + ρA L) L̈ − ρA L̇²     ≥ ε(1 − r)F   (stability)
//! T_winch(L, L̈)    = T_w(L) − (m + ρA L) L̈
//! T_top(L, L̈)      = T_t(L) − m L̈                      (largest: ≤ allowable)
//! ```
//!
//! In calm air `S = (1 − r)F − ρA g L`, `T_w = F − ρA g L`, `T_t = F`
//! (SPEC §1, §7). In wind `T_w`, `T_t` are the equilibrium tensions at the
//! winch and at the aerostat with the full buoyancy `F` (with normal drag
//! only, `dT/ds = ρA g sin θ ≥ 0`: the tension grows monotonically from
//! the winch up, so these two bound it), and `S` is the **stability
//! criterion** [`StabilityCriterion`] evaluated on the equilibrium with the
//! reserve buoyancy `(1 − r)F`. The default, [`string_tension_criterion`],
//! is the one the operating envelope uses (SPEC §6, `envelope::judge`):
//! the continuum string criterion on the smallest tension of the
//! blown-down tether, unstable when the tether goes slack (touches the
//! ground). It is one function of `(problem, equilibrium)`, so a
//! quasi-static geometrically exact check can replace it.
//!
//! Paying out, the aerostat climbs into the air and its own drag takes
//! tension off the tether: [`super::ascent`] bounds the loss, `δ(L̇)`,
//! and the stability criterion subtracts it
//! (`T_eff = S − (m + ρA L)L̈ − ρA L̇² − δ(L̇)`). The tensions the rating
//! bounds keep the loads at rest (the ascent only lowers them).
//!
//! **Gusts** (SPEC §10, [`SteadyWind::gust`]): every limit holds at the
//! gust speed as well. The tensions the pass bounds are the larger of the
//! mean's and the gust's at each length ([`SteadyWind::limit_tensions`]),
//! and the string criterion's `S` the smaller ([`SteadyWind::stability_tension_n`];
//! the quasi-static GE criterion is judged in the mean wind). The gust
//! is the static equilibrium at the gust speed, which is conservative for
//! the tension; with a gust equal to the mean (I = 0) nothing is computed
//! twice and every number is the mean's bit for bit.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::numerics::params::AerostatSystem;
use crate::numerics::plan::ascent::AscentDrag;
use crate::numerics::plan::boundary::bracket_crossing;
use crate::numerics::plan::sparse::{RELATIVE_TOLERANCE, Solved, sparse_along};
use crate::numerics::plan::{PlanProblem, STABILITY_MARGIN};
use crate::numerics::tether::continuation::ShootingContinuation;
use crate::numerics::tether::gust::dynamic_tension_n;
use crate::numerics::tether::{
    Body, Cable, Equilibrium, EquilibriumConfig, EquilibriumProblem, WindProfile,
};

/// Static loads at one length, at rest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestLoads {
    /// `S(L)`: effective tension at rest with the reserve buoyancy, by the
    /// stability criterion (N); below `ε(1 − r)F` the state is not
    /// admissible.
    pub stability_tension_n: f64,
    /// Axial tension at the winch, full buoyancy (N).
    pub winch_tension_n: f64,
    /// Axial tension at the aerostat, full buoyancy (N).
    pub top_tension_n: f64,
    /// Altitude of the aerostat above the winch, full buoyancy (m).
    pub altitude_m: f64,
    /// The tension its ascent may take off while paying out.
    pub ascent: AscentDrag,
}

impl RestLoads {
    /// `T_eff = S − (m + ρA L) L̈ − ρA L̇² − δ(L̇)` (N).
    pub fn effective_tension_n(
        &self,
        s: &AerostatSystem,
        length_m: f64,
        rate: f64,
        acc: f64,
    ) -> f64 {
        let rho_a = s.mass_per_length_kg_m;
        self.stability_tension_n
            - (s.aerostat_mass_kg + rho_a * length_m) * acc
            - rho_a * rate * rate
            - self.ascent.loss_n(rate)
    }

    /// Winch tension with the acceleration (N).
    pub fn winch_tension_at_n(&self, s: &AerostatSystem, length_m: f64, acc: f64) -> f64 {
        self.winch_tension_n - (s.aerostat_mass_kg + s.mass_per_length_kg_m * length_m) * acc
    }

    /// Largest tension along the tether with the acceleration (N).
    pub fn max_tension_at_n(&self, s: &AerostatSystem, length_m: f64, acc: f64) -> f64 {
        (self.top_tension_n - s.aerostat_mass_kg * acc)
            .max(self.winch_tension_at_n(s, length_m, acc))
    }

    /// Largest stable rate at this length and acceleration (m/s); 0 when
    /// even rest is unstable.
    pub fn rate_ceiling_m_s(&self, s: &AerostatSystem, length_m: f64, acc: f64) -> f64 {
        self.ascent.ceiling_m_s(
            s.mass_per_length_kg_m,
            self.effective_tension_n(s, length_m, 0.0, acc),
        )
    }
}

/// The stability criterion at rest: `S(L)` (N) from the equilibrium with
/// the reserve buoyancy and its problem. This is the one function a
/// quasi-static geometrically exact stability check replaces: it must
/// return the effective tension at rest that the kinematic terms
/// `(m + ρA L) L̈ + ρA L̇²` are then taken from (negative when unstable).
pub type StabilityCriterion = fn(&EquilibriumProblem, &Equilibrium) -> f64;

/// The envelope's criterion (SPEC §6): the smallest tension of the
/// blown-down tether, and unstable (`−(1 − r)F`) when it is slack or the
/// equilibrium did not converge.
pub fn string_tension_criterion(problem: &EquilibriumProblem, eq: &Equilibrium) -> f64 {
    if eq.slack || !eq.converged || eq.min_tension_n <= 0.0 {
        -problem.body.net_buoyancy_n
    } else {
        eq.min_tension_n
    }
}

/// What [`string_tension_criterion`] is, for the answer.
pub const STRING_TENSION_CRITERION: &str = "string tension criterion on the steady-wind equilibrium \
(as the operating envelope): the smallest tension of the blown-down tether with the reserve buoyancy, less \
(m + ρA L)L̈ + ρA L̇² and, paying out, the bound on the aerostat's ascent drag, must stay ≥ ε(1−r)F; a slack \
tether (touching the ground) is unstable";

/// A steady wind and the aerodynamic data of the tether and the aerostat.
#[derive(Clone, Debug)]
pub struct SteadyWind {
    /// The tether (its `mass_per_length_kg_m` is replaced by the system's).
    pub cable: Cable,
    /// The aerostat (its `net_buoyancy_n` is replaced by the system's).
    pub body: Body,
    pub wind: WindProfile,
    pub air_density_kg_m3: f64,
    pub config: EquilibriumConfig,
    pub criterion: StabilityCriterion,
    /// Its description.
    pub criterion_name: &'static str,
    /// The quasi-static GE criterion, which replaces `criterion` when set
    /// ([`super::ge_stability`]).
    pub ge: Option<super::ge_stability::GeCriterion>,
    /// The gust profile (SPEC §10); `None`: the mean wind only.
    pub gust: Option<WindProfile>,
    /// The factor on the gust's static tensions' increment over calm air (1
    /// unless set by [`Self::with_gust_tension_factor`]): the dynamic peak
    /// over the static check
    /// (`crate::numerics::tether::gust::DYNAMIC_TENSION_FACTOR`).
    pub gust_tension_factor: f64,
    /// Answers already computed, by (length, buoyancy, kind) bits: the
    /// pass, the bound, the constant-rate plan and the jerk check of one
    /// request share their grid's lengths.
    cache: Arc<Mutex<HashMap<CacheKey, [f64; 3]>>>,
}

/// Winch and top tension of the tether hanging still in calm air at full
/// buoyancy (N): `F − ρA g L` (0 once the tether would rest on the ground)
/// and `F`, the base the gust's dynamic factor amplifies over.
pub fn calm_tensions_n(s: &AerostatSystem, length_m: f64) -> (f64, f64) {
    let f = s.net_buoyancy_n;
    let winch = (f - s.mass_per_length_kg_m * s.gravity_m_s2 * length_m).max(0.0);
    (winch, f)
}

impl SteadyWind {
    /// With the envelope's criterion and 100 RK4 steps.
    pub fn new(cable: Cable, body: Body, wind: WindProfile, air_density_kg_m3: f64) -> Self {
        Self {
            cable,
            body,
            wind,
            air_density_kg_m3,
            config: EquilibriumConfig {
                keep_shape: false,
                ..EquilibriumConfig::default()
            },
            criterion: string_tension_criterion,
            criterion_name: STRING_TENSION_CRITERION,
            ge: None,
            gust: None,
            gust_tension_factor: 1.0,
            cache: Arc::default(),
        }
    }

    /// The same wind with gusts of profile `gust`.
    pub fn with_gust(mut self, gust: WindProfile) -> Self {
        self.gust = Some(gust);
        self
    }

    /// The gust's static tensions judged at their dynamic value: the calm
    /// tension plus `factor` times their increment over it
    /// ([`dynamic_tension_n`]).
    pub fn with_gust_tension_factor(mut self, factor: f64) -> Self {
        self.gust_tension_factor = factor;
        self
    }

    /// The gust profile when it differs from the mean.
    fn distinct_gust(&self) -> Option<&WindProfile> {
        self.gust.as_ref().filter(|g| **g != self.wind)
    }

    fn cached(&self, key: CacheKey, f: impl FnOnce() -> [f64; 3]) -> [f64; 3] {
        if let Some(v) = self.cache.lock().ok().and_then(|c| c.get(&key).copied()) {
            return v;
        }
        let v = f();
        if let Ok(mut c) = self.cache.lock() {
            c.insert(key, v);
        }
        v
    }

    /// The equilibrium problem at a length with a net buoyancy.
    pub fn problem(
        &self,
        s: &AerostatSystem,
        buoyancy_n: f64,
        length_m: f64,
    ) -> EquilibriumProblem {
        self.problem_in(&self.wind, s, buoyancy_n, length_m)
    }

    /// [`Self::problem`] in the gust; `None` without gusts.
    pub fn gust_problem(
        &self,
        s: &AerostatSystem,
        buoyancy_n: f64,
        length_m: f64,
    ) -> Option<EquilibriumProblem> {
        let g = self.gust.as_ref()?;
        Some(self.problem_in(g, s, buoyancy_n, length_m))
    }

    fn problem_in(
        &self,
        wind: &WindProfile,
        s: &AerostatSystem,
        buoyancy_n: f64,
        length_m: f64,
    ) -> EquilibriumProblem {
        let mut cable = self.cable.clone();
        cable.mass_per_length_kg_m = s.mass_per_length_kg_m;
        cable.axial_stiffness_n = None;
        let mut body = self.body.clone();
        body.net_buoyancy_n = buoyancy_n;
        EquilibriumProblem {
            cable,
            body,
            wind: wind.clone(),
            air_density_kg_m3: self.air_density_kg_m3,
            tether_length_m: length_m,
            gravity_m_s2: s.gravity_m_s2,
        }
    }

    fn solve(&self, problem: &EquilibriumProblem) -> Option<Equilibrium> {
        problem.solve(&self.config).ok()
    }

    /// [`Self::solve`], started from the continuation's neighbours when
    /// there is one (and recorded in it).
    fn solve_along(
        &self,
        problem: &EquilibriumProblem,
        continuation: Option<&mut ShootingContinuation>,
    ) -> Option<Equilibrium> {
        let Some(c) = continuation else {
            return self.solve(problem);
        };
        let l = problem.tether_length_m;
        let eq = problem.solve_from(&self.config, c.start_at(l)).ok();
        c.record(l, eq.as_ref());
        eq
    }

    /// The bound on the tension the aerostat's ascent takes off at length
    /// `length_m` ([`super::ascent`]): the faster of the mean wind and the
    /// gust anywhere below it.
    pub fn ascent_drag(&self, length_m: f64) -> AscentDrag {
        let gust = self
            .gust
            .as_ref()
            .map_or(0.0, |g| g.fastest_below_m_s(length_m));
        AscentDrag::new(
            self.air_density_kg_m3,
            self.body.drag_coefficient,
            self.body.lift_coefficient,
            self.body.reference_area_m2,
            self.wind.fastest_below_m_s(length_m).max(gust),
        )
    }

    /// `S(L)` with the reserve buoyancy (N).
    pub fn stability_tension_n(&self, p: &PlanProblem, length_m: f64) -> f64 {
        self.stability_tension_along(p, length_m, None)
    }

    /// [`Self::stability_tension_n`] with the shootings started from the
    /// continuations of a sequence of lengths (its answer is the same to
    /// the shooting's tolerance).
    fn stability_tension_along(
        &self,
        p: &PlanProblem,
        length_m: f64,
        mut along: Option<&mut Along>,
    ) -> f64 {
        let mut offset_n = 0.0;
        if let Some(ge) = &self.ge {
            if !ge.string_in_wind(self) {
                return ge.stability_tension_n(self, p, length_m);
            }
            // converged GE in wind: the string criterion itself (the table,
            // made for the answer, holds its rates)
            let _ = ge.table(self, p);
            offset_n = ge.offset_n;
        }
        let b = p.reserve_buoyancy_n();
        let key = key(&p.system, length_m, b, self.criterion as usize, 0);
        let at = |wind: &WindProfile, c: Option<&mut ShootingContinuation>| {
            let pr = self.problem_in(wind, &p.system, b, length_m);
            match self.solve_along(&pr, c) {
                Some(eq) => ((self.criterion)(&pr, &eq), eq.altitude_m),
                None => (-b, f64::NAN),
            }
        };
        let [st, mean_alt, gust_alt] = self.cached(key, || {
            let (mean, mean_alt) = at(&self.wind, along.as_deref_mut().map(|a| &mut a.reserve[0]));
            match self.distinct_gust() {
                Some(g) => {
                    let (gust, gust_alt) = at(g, along.as_deref_mut().map(|a| &mut a.reserve[1]));
                    [mean.min(gust), mean_alt, gust_alt]
                }
                None => [mean, mean_alt, f64::NAN],
            }
        });
        if let Some(a) = along {
            // a cached answer continues the sequences too (recorded twice is a no-op)
            a.reserve[0].record_altitude(length_m, mean_alt);
            if self.distinct_gust().is_some() {
                a.reserve[1].record_altitude(length_m, gust_alt);
            }
        }
        st - offset_n
    }

    /// Winch tension, top tension and altitude with the full buoyancy.
    pub fn operating(&self, s: &AerostatSystem, length_m: f64) -> (f64, f64, f64) {
        self.operating_along(s, length_m, None)
    }

    fn operating_along(
        &self,
        s: &AerostatSystem,
        length_m: f64,
        continuation: Option<&mut ShootingContinuation>,
    ) -> (f64, f64, f64) {
        self.full_buoyancy_state(&self.wind, 1, s, length_m, continuation)
    }

    /// Winch tension, top tension and altitude with the full buoyancy in
    /// `wind` (cached as `kind`), the shooting continued when asked.
    fn full_buoyancy_state(
        &self,
        wind: &WindProfile,
        kind: u8,
        s: &AerostatSystem,
        length_m: f64,
        mut continuation: Option<&mut ShootingContinuation>,
    ) -> (f64, f64, f64) {
        let key = key(s, length_m, s.net_buoyancy_n, 0, kind);
        let [w, t, a] = self.cached(key, || {
            let pr = self.problem_in(wind, s, s.net_buoyancy_n, length_m);
            match self.solve_along(&pr, continuation.as_deref_mut()) {
                Some(eq) => [eq.winch_tension_n, eq.top_tension_n, eq.altitude_m],
                None => [f64::NAN; 3],
            }
        });
        if let Some(c) = continuation {
            c.record_altitude(length_m, a);
        }
        (w, t, a)
    }

    /// [`Self::operating`] in the gust; `None` without gusts.
    pub fn gust_operating(&self, s: &AerostatSystem, length_m: f64) -> Option<(f64, f64, f64)> {
        self.gust_operating_along(s, length_m, None)
    }

    fn gust_operating_along(
        &self,
        s: &AerostatSystem,
        length_m: f64,
        along: Option<&mut Along>,
    ) -> Option<(f64, f64, f64)> {
        let g = self.gust.as_ref()?;
        let (w, t, alt) = if *g == self.wind {
            self.operating_along(s, length_m, along.map(|a| &mut a.full[0]))
        } else {
            self.full_buoyancy_state(g, 2, s, length_m, along.map(|a| &mut a.full[1]))
        };
        let (calm_w, calm_t) = calm_tensions_n(s, length_m);
        let k = self.gust_tension_factor;
        Some((
            dynamic_tension_n(w, calm_w, k),
            dynamic_tension_n(t, calm_t, k),
            alt,
        ))
    }

    /// The winch and top tensions the limits bound: the larger of the
    /// mean's and the gust's (N).
    pub fn limit_tensions(&self, s: &AerostatSystem, length_m: f64) -> (f64, f64) {
        self.limit_tensions_along(s, length_m, None)
    }

    fn limit_tensions_along(
        &self,
        s: &AerostatSystem,
        length_m: f64,
        mut along: Option<&mut Along>,
    ) -> (f64, f64) {
        let (w, t, _) =
            self.operating_along(s, length_m, along.as_deref_mut().map(|a| &mut a.full[0]));
        match self.distinct_gust() {
            Some(_) => {
                let (gw, gt, _) = self
                    .gust_operating_along(s, length_m, along)
                    .expect("a gust profile is set");
                (w.max(gw), t.max(gt))
            }
            None => (w, t),
        }
    }
}

impl SteadyWind {
    /// The interpolation tolerances of [`sparse_along`] over `lengths`:
    /// forces (N) relative to the full buoyancy plus the weight of the
    /// longest tether, lengths (m) relative to the longest.
    fn tolerances(&self, p: &PlanProblem, lengths: &[f64]) -> (f64, f64) {
        let s = &p.system;
        let longest = lengths.iter().fold(0.0, |m: f64, &l| m.max(l.abs()));
        let force = s.net_buoyancy_n.abs() + s.mass_per_length_kg_m * s.gravity_m_s2 * longest;
        (
            RELATIVE_TOLERANCE * force,
            RELATIVE_TOLERANCE * longest.max(1.0),
        )
    }

    /// Whether a stability tension is in the criterion's smooth regime:
    /// finite and not the "unstable" answer of a slack tether or a failed
    /// shooting (`−(1 − r)F`).
    fn smooth(&self, p: &PlanProblem, stability_tension_n: f64) -> bool {
        stability_tension_n.is_finite() && stability_tension_n > -p.reserve_buoyancy_n()
    }
}

/// The continuations of the shootings along one sequence of lengths: with
/// the reserve and with the full buoyancy, each in the mean wind `[0]` and
/// in the gust `[1]`.
#[derive(Default)]
struct Along {
    reserve: [ShootingContinuation; 2],
    full: [ShootingContinuation; 2],
}

/// Lengths per chunk of [`along`]: each chunk starts cold, so the answer
/// depends on the chunking, never on the number of threads.
const ALONG_CHUNK: usize = 64;

impl super::ge_stability::GeWind for SteadyWind {
    fn problem(&self, s: &AerostatSystem, buoyancy_n: f64, length_m: f64) -> EquilibriumProblem {
        SteadyWind::problem(self, s, buoyancy_n, length_m)
    }
    fn air_density_kg_m3(&self) -> f64 {
        self.air_density_kg_m3
    }
    fn speed_m_s(&self, z_m: f64) -> f64 {
        self.wind.speed_m_s(z_m)
    }
}

/// `f` at every length, in fixed chunks on rayon, each chunk in order
/// with its own continuations: the equilibria of a fine grid of lengths
/// take about one RK4 pass each instead of five.
fn along<T: Send>(lengths: &[f64], f: impl Fn(f64, &mut Along) -> T + Sync) -> Vec<T> {
    lengths
        .par_chunks(ALONG_CHUNK)
        .flat_map_iter(|chunk| {
            let mut a = Along::default();
            chunk.iter().map(|&l| f(l, &mut a)).collect::<Vec<T>>()
        })
        .collect()
}

/// (length, buoyancy, ρA, g, criterion) bits and the kind of answer.
type CacheKey = (u64, u64, u64, u64, usize, u8);

fn key(s: &AerostatSystem, length_m: f64, buoyancy_n: f64, criterion: usize, kind: u8) -> CacheKey {
    (
        length_m.to_bits(),
        buoyancy_n.to_bits(),
        s.mass_per_length_kg_m.to_bits(),
        s.gravity_m_s2.to_bits(),
        criterion,
        kind,
    )
}

/// The air of a plan.
#[derive(Clone, Debug, Default)]
pub enum Air {
    #[default]
    Calm,
    Wind(Box<SteadyWind>),
}

/// The tolerance of the lift limit and of the length for an altitude,
/// relative to the longest length searched: a micrometre at a kilometre,
/// far below the equilibrium's own discretisation error (about 1e-6 of the
/// length in a sheared wind, [`super::sparse`]).
pub const LENGTH_TOLERANCE: f64 = 1e-9;

impl Air {
    pub fn is_calm(&self) -> bool {
        matches!(self, Self::Calm)
    }

    /// Whether stability is judged by the quasi-static GE criterion.
    pub fn has_ge(&self) -> bool {
        matches!(self, Self::Wind(w) if w.ge.is_some())
    }

    /// The loads at rest at one length.
    pub fn rest_loads(&self, p: &PlanProblem, length_m: f64) -> RestLoads {
        let s = &p.system;
        match self {
            Self::Calm => {
                let w = s.mass_per_length_kg_m * s.gravity_m_s2 * length_m;
                RestLoads {
                    stability_tension_n: p.reserve_buoyancy_n() - w,
                    winch_tension_n: s.net_buoyancy_n - w,
                    top_tension_n: s.net_buoyancy_n,
                    altitude_m: length_m,
                    ascent: AscentDrag::NONE,
                }
            }
            Self::Wind(w) => {
                let (winch, top, alt) = w.operating(s, length_m);
                RestLoads {
                    stability_tension_n: w.stability_tension_n(p, length_m),
                    winch_tension_n: winch,
                    top_tension_n: top,
                    altitude_m: alt,
                    ascent: w.ascent_drag(length_m),
                }
            }
        }
    }

    /// [`Self::rest_loads`] and [`Self::gust_rest_loads`] at every length
    /// (on rayon in wind, the shootings continued along the lengths).
    pub fn rest_loads_at(
        &self,
        p: &PlanProblem,
        lengths: &[f64],
    ) -> Vec<(RestLoads, Option<RestLoads>)> {
        let Self::Wind(w) = self else {
            return lengths
                .iter()
                .map(|&l| (self.rest_loads(p, l), None))
                .collect();
        };
        let s = &p.system;
        let gusty = w.gust.is_some();
        let (force, length) = w.tolerances(p, lengths);
        let tolerance = [force, force, force, length, force, force, length];
        let solved = |l: f64, a: &mut Along| {
            let st = w.stability_tension_along(p, l, Some(a));
            let (winch, top, alt) = w.operating_along(s, l, Some(&mut a.full[0]));
            let (gw, gt, ga) = w
                .gust_operating_along(s, l, Some(a))
                .unwrap_or((0.0, 0.0, 0.0));
            let values = [st, winch, top, alt, gw, gt, ga];
            Solved {
                values,
                // the GE criterion's S is solved at every length
                smooth: w.ge.is_none() && w.smooth(p, st) && values.iter().all(|v| v.is_finite()),
            }
        };
        sparse_along(lengths, tolerance, solved)
            .into_iter()
            .zip(lengths)
            .map(|(v, &l)| {
                let [stability_tension_n, winch, top, alt, gw, gt, ga] = v;
                let ascent = w.ascent_drag(l);
                let mean = RestLoads {
                    stability_tension_n,
                    winch_tension_n: winch,
                    top_tension_n: top,
                    altitude_m: alt,
                    ascent,
                };
                let gust = gusty.then_some(RestLoads {
                    stability_tension_n,
                    winch_tension_n: gw,
                    top_tension_n: gt,
                    altitude_m: ga,
                    ascent,
                });
                (mean, gust)
            })
            .collect()
    }

    /// The bound on the tension the aerostat's ascent takes off at a
    /// length ([`super::ascent`]); none in calm air without the air's data.
    pub fn ascent_drag(&self, length_m: f64) -> AscentDrag {
        match self {
            Self::Calm => AscentDrag::NONE,
            Self::Wind(w) => w.ascent_drag(length_m),
        }
    }

    /// Whether the wind has gusts.
    pub fn has_gust(&self) -> bool {
        matches!(self, Self::Wind(w) if w.gust.is_some())
    }

    /// The loads at rest at one length in the gust (full buoyancy; its
    /// `stability_tension_n` is the plan's `S`); `None` without gusts.
    pub fn gust_rest_loads(&self, p: &PlanProblem, length_m: f64) -> Option<RestLoads> {
        let Self::Wind(w) = self else {
            return None;
        };
        let (winch, top, alt) = w.gust_operating(&p.system, length_m)?;
        Some(RestLoads {
            stability_tension_n: w.stability_tension_n(p, length_m),
            winch_tension_n: winch,
            top_tension_n: top,
            altitude_m: alt,
            ascent: w.ascent_drag(length_m),
        })
    }

    /// `S(L)` at every length (on rayon in wind).
    pub fn stability_tensions_n(&self, p: &PlanProblem, lengths: &[f64]) -> Vec<f64> {
        match self {
            Self::Calm => lengths
                .iter()
                .map(|&l| self.rest_loads(p, l).stability_tension_n)
                .collect(),
            Self::Wind(w) if w.ge.is_some() => {
                along(lengths, |l, a| w.stability_tension_along(p, l, Some(a)))
            }
            Self::Wind(w) => {
                let (force, _) = w.tolerances(p, lengths);
                sparse_along(lengths, [force], |l, a: &mut Along| {
                    let st = w.stability_tension_along(p, l, Some(a));
                    Solved {
                        values: [st],
                        smooth: w.smooth(p, st),
                    }
                })
                .into_iter()
                .map(|[st]| st)
                .collect()
            }
        }
    }

    /// `(T_w, T_t)` with the full buoyancy at every length (on rayon in
    /// wind): with gusts the larger of the mean's and the gust's.
    pub fn operating_tensions_n(&self, p: &PlanProblem, lengths: &[f64]) -> Vec<(f64, f64)> {
        match self {
            Self::Calm => lengths
                .iter()
                .map(|&l| {
                    let r = self.rest_loads(p, l);
                    (r.winch_tension_n, r.top_tension_n)
                })
                .collect(),
            Self::Wind(w) => {
                let (force, _) = w.tolerances(p, lengths);
                sparse_along(lengths, [force, force], |l, a: &mut Along| {
                    let (winch, top) = w.limit_tensions_along(&p.system, l, Some(a));
                    Solved {
                        values: [winch, top],
                        smooth: winch.is_finite() && top.is_finite(),
                    }
                })
                .into_iter()
                .map(|[winch, top]| (winch, top))
                .collect()
            }
        }
    }

    /// The longest length whose rest state keeps the margin, `S(L) ≥
    /// ε(1 − r)F` (m): the static lift limit. Calm air: the closed form
    /// [`PlanProblem::lift_limit_m`]; wind: the crossing of `S` below the
    /// calm-air limit ([`bracket_crossing`] to [`LENGTH_TOLERANCE`] of it;
    /// the wind only shortens it for this criterion when the tether goes
    /// slack; `S` is taken as decreasing in `L`), its admissible end.
    pub fn lift_limit_m(&self, p: &PlanProblem) -> f64 {
        let calm = p.lift_limit_m();
        let Self::Wind(w) = self else {
            return calm;
        };
        let need = STABILITY_MARGIN * p.reserve_buoyancy_n();
        // the search's shootings start from its earlier points
        let mut along = Along::default();
        let mut margin = |l: f64| w.stability_tension_along(p, l, Some(&mut along)) - need;
        // The GE criterion may allow more than the calm string (bending).
        let calm = match &w.ge {
            Some(ge) => ge.search_upper_m(&**w, p).map_or(calm, |u| u.max(calm)),
            None => calm,
        };
        let at_calm = margin(calm);
        if at_calm >= 0.0 {
            return calm;
        }
        bracket_crossing(
            0.0,
            f64::INFINITY,
            calm,
            at_calm,
            LENGTH_TOLERANCE * calm,
            margin,
        )
        .0
    }

    /// The tether length at which the aerostat (full buoyancy) flies at
    /// `altitude_m`, searched up to `max_length_m` ([`bracket_crossing`] on
    /// the equilibrium altitude, taken as increasing in `L`, to
    /// [`LENGTH_TOLERANCE`] of `max_length_m`), its end at or above the
    /// altitude. Calm air: the altitude itself. `Err(reachable)` with the
    /// altitude at `max_length_m` when it is lower.
    pub fn length_for_altitude(
        &self,
        s: &AerostatSystem,
        altitude_m: f64,
        max_length_m: f64,
    ) -> Result<f64, f64> {
        let Self::Wind(w) = self else {
            return Ok(altitude_m);
        };
        let mut along = ShootingContinuation::default();
        let mut above = |l: f64| w.operating_along(s, l, Some(&mut along)).2 - altitude_m;
        let top = above(max_length_m);
        if !(top >= 0.0) {
            let top = top + altitude_m;
            return Err(if top.is_finite() { top } else { 0.0 });
        }
        let lo = altitude_m.min(max_length_m);
        let at_lo = above(lo);
        if at_lo >= 0.0 {
            return Ok(lo);
        }
        Ok(bracket_crossing(
            max_length_m,
            top,
            lo,
            at_lo,
            LENGTH_TOLERANCE * max_length_m,
            above,
        )
        .0)
    }
}
