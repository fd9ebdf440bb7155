//! The live flight's contract and store (issue 33): telemetry parsing
//! (JSON, CSV, NMEA with exact unit conversion), the measured wind carried
//! into the plan's flow, the plan's stability ceiling against the calm-air
//! closed form, and the SQLite flight store (dedup by time, owners,
//! reopening).

mod telemetry {
    use tetherplan::contract::RequestError;
    use tetherplan::contract::flight::telemetry::*;

    /// `$` + body + `*` + the XOR checksum, computed here.
    fn nmea(body: &str) -> String {
        let c = body.bytes().fold(0u8, |a, b| a ^ b);
        format!("${body}*{c:02X}")
    }

    #[test]
    fn json_keeps_the_good_samples_and_names_the_bad_ones() {
        let body = br#"[
        {"time_s": 0.0, "tether_length_m": 10, "winch_tension_n": 900},
        {"time_s": 0.1, "wind_speed_m_s": -3},
        {"tether_length_m": 11},
        {"time_s": 0.3, "tension": 5},
        {"time_s": "x"},
        {"time_s": 0.5, "winch_rate_m_s": 1.5, "aerostat_altitude_m": 9.0}
    ]"#;
        let p = parse_batch(Format::Json, body, 0.0).unwrap();
        assert_eq!(p.samples.len(), 2);
        assert_eq!(p.samples[1].winch_rate_m_s, Some(1.5));
        let named: Vec<(usize, &str)> = p
            .rejected
            .iter()
            .map(|r| (r.line, r.field.as_str()))
            .collect();
        assert_eq!(
            named,
            vec![
                (2, "wind_speed_m_s"),
                (3, "time_s"),
                (4, "tension"),
                (5, "time_s")
            ]
        );
        assert!(
            p.rejected[2].reason.contains("unknown"),
            "{:?}",
            p.rejected[2]
        );
        assert!(matches!(
            parse_batch(Format::Json, b"{}", 0.0),
            Err(RequestError::Invalid(_))
        ));
        assert!(matches!(
            parse_batch(Format::Json, b"[", 0.0),
            Err(RequestError::Malformed(_))
        ));
    }

    #[test]
    fn csv_by_header_with_empty_cells_missing() {
        let body = "time_s,winch_tension_n,wind_speed_m_s\n0,1000,5\n0.1,,5.5\n0.2,abc,5\n0.3,1000\n\n0.4,1001,6\n";
        let p = parse_batch(Format::Csv, body.as_bytes(), 0.0).unwrap();
        assert_eq!(p.samples.len(), 3);
        assert_eq!(p.samples[1].winch_tension_n, None);
        assert_eq!(p.samples[1].wind_speed_m_s, Some(5.5));
        let named: Vec<(usize, &str)> = p
            .rejected
            .iter()
            .map(|r| (r.line, r.field.as_str()))
            .collect();
        assert_eq!(named, vec![(4, "winch_tension_n"), (5, "line")]);
        let Err(RequestError::Invalid(e)) = parse_batch(Format::Csv, b"time_s,tension\n0,1\n", 0.0)
        else {
            panic!("an unknown column refuses the batch")
        };
        assert_eq!(e.field, "tension");
        assert!(parse_batch(Format::Csv, b"winch_tension_n\n1\n", 0.0).is_err());
    }

    #[test]
    fn nmea_knots_are_converted_exactly_and_the_v_flag_is_not_used() {
        let lines = [
            format!("12.5,{}", nmea("WIMWV,270.0,R,10.0,N,A")),
            format!("12.6,{}", nmea("WIMWV,270.0,R,10.0,N,V")),
            format!("12.7,{}", nmea("WIMWV,270.0,T,36.0,K,A")),
            format!("12.8,{}", nmea("WIMWV,270.0,T,7.3,M,A")),
            nmea("WIMWV,270.0,T,12.345678,N,A"),
            "12.9,$WIMWV,270.0,R,10.0,N,A*00".to_string(),
            format!("13.0,{}", nmea("GPGLL,4916.45,N,12311.12,W,225444,A")),
        ];
        let p = parse_batch(Format::Nmea, lines.join("\r\n").as_bytes(), 99.0).unwrap();
        let got: Vec<(f64, f64)> = p
            .samples
            .iter()
            .map(|s| (s.time_s, s.wind_speed_m_s.unwrap()))
            .collect();
        // 1 kn = 1852/3600 m/s exactly; f64 of the text, not the crate's f32
        assert_eq!(
            got,
            vec![
                (12.5, 10.0 * 1852.0 / 3600.0),
                (12.7, 36.0 * 1000.0 / 3600.0),
                (12.8, 7.3),
                (99.0, 12.345678 * 1852.0 / 3600.0),
            ]
        );
        assert_ne!(12.345678_f32 as f64 * 1852.0 / 3600.0, got[3].1);
        let named: Vec<(usize, &str)> = p
            .rejected
            .iter()
            .map(|r| (r.line, r.field.as_str()))
            .collect();
        assert_eq!(
            named,
            vec![(2, "data_valid"), (6, "sentence"), (7, "sentence")]
        );
        assert!(
            p.rejected[1].reason.contains("hecksum"),
            "{:?}",
            p.rejected[1]
        );
    }

    #[test]
    fn content_types() {
        assert_eq!(
            Format::from_content_type("application/json; charset=utf-8"),
            Some(Format::Json)
        );
        assert_eq!(Format::from_content_type("Text/CSV"), Some(Format::Csv));
        assert_eq!(Format::from_content_type("text/plain"), Some(Format::Nmea));
        assert_eq!(Format::from_content_type("application/xml"), None);
    }
}

