//! The live-flight monitor's pure numerics (issue 33, `numerics::monitor`):
//! the rolling wind windows against direct sums, one level's dwell and
//! hysteresis, the ceiling table against closed forms, and the monitor as a
//! whole (spikes, latching, acknowledgement, staleness, order, each check
//! against its reference computed here).

mod window {
    use tetherplan::numerics::monitor::window::*;

    /// Direct O(n) means over the same half-open windows.
    fn direct_mean(s: &[(f64, f64)], t: f64, span: f64) -> f64 {
        let w: Vec<f64> = s
            .iter()
            .filter(|(ti, _)| *ti > t - span && *ti <= t)
            .map(|p| p.1)
            .collect();
        w.iter().sum::<f64>() / w.len() as f64
    }

    fn series(n: usize) -> Vec<(f64, f64)> {
        // irregular times, a deterministic wiggly value
        let mut t = 0.0;
        (0..n)
            .map(|i| {
                t += 0.05 + 0.1 * ((i * 7919 % 13) as f64 / 13.0);
                (
                    t,
                    8.0 + 3.0 * (0.37 * i as f64).sin() + ((i * 104729 % 17) as f64) / 17.0,
                )
            })
            .collect()
    }

    #[test]
    fn rolling_mean_matches_the_direct_mean_to_1e_12() {
        let s = series(20_000);
        let mut w = RollingMean::new(600.0);
        for (i, &(t, v)) in s.iter().enumerate() {
            let m = w.push(t, v);
            if i % 997 == 0 || i + 1 == s.len() {
                let d = direct_mean(&s[..=i], t, 600.0);
                assert!((m - d).abs() <= 1e-12 * d, "i {i}: {m} vs {d}");
            }
        }
    }

    #[test]
    fn gust_is_the_largest_3_s_mean_of_the_last_10_minutes() {
        let s = series(12_000);
        let mut w = WindWindow::new(600.0, 3.0);
        for (i, &(t, v)) in s.iter().enumerate() {
            let (_, gust) = w.push(t, v);
            if i % 1499 == 0 || i + 1 == s.len() {
                // the 3 s mean at every sample time of the last 600 s
                let direct = s[..=i]
                    .iter()
                    .filter(|(tj, _)| *tj > t - 600.0)
                    .map(|&(tj, _)| direct_mean(&s[..=i], tj, 3.0))
                    .fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    (gust - direct).abs() <= 1e-12 * direct,
                    "i {i}: {gust} vs {direct}"
                );
            }
        }
    }

    #[test]
    fn a_step_in_the_wind_reaches_the_mean_linearly_and_the_gust_after_3_s() {
        // 1 Hz samples: 5 m/s for 600 s then 10 m/s
        let mut w = WindWindow::new(600.0, 3.0);
        for k in 1..=600 {
            w.push(k as f64, 5.0);
        }
        let (m, g) = w.push(601.0, 10.0);
        // the window (1, 601] holds 599 fives and one ten
        assert!((m - (599.0 * 5.0 + 10.0) / 600.0).abs() < 1e-12);
        assert!((g - (5.0 + 5.0 + 10.0) / 3.0).abs() < 1e-12);
        w.push(602.0, 10.0);
        let (_, g) = w.push(603.0, 10.0);
        assert_eq!(g, 10.0);
        // after 10 minutes of ten, the fives are gone from both
        let mut last = (0.0, 0.0);
        for k in 604..=1203 {
            last = w.push(k as f64, 10.0);
        }
        assert_eq!(last, (10.0, 10.0));
    }

    #[test]
    fn rolling_max_forgets_after_the_span() {
        let mut m = RollingMax::new(10.0);
        assert_eq!(m.push(0.0, 5.0), 5.0);
        assert_eq!(m.push(1.0, 3.0), 5.0);
        assert_eq!(m.push(9.5, 1.0), 5.0);
        assert_eq!(m.push(10.0, 2.0), 3.0); // the 5 at t = 0 is exactly 10 s old
        assert_eq!(m.push(11.0, 0.0), 2.0);
    }
}

mod level {
    use tetherplan::numerics::monitor::level::*;

