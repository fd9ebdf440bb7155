//! A GE critical-time search you can trust (issue 10, item 3), Table 7.1
//! data, 20 elements, default search settings (Δt = 0.02 s, QEP every 25
//! steps, generalized-α with ρ∞ = 0, up to 8 step halvings):
//!
//! * perturbed charts (F0 = 0, 200, 400 N at 12, 26 and 40 m/s) complete:
//!   a failed Newton step is halved and retried;
//! * a start from rest and a start in steady payout give the same t*
//!   within 2 % at E* = 1e5 (the dissipation removes the unresolved axial
//!   ringing a start from rest sets off, which without it shows as a
//!   false early onset);
//! * the closed forms printed beside an onset are flagged when the onset
//!   is a start-up transient (E* = 1 at 75 m/s) and not when it is the
//!   quasi-static loss of tension (E* = 1e5 at 12 m/s).
//!
//! The runs take about a second each; each test fans them out on rayon.

use rayon::prelude::*;
use tetherplan::numerics::ge::chart::{
    ClosedFormVerdict, GeChartRequest, GeChartSystem, deployment_chart,
};
use tetherplan::numerics::ge::critical::{
    CriticalConfig, CriticalProblem, GeCriticalTime, GeOnset, StartState, critical_time,
};
use tetherplan::numerics::ge::solver::Scheme;
use tetherplan::numerics::parallel::Parallelism;
use tetherplan::numerics::profile::Profile;

fn never() -> bool {
    false
}

fn search(
    rate: f64,
    stiffness_ratio: f64,
    start: StartState,
    config: &CriticalConfig,
) -> GeCriticalTime {
    let model = GeChartSystem::table_7_1().model(stiffness_ratio).unwrap();
    let problem = CriticalProblem {
        profile: Profile::constant_rate(1.0, rate, None).unwrap(),
        net_buoyancy_n: 1000.0,
        perturbation: None,
        aero: None,
        start,
    };
    critical_time(&model, &problem, config, &never).unwrap()
}

fn t_star(r: &GeCriticalTime) -> f64 {
    match r.onset {
        GeOnset::During { time_s, .. } => time_s,
        other => panic!("expected an onset during the deployment, got {other:?}"),
    }
}

/// Issue 10: F0 = 0, 200, 400 N at 12, 26 and 40 m/s all complete at the
/// default settings, with the Table 7.1 aerostat (10 kg) and with a
/// massless one. Before this issue (average acceleration, no step cuts)
/// F0 = 400 N failed with `newton_failed` at all three rates. Reference:
/// every point has an onset during the deployment, and the perturbed t*
/// is within 10 % of the unperturbed one (thesis Fig. 7.4: F0 moves t* by
/// a few per cent at most below 70 m/s).
#[test]
fn perturbed_chart_completes_at_default_settings() {
    let charts: Vec<_> = [10.0, 0.0]
        .into_par_iter()
        .map(|mass| {
            let mut request = GeChartRequest::table_7_1(vec![12.0, 26.0, 40.0], vec![1e5]);
            request.system.aerostat_mass_kg = mass;
            request.perturbation_forces_n = vec![0.0, 200.0, 400.0];
            (
                mass,
                deployment_chart(&request, Parallelism::Rayon, &|_, _| {}, &never).unwrap(),
            )
        })
        .collect();
    for (mass, series) in &charts {
        let unperturbed: Vec<f64> = series[0]
            .points
            .iter()
            .map(|p| p.critical_time_s.unwrap())
            .collect();
        for s in series {
            for (p, t0) in s.points.iter().zip(&unperturbed) {
                println!(
                    "m = {mass} kg, F0 = {:3.0} N, {:4.1} m/s: t* = {:?} s, {} steps, {} step cuts, closed form applies: {}",
                    s.perturbation_force_n,
                    p.rate_m_s,
                    p.critical_time_s,
                    p.steps,
                    p.step_cuts,
                    p.closed_form.applies()
                );
                let t = p.critical_time_s.unwrap_or_else(|| {
                    panic!(
                        "F0 = {} N, {} m/s: {:?}",
                        s.perturbation_force_n, p.rate_m_s, p.onset
                    )
                });
                assert!(matches!(p.onset, GeOnset::During { .. }));
                assert!((t / t0 - 1.0).abs() < 0.10, "t* = {t} against {t0}");
                assert!(p.closed_form.applies());
            }
        }
    }
}