mod wind {
    use tetherplan::contract::flight::wind::*;
    use tetherplan::contract::system::{WindFlowInput, WindInput};

    #[test]
    fn each_shape_scales_to_the_measured_speed_at_the_anemometer() {
        let flows = [
            WindFlowInput::PowerLaw {
                coefficient_m_s: 5.0,
                exponent_nondim: 0.14,
                reference_height_m: 10.0,
            },
            WindFlowInput::LogLaw {
                speed_m_s: 6.0,
                reference_height_m: 10.0,
                roughness_length_m: 0.03,
            },
        ];
        for f in &flows {
            let (s, k) = scaled_flow(Some(f), 4.0, 3.3);
            assert!((speed_at_m_s(&s, 4.0) - 3.3).abs() < 1e-12);
            // the shape kept: the ratio between two heights is the plan's
            let ratio = |g: &WindFlowInput| speed_at_m_s(g, 300.0) / speed_at_m_s(g, 50.0);
            assert!((ratio(&s) - ratio(f)).abs() < 1e-12);
            assert!(k.is_some());
        }
        // the power law by hand: 5 (4/10)^0.14 at 4 m
        let here = 5.0 * (0.4f64).powf(0.14);
        assert!((speed_at_m_s(&flows[0], 4.0) - here).abs() < 1e-12);
        let (u, k) = scaled_flow(None, 10.0, 7.0);
        assert!(matches!(u, WindFlowInput::Uniform { speed_m_s } if speed_m_s == 7.0));
        assert!(k.is_none());
    }

    #[test]
    fn the_gust_keeps_its_factor_at_the_reference_height() {
        let w = WindInput {
            flow: WindFlowInput::LogLaw {
                speed_m_s: 6.0,
                reference_height_m: 10.0,
                roughness_length_m: 0.03,
            },
            air_density_kg_m3: 1.2,
            gust: None,
        };
        let m = measured_wind(Some(&w), 2.0, 4.0, Some(6.0));
        let at10 = speed_at_m_s(&m.flow, 10.0);
        assert!((m.gust.unwrap().gust_m_s.unwrap() - 1.5 * at10).abs() < 1e-12);
        assert_eq!(m.air_density_kg_m3, 1.2);
        assert!(measured_wind(Some(&w), 2.0, 4.0, Some(3.0)).gust.is_none());
    }
}

mod plan_ceiling {
    use tetherplan::contract::plan::PlanRequest;
    use tetherplan::contract::plan::ceiling::*;
    use tetherplan::numerics::plan::STABILITY_MARGIN;