    /// Feeds `(time, value)` and returns the transitions with their times.
    fn run(sense: Sense, thr: f64, s: &[(f64, f64)]) -> Vec<(f64, Transition)> {
        let d = Dwell::default();
        let mut l = LevelTracker::default();
        s.iter()
            .map(|&(t, v)| (t, l.update(&d, sense, t, v, thr)))
            .filter(|(_, tr)| *tr != Transition::None)
            .collect()
    }

    #[test]
    fn a_single_sample_spike_raises_nothing() {
        let mut s: Vec<(f64, f64)> = (0..100).map(|k| (0.1 * k as f64, 1.0)).collect();
        s[50].1 = 100.0;
        assert!(run(Sense::Above, 2.0, &s).is_empty());
    }

    #[test]
    fn raised_after_the_dwell_and_cleared_after_the_longer_one_below_0_9() {
        // 10 Hz: above from t = 1.0 to 3.0, then at 0.95 × threshold (no
        // clearing), then 0.85 × threshold from t = 5.0
        let s: Vec<(f64, f64)> = (0..200)
            .map(|k| {
                let t = 0.1 * k as f64;
                let v = if k < 10 {
                    1.0
                } else if k <= 30 {
                    2.5
                } else if k < 50 {
                    1.9
                } else {
                    1.7
                };
                (t, v)
            })
            .collect();
        let tr = run(Sense::Above, 2.0, &s);
        assert_eq!(tr.len(), 2, "{tr:?}");
        assert_eq!(tr[0].1, Transition::Raised);
        // the run starts at k = 10 (t = 1.0); raised at the first t ≥ 2.0
        assert!((tr[0].0 - 2.0).abs() < 1e-9, "{tr:?}");
        assert_eq!(tr[1].1, Transition::Cleared);
        // back below 1.8 from k = 50 (t = 5.0): cleared at t = 10.0
        assert!((tr[1].0 - 10.0).abs() < 1e-9, "{tr:?}");
    }

    #[test]
    fn a_dip_interrupts_the_raise_and_a_bump_the_clear() {
        let mut s: Vec<(f64, f64)> = (0..30).map(|k| (0.1 * k as f64, 3.0)).collect();
        s[8].1 = 1.0; // the run restarts at k = 9
        let tr = run(Sense::Above, 2.0, &s);
        assert!((tr[0].0 - 1.9).abs() < 1e-9, "{tr:?}");
    }

    #[test]
    fn below_sense_clears_above_threshold_over_0_9() {
        // slack: threshold 50 N; value 10 N for 2 s, then 54 N (not back:
        // 54 × 0.9 = 48.6 < 50), then 60 N (back) for 5 s
        let mut s = Vec::new();
        for k in 0..=20 {
            s.push((0.1 * k as f64, 10.0));
        }
        for k in 21..=40 {
            s.push((0.1 * k as f64, 54.0));
        }
        for k in 41..=100 {
            s.push((0.1 * k as f64, 60.0));
        }
        let tr = run(Sense::Below, 50.0, &s);
        assert_eq!(tr[0], (1.0, Transition::Raised));
        assert_eq!(tr[1].1, Transition::Cleared);
        assert!((tr[1].0 - 9.1).abs() < 1e-9, "{tr:?}");
    }
}

mod ceiling {
    use tetherplan::numerics::monitor::ceiling::*;

    #[test]
    fn bilinear_is_exact_for_a_bilinear_function_and_clamps_outside() {
        let f = |l: f64, w: f64| 40.0 - 0.01 * l - 0.5 * w + 0.0002 * l * w;
        let t = CeilingTable::tabulate(
            vec![0.0, 250.0, 600.0, 1000.0],
            vec![0.0, 4.0, 10.0, 20.0],
            f,
        )
        .unwrap();
        for (l, w) in [(0.0, 0.0), (123.0, 3.3), (777.0, 15.5), (1000.0, 20.0)] {
            assert!((t.ceiling_m_s(l, w) - f(l, w)).abs() < 1e-12, "{l} {w}");
        }
        assert!((t.ceiling_m_s(2000.0, 50.0) - f(1000.0, 20.0)).abs() < 1e-12);
        assert!((t.ceiling_m_s(-5.0, -1.0) - f(0.0, 0.0)).abs() < 1e-12);
    }

