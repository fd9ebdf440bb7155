//! The physical branch of the quasi-static GE equilibrium in a steady wind
//! (issue 21): the blown-down state reached by paying out, which the
//! converged onset search of [`super::qs_converged`] follows on every mesh.
//!
//! **Why the mesh levels disagreed in wind.** Measured on the thesis
//! tether (ρA = 0.078 kg/m, F = 1000 N, d = 5 mm, C_n = 1.2, C_D A =
//! 0.9 m², EA = 10⁶ N, EI = 1 N m², 8 m/s uniform, payout 10 m/s): the
//! linear GE element under-integrated in the rotation has equilibria in
//! which the section rotation winds by multiples of 2π between two nodes
//! (a "wrapped" element: its midpoint frame is that of the unwrapped
//! shape, so it costs only the bending energy `EI (2πk/h)² h / 2`, a few
//! joules at EI = 1 N m²). A Newton started far from the solution (the
//! straight tether continued in the dynamic pressure, a scan point 100 m
//! away, a coarser level prolonged) lands on such states: a continuation
//! in the length in 0.5 % steps reached rotation jumps of 7 to 232 rad
//! between neighbouring nodes and altitudes 30–120 m below the continuum
//! tether at 1000 m (882 / 863 / 893 / 877 m at 40 / 80 / 160 / 320
//! elements against 927.2 m), with `det K` changing sign 4 to 11 times
//! between 730 and 1460 m: every level's "divergence root" was the first
//! of these, a different spurious state on each mesh (1134 … 1316 m).
//! Started from the continuum tether's shape instead, every mesh from 20
//! to 640 elements reaches one state, which converges to the continuum
//! tether ([`crate::numerics::tether::equilibrium`], 0.007 % from MoorDyn):
//! at EI = 10⁻³ N m² and rest, 1000 m, the altitude error is 0.230 /
//! 0.057 / 0.014 / 0.004 / 0.002 / 0.001 m at 20 … 640 elements (second
//! order) and the guide force 12.3 / 6.1 / 3.0 / 1.5 / 0.75 / 0.37 N
//! (first order: the first element's force is its mid-element value);
//! and `det K` stays positive up to the ground contact (1230 m).
//!
//! **The branch.** [`branch_equilibrium`] accepts an equilibrium only when
//! it is on that branch: no element whose frame (the mean rotation of
//! its nodes, where it is integrated) turns [`MAX_FRAME_TURN`] or more
//! from its chord (a wrap; the nodes' own rotations may zig-zag about the
//! tangent, a mode the one-point rule barely sees at small `EI`), and
//! the aerostat within
//! [`TIP_TOLERANCE`] of the length from the continuum tether's. Newton
//! starts from a known nearby state of the caller, then from the
//! continuum shape interpolated onto the mesh, then (last resort) from the
//! straight tether continued in the dynamic pressure; the first accepted
//! state is the answer. The Newton steps from a start are limited
//! ([`MAX_STEP_ROTATION_RAD`], [`MAX_STEP_DISPLACEMENT`] of the length), so
//! that it converges to the state next to its start instead of jumping
//! to a wrapped one.
//!
//! **Ground contact.** The GE model has no ground: past the length at
//! which the continuum tether's lower end reaches the ground at the winch
//! (the envelope's `slack` limit) its equilibria hang below the guide and
//! are not the tether's. [`airborne_length_m`] finds that length (the
//! grounding of the continuum tether, bisected to `10⁻⁶` relative); the
//! length searches in wind stop there, and a state past it has no branch
//! equilibrium.

use super::GeModel;
use super::air_load::AirLoads;
use super::element::{TipLoad, node};
use super::quasi_static::{QsConfig, StepLimit, newton_from, wind_equilibrium};
use crate::numerics::params::Kinematics;
use crate::numerics::tether::equilibrium::{
    Body, Cable, Equilibrium, EquilibriumConfig, EquilibriumProblem,
};