    #[test]
    fn calm_air_is_the_closed_form() {
        // √(((1 − r)(1 − ε)F − ρA g L)/ρA), no drag data: no ascent term
        let req: PlanRequest = serde_json::from_value(serde_json::json!({
            "cable": {"mass_per_length_kg_m": 0.078},
            "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0},
            "initial_length_m": 1.0,
            "target_elevation_m": 1000.0,
            "winch": {"max_rate_m_s": 5.0, "max_acceleration_m_s2": 1.0},
            "lift_reserve_nondim": 0.05
        }))
        .unwrap();
        let lengths = [0.0, 100.0, 600.0, 1200.0, 2000.0];
        let c = rate_ceilings_m_s(&req, &lengths).unwrap();
        for (l, c) in lengths.iter().zip(c) {
            let budget = 0.95 * (1.0 - STABILITY_MARGIN) * 1000.0 - 0.078 * 9.81 * l;
            let exact = (budget / 0.078).max(0.0).sqrt();
            assert!(
                (c - exact).abs() <= 1e-9 * exact.max(1.0),
                "{l}: {c} vs {exact}"
            );
        }
    }
}

mod store {
    use tetherplan::jobs::flights::*;
    use tetherplan::jobs::flights_sqlite::*;
    use tetherplan::numerics::monitor::Sample;

    fn flight() -> NewFlight<'static> {
        NewFlight {
            name: "f",
            request: "{}",
            plan: "{}",
            limits: "{}",
            ceiling: "{}",
        }
    }

    #[test]
    fn samples_are_stored_once_by_time_and_numbered_in_arrival_order() {
        let s = SqliteFlights::open_in_memory().unwrap();
        let id = s.create_flight("a", &flight()).unwrap().unwrap();
        let batch: Vec<Sample> = [0.0, 0.2, 0.1].iter().map(|&t| Sample::at(t)).collect();
        let b = s.insert_samples(id, &batch, 1000).unwrap();
        assert_eq!((b.accepted, b.duplicates, b.last_seq), (3, 0, 3));
        let b = s.insert_samples(id, &batch, 2000).unwrap();
        assert_eq!((b.accepted, b.duplicates, b.last_seq), (0, 3, 3));
        let b = s
            .insert_samples(id, &[Sample::at(0.15), Sample::at(0.2)], 3000)
            .unwrap();
        assert_eq!((b.accepted, b.duplicates, b.last_seq), (1, 1, 4));
        let times: Vec<f64> = s
            .samples_by_time(id)
            .unwrap()
            .iter()
            .map(|s| s.time_s)
            .collect();
        assert_eq!(times, vec![0.0, 0.1, 0.15, 0.2]);
        let after: Vec<(i64, f64)> = s
            .samples_after(id, 2, 10)
            .unwrap()
            .iter()
            .map(|(q, s)| (*q, s.time_s))
            .collect();
        assert_eq!(after, vec![(3, 0.1), (4, 0.15)]);
        let row = s.get_flight(id, "a").unwrap().unwrap();
        assert_eq!((row.samples, row.last_arrival_ms), (4, Some(3000)));
    }

    #[test]
    fn another_owner_sees_nothing() {
        let s = SqliteFlights::open_in_memory().unwrap();
        let id = s.create_flight("a", &flight()).unwrap().unwrap();
        assert!(s.get_flight(id, "b").unwrap().is_none());
        assert!(s.list_flights("b").unwrap().is_empty());
        assert!(!s.end_flight(id, "b").unwrap());
        assert_eq!(s.list_flights("a").unwrap().len(), 1);
        assert!(s.end_flight(id, "a").unwrap());
        assert!(s.get_flight(id, "a").unwrap().unwrap().ended_at.is_some());
    }

    #[test]
    fn the_schema_survives_a_reopen() {
        let dir = std::env::temp_dir().join(format!("tp-flights-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.db");
        let _ = std::fs::remove_file(&path);
        let id = {
            let s = SqliteFlights::open(&path).unwrap();
            let id = s.create_flight("a", &flight()).unwrap().unwrap();
            s.insert_samples(id, &[Sample::at(1.0)], 5).unwrap();
            s.add_acknowledgement(id, 1.0).unwrap();
            id
        };
        let s = SqliteFlights::open(&path).unwrap();
        assert_eq!(s.samples_by_time(id).unwrap().len(), 1);
        assert_eq!(s.acknowledgements(id).unwrap(), vec![1.0]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

mod clock {
    use tetherplan::api::flights::hub::parse_ms;

    #[test]
    fn sqlite_timestamps_to_epoch_ms() {
        assert_eq!(parse_ms("1970-01-01T00:00:00.000Z"), 0);
        assert_eq!(parse_ms("2000-03-01T00:00:01.500Z"), 951_868_801_500);
    }
}