    #[test]
    fn a_calm_air_closed_form_is_interpolated_to_its_stated_error() {
        // √((F − ρA g L)/ρA), F = 1000 N, ρA = 0.078 kg/m: the interpolation
        // error of a concave function on 50 m cells below 90 % of the lift
        // limit is below 0.5 % of the value
        let g = 9.81;
        let f = |l: f64, _w: f64| ((1000.0 - 0.078 * g * l) / 0.078).max(0.0).sqrt();
        let lengths: Vec<f64> = (0..=24).map(|k| 50.0 * k as f64).collect();
        let t = CeilingTable::tabulate(lengths, vec![0.0, 10.0], f).unwrap();
        let limit = 1000.0 / (0.078 * g);
        let mut l = 0.0;
        while l < 0.9 * limit {
            let (exact, interp) = (f(l, 0.0), t.ceiling_m_s(l, 3.0));
            assert!(
                interp <= exact * (1.0 + 1e-12),
                "chord below a concave curve"
            );
            assert!((exact - interp) / exact < 5e-3, "{l}: {interp} vs {exact}");
            l += 7.3;
        }
    }

    #[test]
    fn bad_tables_are_refused() {
        assert!(CeilingTable::new(vec![1.0, 1.0], vec![0.0], vec![1.0, 1.0]).is_err());
        assert!(CeilingTable::new(vec![1.0], vec![0.0], vec![f64::NAN]).is_err());
        assert!(CeilingTable::new(vec![1.0, 2.0], vec![0.0], vec![1.0]).is_err());
    }
}

mod engine {
    use std::sync::Arc;

    use tetherplan::numerics::monitor::*;

    const A: f64 = 10_000.0; // allowed tension (N)
    const F: f64 = 2_000.0; // net buoyancy (N)

    /// Tension and slack only.
    fn model() -> FlightModel {
        let mut limits = Limits::new(F);
        limits.allowable_tension_n = Some(A);
        FlightModel {
            limits,
            plan: None,
            ceiling: None,
        }
    }

    /// With the wind limits: 10 m/s mean, 15 m/s gust.
    fn model_wind() -> FlightModel {
        let mut m = model();
        m.limits.max_operating_wind_m_s = Some(10.0);
        m.limits.max_gust_m_s = Some(15.0);
        m
    }

    fn tension(t: f64, n: f64) -> Sample {
        Sample {
            winch_tension_n: Some(n),
            ..Sample::at(t)
        }
    }

    fn state_of(m: &Monitor, name: CheckName) -> Level {
        m.status(Some(0.0))
            .checks
            .iter()
            .find(|c| c.name == name)
            .unwrap()
            .state
    }

    /// 10 Hz samples of the tension `f(t)` from `t0` to `t1` (inclusive).
    fn feed(m: &mut Monitor, t0: f64, t1: f64, f: impl Fn(f64) -> f64) {
        let (k0, k1) = ((t0 * 10.0).round() as i64, (t1 * 10.0).round() as i64);
        for k in k0..=k1 {
            let t = k as f64 / 10.0;
            m.push(&tension(t, f(t)));
        }
    }

    #[test]
    fn a_single_sample_spike_raises_nothing() {
        let mut m = Monitor::new(model());
        // 1.5 × A (past stop) for one sample, 0 N (slack) for another
        feed(&mut m, 0.0, 20.0, |t| {
            if (t - 7.0).abs() < 1e-9 {
                1.5 * A
            } else if (t - 12.0).abs() < 1e-9 {
                0.0
            } else {
                0.5 * A
            }
        });
        assert!(m.alarms().is_empty(), "{:?}", m.alarms());
        assert_eq!(m.status(Some(0.0)).state, Level::Normal);
    }

    #[test]
    fn caution_raised_after_1_s_and_cleared_after_5_s_below_0_9_of_it() {
        let mut m = Monitor::new(model());
        // 0.85 A from t = 10 to 20, 0.75 A (between 0.72 A and 0.8 A: neither
        // raises nor clears) to 30, 0.7 A after
        let f = |t: f64| {
            if t < 10.0 {
                0.5 * A
            } else if t < 20.0 {
                0.85 * A
            } else if t < 30.0 {
                0.75 * A
            } else {
                0.7 * A
            }
        };
        feed(&mut m, 0.0, 10.9, f);
        assert!(m.alarms().is_empty());
        feed(&mut m, 11.0, 11.0, f);
        assert_eq!(m.alarms().len(), 1);
        let a = m.alarms()[0];
        assert_eq!(
            (a.check, a.level, a.raised_at_s),
            (CheckName::Tension, Level::Caution, 11.0)
        );
        feed(&mut m, 11.1, 34.9, f);
        assert_eq!(state_of(&m, CheckName::Tension), Level::Caution);
        assert_eq!(m.alarms()[0].cleared_at_s, None);
        feed(&mut m, 35.0, 40.0, f);
        assert_eq!(m.alarms()[0].cleared_at_s, Some(35.0));
        assert_eq!(m.status(Some(0.0)).state, Level::Normal);
        // a caution needs no acknowledgement
        assert_eq!(m.alarms()[0].acknowledged_at_s, None);
    }

