//! What the flight tests against real servers share: a 10 Hz batch of
//! samples and a flight's answer without what depends on the server's clock.

use serde_json::{Value, json};

/// `n` samples at 10 Hz from `t0`, tension `f(t)`, the length at 1 m
/// (the plan's first seconds), 5 m/s of wind.
pub fn batch(t0: f64, n: usize, f: impl Fn(f64) -> f64) -> Value {
    Value::Array(
        (0..n)
            .map(|k| {
                let t = ((t0 * 10.0).round() as i64 + k as i64) as f64 / 10.0;
                json!({"time_s": t, "tether_length_m": 1.0, "winch_rate_m_s": 0.0,
                       "winch_tension_n": f(t), "wind_speed_m_s": 5.0})
            })
            .collect(),
    )
}

/// The flight without what depends on the server's clock.
pub fn comparable(mut f: Value) -> Value {
    f.as_object_mut()
        .unwrap()
        .remove("seconds_since_last_sample_s");
    f["checks"]
        .as_array_mut()
        .unwrap()
        .retain(|c| c["name"] != "data");
    f
}