/// Largest angle between an element's frame (the mean of its nodes'
/// rotations, where the element is integrated) and its chord on a branch
/// equilibrium (rad).
pub const MAX_FRAME_TURN: f64 = std::f64::consts::FRAC_PI_2;
/// Largest distance of the aerostat from the continuum tether's, as a
/// fraction of the length.
pub const TIP_TOLERANCE: f64 = 1.0;
/// Largest rotation change of one Newton step from a start (rad).
pub const MAX_STEP_ROTATION_RAD: f64 = 0.25;
/// Largest displacement change of one Newton step, as a fraction of the length.
pub const MAX_STEP_DISPLACEMENT: f64 = 0.02;
/// RK4 steps of the continuum tether behind a start (at least 4 per element).
const MIN_CONTINUUM_STEPS: usize = 100;

/// The continuum tether of the GE system at `length_m`: the same cable,
/// aerostat loads and wind (the aerostat's `C_D A`, `C_L A` on a unit
/// reference area).
pub fn continuum_problem(
    model: &GeModel,
    air: &AirLoads,
    net_buoyancy_n: f64,
    length_m: f64,
) -> EquilibriumProblem {
    EquilibriumProblem {
        cable: Cable {
            mass_per_length_kg_m: model.section.mass_per_length_kg_m,
            diameter_m: air.cable_diameter_m.max(1e-9),
            normal_drag_coefficient: air.cable_normal_drag_coefficient,
            axial_stiffness_n: Some(model.section.axial_stiffness_n),
            breaking_strength_n: None,
        },
        body: Body {
            net_buoyancy_n,
            drag_coefficient: air.aerostat_drag_area_m2,
            lift_coefficient: air.aerostat_lift_area_m2,
            reference_area_m2: 1.0,
        },
        wind: air.wind.clone(),
        air_density_kg_m3: air.air_density_kg_m3,
        tether_length_m: length_m,
        gravity_m_s2: model.gravity_m_s2,
    }
}

fn continuum(
    model: &GeModel,
    air: &AirLoads,
    net_buoyancy_n: f64,
    length_m: f64,
    keep_shape: bool,
) -> Option<Equilibrium> {
    let e = continuum_problem(model, air, net_buoyancy_n, length_m)
        .solve(&EquilibriumConfig {
            steps: MIN_CONTINUUM_STEPS.max(4 * model.elements),
            keep_shape,
            ..Default::default()
        })
        .ok()?;
    e.converged.then_some(e)
}

/// Whether the continuum tether at `length_m` is airborne all along (its
/// lower end above the ground at the winch, tension everywhere).
pub fn airborne(model: &GeModel, air: &AirLoads, net_buoyancy_n: f64, length_m: f64) -> bool {
    continuum(model, air, net_buoyancy_n, length_m, false).is_some_and(|e| !e.slack)
}

/// The longest airborne length in `[lo, hi]` (module docs): `hi` when the
/// tether is airborne there, else the grounding length bisected to
/// `10⁻⁶` relative (`lo` when grounded already at `lo`).
pub fn airborne_length_m(
    model: &GeModel,
    air: &AirLoads,
    net_buoyancy_n: f64,
    (lo, hi): (f64, f64),
) -> f64 {
    if air.is_calm() || airborne(model, air, net_buoyancy_n, hi) {
        return hi;
    }
    if !airborne(model, air, net_buoyancy_n, lo) {
        return lo;
    }
    let (mut a, mut b) = (lo, hi);
    while b - a > 1e-6 * b {
        let m = 0.5 * (a + b);
        if airborne(model, air, net_buoyancy_n, m) {
            a = m;
        } else {
            b = m;
        }
    }
    a
}