    #[test]
    fn a_stop_stays_latched_until_acknowledged() {
        let mut m = Monitor::new(model());
        feed(
            &mut m,
            0.0,
            5.0,
            |t| if t >= 2.0 { 1.2 * A } else { 0.5 * A },
        );
        let status = m.status(Some(0.0));
        assert_eq!(status.state, Level::Stop);
        // acknowledged while still past the stop: stays stop
        assert_eq!(m.acknowledge(), 2); // the caution and the stop
        assert_eq!(m.status(Some(0.0)).state, Level::Stop);
        // back to 0.5 A: the stop clears after 5 s and, acknowledged, goes
        feed(&mut m, 5.1, 10.0, |_| 0.5 * A);
        assert_eq!(m.status(Some(0.0)).state, Level::Stop);
        feed(&mut m, 10.1, 10.1, |_| 0.5 * A);
        assert_eq!(m.status(Some(0.0)).state, Level::Normal);

        // raised again and cleared without an acknowledgement: latched
        feed(&mut m, 20.0, 22.0, |_| 1.2 * A);
        feed(&mut m, 22.1, 60.0, |_| 0.5 * A);
        let stop = *m
            .alarms()
            .iter()
            .rev()
            .find(|a| a.level == Level::Stop)
            .unwrap();
        assert_eq!((stop.raised_at_s, stop.cleared_at_s), (21.0, Some(27.1)));
        assert_eq!(m.status(Some(0.0)).state, Level::Stop, "latched");
        assert_eq!(state_of(&m, CheckName::Tension), Level::Stop);
        m.acknowledge();
        let stop = *m
            .alarms()
            .iter()
            .rev()
            .find(|a| a.level == Level::Stop)
            .unwrap();
        assert_eq!(stop.acknowledged_at_s, Some(60.0));
        assert_eq!(m.status(Some(0.0)).state, Level::Normal);
    }

    #[test]
    fn slack_stops_below_5_percent_of_the_buoyancy_and_clears_above_it_over_0_9() {
        let mut m = Monitor::new(model());
        let th = 0.05 * F; // 100 N
        feed(
            &mut m,
            0.0,
            3.0,
            |t| if t >= 1.0 { 0.8 * th } else { 5.0 * th },
        );
        let a = m.alarms()[0];
        assert_eq!(
            (a.check, a.level, a.raised_at_s),
            (CheckName::Slack, Level::Stop, 2.0)
        );
        // 105 N is above the threshold but not above 100/0.9 = 111 N
        feed(&mut m, 3.1, 20.0, |_| 1.05 * th);
        assert_eq!(m.alarms()[0].cleared_at_s, None);
        feed(&mut m, 20.1, 30.0, |_| 1.2 * th);
        assert_eq!(m.alarms()[0].cleared_at_s, Some(25.1));
    }

    #[test]
    fn silence_makes_the_flight_unavailable_and_samples_bring_it_back() {
        let mut m = Monitor::new(model());
        assert_eq!(
            m.status(None).state,
            Level::Unavailable,
            "before any sample"
        );
        feed(&mut m, 0.0, 3.0, |_| 0.5 * A);
        assert_eq!(m.status(Some(4.9)).state, Level::Normal);
        let st = m.status(Some(5.1));
        assert_eq!(st.state, Level::Unavailable);
        let data = st
            .checks
            .iter()
            .find(|c| c.name == CheckName::Data)
            .unwrap();
        assert_eq!((data.state, data.value), (Level::Unavailable, Some(5.1)));
        feed(&mut m, 3.1, 3.1, |_| 0.5 * A);
        assert_eq!(m.status(Some(0.0)).state, Level::Normal);
        // a latched stop is not hidden by the silence
        feed(&mut m, 4.0, 6.0, |_| 1.5 * A);
        assert_eq!(m.status(Some(60.0)).state, Level::Stop);
    }

