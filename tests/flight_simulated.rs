//! The monitor on a flight flown in the dynamics model (issue 33): the
//! reference tether of issue 23 held at its 1000 m operating length in a
//! steady 8 m/s, hit by a `1 − cos` gust of +6 m/s over 20 s; its winch
//! tension at 10 Hz is the telemetry. The caution threshold is put halfway
//! between the steady tension and the gust's peak (both read from the
//! run), so the gust passes it and the steady flight does not. The
//! expected raise and clear times are found here by scanning the trace
//! directly: the monitor must raise the caution within 1 s of sample
//! time after the exceedance (1 s dwell, plus at most one sample
//! interval), clear it 5 s after the tension is back below 0.9 of the
//! threshold, and raise nothing in the same flight without the gust.

use tetherplan::numerics::dynamics::reference::reference_problem;
use tetherplan::numerics::dynamics::{DynamicsConfig, GustHistory, Outcome, simulate};
use tetherplan::numerics::monitor::{
    CheckName, FlightModel, Level, Limits, Monitor, Sample as Telemetry,
};

const DT: f64 = 0.1;

/// `(time, winch tension, wind at the aerostat)` of the flight, with or
/// without the gust.
fn fly(gust: bool) -> Vec<(f64, f64, f64)> {
    let mut p = reference_problem(8.0);
    if gust {
        p.gusts = vec![GustHistory::OneMinusCosine {
            start_time_s: 60.0,
            duration_s: 20.0,
            amplitude_m_s: 6.0,
        }];
    }
    let cfg = DynamicsConfig {
        segments: 50,
        duration_s: 150.0,
        sample_interval_s: DT,
        ..Default::default()
    };
    let run = simulate(&p, &cfg).unwrap();
    assert_eq!(run.outcome, Outcome::Completed);
    run.samples
        .iter()
        .map(|s| (s.time_s, s.winch_tension_n, s.aerostat_wind_m_s))
        .collect()
}

fn monitor(allowed_n: f64, trace: &[(f64, f64, f64)]) -> Monitor {
    let mut limits = Limits::new(1000.0);
    limits.allowable_tension_n = Some(allowed_n);
    let mut m = Monitor::new(FlightModel {
        limits,
        plan: None,
        ceiling: None,
    });
    for &(t, tension, wind) in trace {
        m.push(&Telemetry {
            tether_length_m: Some(1000.0),
            winch_rate_m_s: Some(0.0),
            winch_tension_n: Some(tension),
            wind_speed_m_s: Some(wind),
            ..Telemetry::at(t)
        });
    }
    m
}

#[test]
fn a_gust_in_the_dynamics_model_raises_the_caution_in_time_and_it_clears_after_the_dwell() {
    let calm = fly(false);
    let gusty = fly(true);
    let steady = calm[0].1;
    let peak = gusty.iter().map(|s| s.1).fold(f64::MIN, f64::max);
    assert!(peak > 1.2 * steady, "the gust loads the tether: {steady} → {peak} N");
    let caution = steady + 0.5 * (peak - steady);
    let allowed = caution / 0.8;

    // the exceedance and the expected raise, from the trace
    let first = gusty.iter().position(|s| s.1 > caution).unwrap();
    let t_exceed = gusty[first].0;
    let raise = gusty[first..]
        .iter()
        .take_while(|s| s.1 > caution)
        .find(|s| s.0 - t_exceed >= 1.0 - 1e-6)
        .expect("above the threshold for a second")
        .0;
    // the first 5 s run below 0.9 × threshold after the raise
    let raised_at = gusty.iter().position(|s| s.0 == raise).unwrap();
    let mut run_start: Option<f64> = None;
    let mut clear = None;
    for s in &gusty[raised_at + 1..] {
        if s.1 < 0.9 * caution {
            let start = *run_start.get_or_insert(s.0);
            if s.0 - start >= 5.0 - 1e-6 {
                clear = Some(s.0);
                break;
            }
        } else {
            run_start = None;
        }
    }
    let clear = clear.expect("the tension comes back below 0.9 of the threshold for 5 s");

    let m = monitor(allowed, &gusty);
    let alarms = m.alarms();
    assert_eq!(alarms.len(), 1, "{alarms:?}");
    let a = alarms[0];
    assert_eq!((a.check, a.level), (CheckName::Tension, Level::Caution));
    assert!((a.raised_at_s - raise).abs() < 1e-9, "{} vs {raise}", a.raised_at_s);
    assert!(a.raised_at_s - t_exceed <= 1.0 + DT + 1e-9, "within 1 s of sample time");
    assert_eq!(a.cleared_at_s, Some(clear));
    assert_eq!(m.status(Some(0.0)).state, Level::Normal);

    // the same flight without the gust raises nothing
    let quiet = monitor(allowed, &calm);
    assert!(quiet.alarms().is_empty(), "{:?}", quiet.alarms());
}