/// The branch reference at `length_m`: the continuum shape interpolated
/// onto the nodes of `model` (`u1 = z − ζL`, `u2 = x`, the rotation the
/// chord's angle from the vertical) and its aerostat position; `None`
/// when the continuum tether is grounded or not found. Memoised per
/// thread on every input (the same answer bit for bit, see
/// `START_CACHE`).
pub fn continuum_start(
    model: &GeModel,
    air: &AirLoads,
    net_buoyancy_n: f64,
    length_m: f64,
) -> Option<(Vec<f64>, [f64; 2])> {
    let key = StartKey::of(model, air, net_buoyancy_n, length_m);
    if let Some(hit) = START_CACHE.with(|c| {
        c.borrow()
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v.clone())
    }) {
        return hit;
    }
    let start = solve_continuum_start(model, air, net_buoyancy_n, length_m);
    START_CACHE.with(|c| {
        let mut c = c.borrow_mut();
        if c.len() >= START_CACHE_ENTRIES {
            c.remove(0);
        }
        c.push((key, start.clone()));
    });
    start
}

/// Continuum starts kept per thread ([`continuum_start`]).
const START_CACHE_ENTRIES: usize = 8;

/// Everything [`continuum_start`] depends on: the mesh's element count
/// (nodes and RK4 steps), the cable's `ρA`, `EA` and gravity, the air, the
/// buoyancy and the length (floats by their bits).
#[derive(Clone, Debug, PartialEq)]
struct StartKey {
    elements: usize,
    scalars: [u64; 5],
    air: AirLoads,
}

impl StartKey {
    fn of(model: &GeModel, air: &AirLoads, net_buoyancy_n: f64, length_m: f64) -> Self {
        Self {
            elements: model.elements,
            scalars: [
                model.section.mass_per_length_kg_m.to_bits(),
                model.section.axial_stiffness_n.to_bits(),
                model.gravity_m_s2.to_bits(),
                net_buoyancy_n.to_bits(),
                length_m.to_bits(),
            ],
            air: air.clone(),
        }
    }
}

type CachedStart = Option<(Vec<f64>, [f64; 2])>;