    #[test]
    fn a_check_without_fresh_values_is_unavailable() {
        let mut m = Monitor::new(model_wind());
        // the wind arrives, then only the tension for 6 s of sample time
        m.push(&Sample {
            wind_speed_m_s: Some(3.0),
            ..Sample::at(0.0)
        });
        feed(&mut m, 0.1, 5.0, |_| 0.5 * A);
        assert_eq!(state_of(&m, CheckName::Wind), Level::Normal);
        feed(&mut m, 5.1, 6.0, |_| 0.5 * A);
        assert_eq!(state_of(&m, CheckName::Wind), Level::Unavailable);
        assert_eq!(m.status(Some(0.0)).state, Level::Unavailable);
    }

    #[test]
    fn wind_mean_and_gust_against_their_limits() {
        let mut m = Monitor::new(model_wind());
        // 1 Hz: 7 m/s steady (0.7 of 10 m/s) with a 20 s gust of 13 m/s at
        // t = 300 (0.87 of the 15 m/s gust limit: caution)
        let mut gust_raise = None;
        for k in 0..=400 {
            let t = k as f64;
            let v = if (300..320).contains(&k) { 13.0 } else { 7.0 };
            m.push(&Sample {
                wind_speed_m_s: Some(v),
                ..Sample::at(t)
            });
            if gust_raise.is_none() && state_of(&m, CheckName::Gust) == Level::Caution {
                gust_raise = Some(t);
            }
        }
        // the 3 s mean passes 12 m/s at t = 302 (the window (299, 302] holds
        // three 13s); raised 1 s later
        assert_eq!(gust_raise, Some(303.0));
        // the gust stays the largest 3 s mean of the last 10 minutes: 13 m/s
        let st = m.status(Some(0.0));
        let g = st
            .checks
            .iter()
            .find(|c| c.name == CheckName::Gust)
            .unwrap();
        assert_eq!(
            (g.value, g.caution_at, g.stop_at),
            (Some(13.0), Some(12.0), Some(15.0))
        );
        let w = st
            .checks
            .iter()
            .find(|c| c.name == CheckName::Wind)
            .unwrap();
        // mean of (−200, 400] = 401 samples, 20 of them 13 m/s
        let mean = (381.0 * 7.0 + 20.0 * 13.0) / 401.0;
        assert!((w.value.unwrap() - mean).abs() < 1e-12);
        assert_eq!(w.state, Level::Normal);
    }

    /// The calm-air stability ceiling of SPEC §7 without the margin, `√((1−r)F
    /// − ρA g L)/ρA)`, here wind-independent.
    fn calm_ceiling(l: f64) -> f64 {
        ((0.9 * F - 0.05 * 9.81 * l) / 0.05).max(0.0).sqrt()
    }

    #[test]
    fn payout_rate_against_the_tabulated_ceiling() {
        let lengths: Vec<f64> = (0..=40).map(|k| 100.0 * k as f64).collect();
        let table =
            CeilingTable::tabulate(lengths, vec![0.0, 30.0], |l, _| calm_ceiling(l)).unwrap();
        let mut md = model();
        md.ceiling = Some(Arc::new(table));
        let mut m = Monitor::new(md);
        // paying out at 0.95 of the ceiling at 1000 m (caution: 0.9–1.0)
        let v = 0.95 * calm_ceiling(1000.0);
        for k in 0..=20 {
            m.push(&Sample {
                time_s: 0.1 * k as f64,
                tether_length_m: Some(1000.0),
                winch_rate_m_s: Some(v),
                wind_speed_m_s: Some(2.0),
                ..Sample::default()
            });
        }
        let st = m.status(Some(0.0));
        let p = st
            .checks
            .iter()
            .find(|c| c.name == CheckName::PayoutRate)
            .unwrap();
        assert_eq!(p.state, Level::Caution);
        assert!((p.stop_at.unwrap() - calm_ceiling(1000.0)).abs() < 1e-12);
        assert!((p.caution_at.unwrap() - 0.9 * calm_ceiling(1000.0)).abs() < 1e-12);
    }