/// The step cut on its own: with average acceleration (no dissipation),
/// F0 = 400 N at 26 and 40 m/s fails with `newton_failed` when a failed
/// step may not be retried, and completes when it may be halved (one or
/// two cuts), with t* within 2 % of the default scheme's.
#[test]
fn a_failed_newton_step_is_halved_and_retried() {
    use tetherplan::numerics::ge::critical::TipPerturbation;
    let cases: Vec<(f64, u32)> = vec![(26.0, 0), (26.0, 8), (40.0, 0), (40.0, 8)];
    let run = |v: f64, scheme: Scheme, cuts: u32| {
        let model = GeChartSystem::table_7_1().model(1e5).unwrap();
        let problem = CriticalProblem {
            profile: Profile::constant_rate(1.0, v, None).unwrap(),
            net_buoyancy_n: 1000.0,
            perturbation: Some(TipPerturbation::held(400.0)),
            aero: None,
            start: StartState::AtRest,
        };
        let config = CriticalConfig {
            scheme,
            max_step_cuts: cuts,
            ..CriticalConfig::default()
        };
        critical_time(&model, &problem, &config, &never).unwrap()
    };
    let results: Vec<GeCriticalTime> = cases
        .par_iter()
        .map(|&(v, cuts)| run(v, Scheme::AverageAcceleration, cuts))
        .collect();
    let reference: Vec<f64> = [26.0, 40.0]
        .par_iter()
        .map(|&v| t_star(&run(v, CriticalConfig::default().scheme, 8)))
        .collect();
    for ((v, cuts), r) in cases.iter().zip(&results) {
        println!(
            "{v} m/s, F0 = 400 N, average acceleration, at most {cuts} cuts: {:?}, {} cuts",
            r.onset, r.step_cuts
        );
    }
    for k in 0..2 {
        let (strict, cut) = (&results[2 * k], &results[2 * k + 1]);
        assert!(matches!(strict.onset, GeOnset::NewtonFailed(_)));
        assert!(cut.step_cuts >= 1);
        assert!((t_star(cut) / reference[k] - 1.0).abs() < 0.02);
    }
}

/// Issue 10: from rest and in steady payout, t* agrees within 2 % at
/// E* = 1e5, 12 and 40 m/s with the default (dissipative) scheme. Without
/// dissipation (average acceleration) the start from rest goes unstable
/// early; that is printed, not asserted.
#[test]
fn from_rest_matches_steady_payout_with_dissipation() {
    let default = CriticalConfig::default();
    assert_eq!(
        default.scheme,
        Scheme::GeneralizedAlpha { rho_infinity: 0.0 }
    );
    let undamped = CriticalConfig {
        scheme: Scheme::AverageAcceleration,
        ..default
    };
    let cases: Vec<(f64, StartState, bool)> = [12.0, 40.0]
        .into_iter()
        .flat_map(|v| {
            [
                (v, StartState::AtRest, true),
                (v, StartState::SteadyPayout, true),
                (v, StartState::AtRest, false),
            ]
        })
        .collect();
    let t: Vec<f64> = cases
        .par_iter()
        .map(|&(v, start, dissipative)| {
            let config = if dissipative { &default } else { &undamped };
            t_star(&search(v, 1e5, start, config))
        })
        .collect();
    for (k, v) in [12.0, 40.0].into_iter().enumerate() {
        let (rest, steady, rest_undamped) = (t[3 * k], t[3 * k + 1], t[3 * k + 2]);
        println!(
            "{v} m/s, E* = 1e5: t* from rest {rest:.3} s, steady payout {steady:.3} s ({:+.2} %); \
             from rest without dissipation {rest_undamped:.3} s",
            100.0 * (rest / steady - 1.0)
        );
        assert!((rest / steady - 1.0).abs() < 0.02);
    }
}

/// Issue 10: the closed forms are flagged when the onset is a start-up
/// transient. E* = 1 (EA = F = 1000 N) at 75 m/s from rest: the cable
/// starts with a strain of order one and a reel-out rate of 0.66 axial
/// wave speeds, and the axial force at the guide at t* departs from the
/// steady-payout tension by far more than the 2 % of h* the flag allows.
/// E* = 1e5 at 12 m/s: the onset is quasi-static and the flag is clear.
#[test]
fn closed_form_is_flagged_on_a_start_up_transient() {
    let runs: Vec<(f64, f64)> = vec![(75.0, 1.0), (12.0, 1e5)];
    let verdicts: Vec<(ClosedFormVerdict, GeCriticalTime)> = runs
        .par_iter()
        .map(|&(v, es)| {
            let r = search(v, es, StartState::AtRest, &CriticalConfig::default());
            let model = GeChartSystem::table_7_1().model(es).unwrap();
            (
                tetherplan::numerics::ge::chart::closed_form_verdict(&model, v, 1000.0, false, &r),
                r,
            )
        })
        .collect();
    for ((v, es), (verdict, r)) in runs.iter().zip(&verdicts) {
        println!(
            "{v} m/s, E* = {es}: {:?}, root force {:?} N, verdict {verdict:?}: {:?}",
            r.onset,
            r.onset_root_axial_force_n,
            verdict.reason()
        );
    }
    assert!(matches!(verdicts[0].0, ClosedFormVerdict::Transient { .. }));
    assert!(!verdicts[0].0.applies());
    assert!(
        verdicts[0]
            .0
            .reason()
            .unwrap()
            .contains("start-up transient")
    );
    assert_eq!(verdicts[1].0, ClosedFormVerdict::Applies);
}