thread_local! {
    /// The last [`START_CACHE_ENTRIES`] continuum starts of this thread: a
    /// search along the rate solves every state at one length, and each
    /// state's branch acceptance needs the continuum tether there.
    static START_CACHE: std::cell::RefCell<Vec<(StartKey, CachedStart)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

fn solve_continuum_start(
    model: &GeModel,
    air: &AirLoads,
    net_buoyancy_n: f64,
    length_m: f64,
) -> Option<(Vec<f64>, [f64; 2])> {
    let e = continuum(model, air, net_buoyancy_n, length_m, true)?;
    if e.slack || e.shape.len() < 2 {
        return None;
    }
    let sh = &e.shape;
    let n = model.elements;
    let mut q = vec![0.0; model.dofs()];
    for k in 1..=n {
        let zeta = k as f64 / n as f64;
        let s = zeta * length_m;
        let i = sh.partition_point(|p| p.s_m < s).clamp(1, sh.len() - 1);
        let (a, b) = (sh[i - 1], sh[i]);
        let t = if b.s_m > a.s_m {
            ((s - a.s_m) / (b.s_m - a.s_m)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let x = a.x_m + t * (b.x_m - a.x_m);
        let z = a.z_m + t * (b.z_m - a.z_m);
        q[GeModel::dof(k, 0)] = z - s;
        q[GeModel::dof(k, 1)] = x;
        q[GeModel::dof(k, 2)] = (b.x_m - a.x_m).atan2(b.z_m - a.z_m);
    }
    Some((q, [e.altitude_m, e.downwind_m]))
}

/// Whether `q` is on the branch of the reference aerostat position `tip`
/// (module docs).
pub fn on_branch(model: &GeModel, length_m: f64, q: &[f64], tip: [f64; 2]) -> bool {
    let n = model.elements;
    let h = length_m / n as f64;
    // node k's position `(ζL + u1, u2)` and rotation (node 0: the clamp)
    let at = |k: usize| {
        if k == 0 {
            [0.0, 0.0, 0.0]
        } else {
            let v = node(q, k);
            [k as f64 * h + v[0], v[1], v[2]]
        }
    };
    let smooth = (1..=n).all(|k| {
        let (a, b) = (at(k - 1), at(k));
        let chord = (b[1] - a[1]).atan2(b[0] - a[0]);
        (0.5 * (a[2] + b[2]) - chord).abs() < MAX_FRAME_TURN
    });
    let top = node(q, n);
    let (dz, dx) = (length_m + top[0] - tip[0], top[1] - tip[1]);
    smooth && dz.hypot(dx) <= TIP_TOLERANCE * length_m
}

/// The branch equilibrium at `kin` (module docs): from `near` (a known
/// state of the caller close along its parameter), else the continuum
/// shape, else the continuation from the straight tether; `None` when
/// none of them reaches the branch (or the tether is grounded).
pub fn branch_equilibrium(
    model: &GeModel,
    kin: Kinematics,
    load: TipLoad,
    air: &AirLoads,
    config: &QsConfig,
    near: Option<&[f64]>,
) -> Option<Vec<f64>> {
    let (start, tip) = continuum_start(model, air, load.force_n[0], kin.length_m)?;
    let accept = |q: Vec<f64>| on_branch(model, kin.length_m, &q, tip).then_some(q);
    let limit = StepLimit {
        rotation_rad: MAX_STEP_ROTATION_RAD,
        displacement_m: MAX_STEP_DISPLACEMENT * kin.length_m,
    };
    for s in near.into_iter().chain(std::iter::once(start.as_slice())) {
        let mut q = s.to_vec();
        if newton_from(model, kin, load, air, config, &mut q, Some(limit)).is_ok()
            && let Some(q) = accept(q)
        {
            return Some(q);
        }
    }
    let eq = wind_equilibrium(model, kin, load, air, config, None).ok()?;
    accept(eq.q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::ge::{Section, TipBody};
    use crate::numerics::tether::WindProfile;

    // The thesis tether of tests/verification_ge_converged.rs in 8 m/s.
    const RHO_A: f64 = 0.078;
    const F: f64 = 1000.0;
    const D: f64 = 0.005;

    fn model(ei: f64, elements: usize) -> GeModel {
        let s = Section::new(1e6, 1e6, ei, RHO_A, RHO_A * D * D / 16.0).unwrap();
        GeModel::new(
            s,
            elements,
            TipBody {
                mass_kg: 10.0,
                link_length_m: 0.0,
            },
            9.81,
        )
        .unwrap()
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

    /// EI → 0, at rest: the branch equilibrium converges with the mesh to
    /// the continuum tether (an independent shooting solver, 0.007 % from
    /// MoorDyn): the aerostat at second order, the guide force (the first
    /// element's, a mid-element value) at first order. Measured at 1000 m:
    /// altitude error 0.230 / 0.057 / 0.014 / 0.004 m at 20 … 160 elements.
    #[test]
    fn branch_converges_to_the_continuum_tether() {
        let (l, a) = (1000.0, air(8.0));
        let reference = continuum_problem(&model(1e-3, 20), &a, F, l)
            .solve(&EquilibriumConfig {
                steps: 4000,
                keep_shape: false,
                ..Default::default()
            })
            .unwrap();
        let kin = Kinematics {
            length_m: l,
            rate_m_s: 0.0,
            acceleration_m_s2: 0.0,
        };
        let mut last: Option<(f64, f64)> = None;
        for n in [20, 40, 80, 160] {
            let m = model(1e-3, n);
            let q = branch_equilibrium(&m, kin, load(), &a, &QsConfig::default(), None).unwrap();
            let top = node(&q, n);
            let tip = (l + top[0] - reference.altitude_m).hypot(top[1] - reference.downwind_m);
            let force = (crate::numerics::ge::critical::root_axial_force_n(&m, l, &q)
                - reference.winch_tension_n)
                .abs();
            if let Some((t0, f0)) = last {
                assert!(tip < t0 / 3.0 || tip < 2e-3, "{n}: tip {tip} after {t0}");
                assert!(force < 0.6 * f0, "{n}: force {force} after {f0}");
            }
            last = Some((tip, force));
        }
        let (tip, force) = last.unwrap();
        assert!(tip < 0.01 && force < 2.0, "{tip} m, {force} N");
    }

    /// A wrapped element (its nodes' rotations 4π apart: the midpoint
    /// frame is the unwrapped one) is not on the branch; the branch state
    /// itself is.
    #[test]
    fn wrapped_states_are_not_on_the_branch() {
        let (l, a, n) = (1000.0, air(8.0), 40);
        let m = model(1.0, n);
        let kin = Kinematics {
            length_m: l,
            rate_m_s: 10.0,
            acceleration_m_s2: 0.0,
        };
        let (_, tip) = continuum_start(&m, &a, F, l).unwrap();
        let q = branch_equilibrium(&m, kin, load(), &a, &QsConfig::default(), None).unwrap();
        assert!(on_branch(&m, l, &q, tip));
        let mut wrapped = q.clone();
        for k in 10..=n {
            wrapped[GeModel::dof(k, 2)] += 4.0 * std::f64::consts::PI;
        }
        assert!(!on_branch(&m, l, &wrapped, tip));
    }

    /// The airborne limit is where the continuum tether's lower end
    /// reaches the ground (1228.55 m in 8 m/s), and no branch state
    /// exists past it.
    #[test]
    fn airborne_length_is_the_ground_contact() {
        let (m, a) = (model(1.0, 20), air(8.0));
        let lg = airborne_length_m(&m, &a, F, (1.0, 1960.0));
        assert!((lg - 1228.55).abs() < 0.05, "{lg}");
        assert!(airborne(&m, &a, F, 0.999 * lg));
        assert!(!airborne(&m, &a, F, 1.001 * lg));
        assert!(continuum_start(&m, &a, F, 1.001 * lg).is_none());
        // calm air: no ground contact before the lift limit
        assert_eq!(
            airborne_length_m(&m, &AirLoads::calm(), F, (1.0, 1960.0)),
            1960.0
        );
    }

    /// The memoised continuum start is the solved one bit for bit, and a
    /// change of any input (length, buoyancy, mesh, wind) is solved anew.
    #[test]
    fn memoised_start_is_the_solved_one() {
        let (m, a) = (model(1.0, 20), air(8.0));
        let bits = |s: &Option<(Vec<f64>, [f64; 2])>| {
            s.as_ref().map(|(q, t)| {
                q.iter()
                    .chain(t.iter())
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>()
            })
        };
        for (m, a, f, l) in [
            (m.clone(), a.clone(), F, 900.0),
            (m.clone(), a.clone(), F, 900.0 + 1e-9),
            (m.clone(), a.clone(), 0.9 * F, 900.0),
            (model(1.0, 40), a.clone(), F, 900.0),
            (m.clone(), air(6.0), F, 900.0),
            (m.clone(), a.clone(), F, 1300.0),
        ] {
            let solved = solve_continuum_start(&m, &a, f, l);
            let first = continuum_start(&m, &a, f, l);
            let again = continuum_start(&m, &a, f, l);
            assert_eq!(bits(&first), bits(&solved), "{l} m, {f} N");
            assert_eq!(bits(&again), bits(&solved), "{l} m, {f} N (cached)");
        }
        // 1300 m in 8 m/s is past the ground contact (1228.55 m)
        assert!(continuum_start(&m, &a, F, 1300.0).is_none());
        assert_ne!(
            bits(&continuum_start(&m, &a, F, 900.0)),
            bits(&continuum_start(&m, &air(6.0), F, 900.0))
        );
    }
}