    #[test]
    fn plan_ahead_by_more_than_5_percent_is_a_caution_only() {
        let mut md = model();
        // the plan: 0 → 1000 m at 10 m/s
        md.plan = PlanTrace::new(vec![0.0, 100.0], vec![0.0, 1000.0]);
        let mut m = Monitor::new(md);
        let mut raised = None;
        for k in 0..=600 {
            let t = 0.1 * k as f64;
            // from t = 20 s the winch runs 10 % fast
            let len = if t < 20.0 {
                10.0 * t
            } else {
                200.0 + 11.0 * (t - 20.0)
            };
            m.push(&Sample {
                tether_length_m: Some(len),
                ..Sample::at(t)
            });
            if raised.is_none() && state_of(&m, CheckName::Plan) == Level::Caution {
                raised = Some(t);
            }
        }
        // ahead fraction (11(t−20) + 200 − 10t)/(10t) = (t − 20)/(10t) > 0.05
        // from t = 40 s; raised 1 s later
        let r = raised.unwrap();
        assert!((r - 41.0).abs() < 0.1 + 1e-9, "{r}");
        assert!(m.alarms().iter().all(|a| a.level == Level::Caution));
    }

    #[test]
    fn duplicates_are_ignored_and_late_samples_are_refused_for_a_replay() {
        let mut m = Monitor::new(model());
        assert!(matches!(
            m.push(&tension(1.0, 0.5 * A)),
            Pushed::Evaluated { .. }
        ));
        assert_eq!(m.push(&tension(1.0, 2.0 * A)), Pushed::Duplicate);
        assert_eq!(m.push(&tension(0.5, 2.0 * A)), Pushed::OutOfOrder);
        assert_eq!(m.push(&tension(f64::NAN, 2.0 * A)), Pushed::Invalid);
        assert_eq!(m.samples(), 1);
    }

    /// A flight of 60 s at 10 Hz with a caution, a stop, an acknowledgement
    /// and a gust.
    fn flight() -> Vec<Event> {
        let mut ev = Vec::new();
        for k in 0..=600 {
            let t = 0.1 * k as f64;
            let n = if (10.0..14.0).contains(&t) {
                0.9 * A
            } else if (20.0..23.0).contains(&t) {
                1.1 * A
            } else {
                0.5 * A
            };
            ev.push(Event::Sample(Sample {
                winch_tension_n: Some(n),
                wind_speed_m_s: Some(if (40.0..45.0).contains(&t) { 14.0 } else { 6.0 }),
                ..Sample::at(t)
            }));
            if k == 350 {
                ev.push(Event::Acknowledge { time_s: t });
            }
        }
        ev
    }

    #[test]
    fn late_samples_replayed_give_the_state_of_the_ordered_flight() {
        let ordered = Monitor::replay(model_wind(), &flight());
        assert!(ordered.alarms().len() >= 4, "{:?}", ordered.alarms());
        // the same events in batches of 7 delivered in a scrambled order: the
        // monitor takes what comes in order and replays on a late sample
        let events = flight();
        let batches: Vec<&[Event]> = events.chunks(7).collect();
        let mut order: Vec<usize> = (0..batches.len()).collect();
        let n = order.len();
        for i in 0..n {
            order.swap(i, (i * 7919 + 13) % n);
        }
        let mut seen: Vec<Event> = Vec::new();
        let mut m = Monitor::new(model_wind());
        let mut replays = 0;
        for &b in &order {
            seen.extend_from_slice(batches[b]);
            let mut late = false;
            for e in batches[b] {
                match e {
                    Event::Sample(s) => late |= m.push(s) == Pushed::OutOfOrder,
                    Event::Acknowledge { time_s } => {
                        // made at the last sample's time; otherwise replay
                        late |= m.last_sample_time_s() != Some(*time_s);
                        if !late {
                            m.acknowledge_at(*time_s);
                        }
                    }
                }
            }
            if late {
                m = Monitor::replay(model_wind(), &seen);
                replays += 1;
            }
        }
        assert!(replays > 0);
        assert_eq!(m.alarms(), ordered.alarms());
        assert_eq!(m.status(Some(1.0)), ordered.status(Some(1.0)));
        assert_eq!(m.samples(), ordered.samples());
    }
}
