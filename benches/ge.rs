//! GE cable, Table 7.1 data (ρ = 7800, A = 1e-5, F = 1000 N, m = 10 kg,
//! EI = 1000 N m², E* = 1e5, γ̃ = 1, L0 = 1 m), 20 elements, constant
//! length: free vibration from the static shape under a 100 N side force,
//! to t̄ = 1000 at Δt̄ = 0.1 (10 000 Newmark–Newton steps). Target ≤ 0.5 s.

use criterion::{Criterion, criterion_group, criterion_main};
use tetherplan::numerics::ge::element::TipLoad;
use tetherplan::numerics::ge::solver::{
    self, BaseMotion, Damping, Drive, EndLoads, LengthHistory, NewtonConfig, RunConfig, RunOutcome,
    State,
};
use tetherplan::numerics::ge::{GeModel, Section, TipBody};
use tetherplan::numerics::params::Kinematics;

fn setup() -> (GeModel, Drive, State, RunConfig) {
    let section = Section::from_ratios(1000.0, 1e5, 1.0, 7800.0 * 1e-5, 1.0).unwrap();
    let model = GeModel::new(
        section,
        20,
        TipBody {
            mass_kg: 10.0,
            link_length_m: 0.0,
        },
        9.81,
    )
    .unwrap();
    let buoyancy = TipLoad {
        force_n: [1000.0, 0.0],
        moment_n_m: 0.0,
    };
    let kin = Kinematics {
        length_m: 1.0,
        rate_m_s: 0.0,
        acceleration_m_s2: 0.0,
    };
    let pushed = TipLoad {
        force_n: [1000.0, 100.0],
        moment_n_m: 0.0,
    };
    let q0 = solver::static_solve(&model, kin, pushed, 4, NewtonConfig::default()).unwrap();
    let drive = Drive {
        length: LengthHistory::Constant(1.0),
        loads: EndLoads::steady(buoyancy),
        damping: Damping::default(),
        base: BaseMotion::default(),
        aero: None,
    };
    let v0 = vec![0.0; q0.len()];
    let a0 = solver::initial_acceleration(&model, &drive, 0.0, &q0, &v0).unwrap();
    let time_scale = (section.rotary_inertia_kg_m / section.bending_stiffness_n_m2).sqrt(); // L0 √(I_ρ/EI)
    let config = RunConfig {
        time_step_s: 0.1 * time_scale,
        duration_s: 1000.0 * time_scale,
        newton: NewtonConfig::default(),
        record_every: 10,
        eigen_every: 0,
    };
    (
        model,
        drive,
        State {
            time_s: 0.0,
            q: q0,
            v: v0,
            a: a0,
        },
        config,
    )
}

fn bench(c: &mut Criterion) {
    let (model, drive, state, config) = setup();
    let r = solver::run(&model, &drive, state.clone(), config, &mut |_, _| true);
    assert_eq!(r.outcome, RunOutcome::Completed);
    eprintln!(
        "GE Table 7.1, 20 elements, {} steps: Newton iterations per step mean {:.3}, max {}",
        r.steps,
        r.mean_newton_iterations(),
        r.newton_iterations_max
    );
    let mut g = c.benchmark_group("ge");
    g.sample_size(10);
    g.bench_function("table_7_1_free_vibration_20_elements_tbar_1000", |b| {
        b.iter(|| solver::run(&model, &drive, state.clone(), config, &mut |_, _| true))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
