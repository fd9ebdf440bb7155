//! The one grid type of every request (rates, tether lengths, wind
//! speeds, frequencies): a list of values, or `{min, max, count}` evenly
//! spaced (ends included). Both forms give the same values, so the same
//! answer.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::params::{InvalidInput, compact};

/// Values: a list `[..]`, or `{min, max, count}` evenly spaced, ends included.
///
/// Deserialised by hand (not `untagged`), so that an error names the part
/// at fault (`in \`count\`: …`, lifted into the field path by
/// [`crate::contract::parse_value`]) instead of "matches no variant".
#[derive(Clone, Debug, Serialize, ToSchema, PartialEq)]
#[serde(untagged)]
pub enum GridInput {
    /// The values, in the order given.
    List(Vec<f64>),
    /// `count` values from `min` to `max`, evenly spaced (one value: `min`).
    Range(GridRangeInput),
}

/// An evenly spaced grid.
#[derive(Clone, Debug, Serialize, ToSchema, PartialEq)]
pub struct GridRangeInput {
    #[schema(example = 1.0)]
    pub min: f64,
    #[schema(example = 10.0)]
    pub max: f64,
    #[schema(example = 10, minimum = 1)]
    pub count: usize,
}

impl<'de> Deserialize<'de> for GridInput {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        use serde_json::Value;
        let describe = crate::contract::describe_json;
        let number = |key: &str, v: &Value| -> Result<f64, D::Error> {
            v.as_f64().ok_or_else(|| {
                D::Error::custom(format!("in `{key}`: must be a number, got {}", describe(v)))
            })
        };
        match Value::deserialize(d)? {
            Value::Array(items) => items
                .iter()
                .enumerate()
                .map(|(i, x)| number(&format!("[{i}]"), x))
                .collect::<Result<_, _>>()
                .map(Self::List),
            Value::Object(m) => {
                for k in m.keys() {
                    if !matches!(k.as_str(), "min" | "max" | "count") {
                        return Err(D::Error::custom(format!(
                            "unknown field `{k}`, expected one of `min`, `max`, `count`"
                        )));
                    }
                }
                let get = |k: &str| {
                    m.get(k)
                        .ok_or_else(|| D::Error::custom(format!("missing field `{k}`")))
                };
                let count = get("count")?;
                // A whole number, also when written as 1e9.
                let n = match count.as_f64() {
                    Some(c) if c >= 0.0 && c.fract() == 0.0 => c.min(usize::MAX as f64) as usize,
                    _ => {
                        return Err(D::Error::custom(format!(
                            "in `count`: must be a whole number (1 or more), got {}",
                            describe(count)
                        )));
                    }
                };
                Ok(Self::Range(GridRangeInput {
                    min: number("min", get("min")?)?,
                    max: number("max", get("max")?)?,
                    count: n,
                }))
            }
            other => Err(D::Error::custom(format!(
                "give a list of numbers, like [1, 2, 5], or an even grid {{\"min\", \"max\", \"count\"}}, got {}",
                describe(&other)
            ))),
        }
    }
}

/// The bounds a grid's values and count must respect.
#[derive(Clone, Copy, Debug)]
pub struct GridBounds {
    pub min: f64,
    /// Whether `min` itself is excluded.
    pub exclusive_min: bool,
    pub max: f64,
    pub max_count: usize,
    pub unit: &'static str,
}

impl GridInput {
    /// How many values (without building them).
    pub fn count(&self) -> usize {
        match self {
            Self::List(v) => v.len(),
            Self::Range(r) => r.count,
        }
    }

    /// The field of the count in errors: `at.count` for a range, `at` for a list.
    pub fn count_field(&self, at: &str) -> String {
        match self {
            Self::List(_) => at.to_string(),
            Self::Range(_) => format!("{at}.count"),
        }
    }

    /// The smallest and largest value (for limits and estimates).
    pub fn span(&self) -> (f64, f64) {
        match self {
            Self::List(v) => v
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(*x), b.max(*x))
                }),
            Self::Range(r) => (r.min.min(r.max), r.min.max(r.max)),
        }
    }

    /// The values, checked against `b`; errors name `at` (`at[i]`, `at.min`, `at.count`).
    pub fn values(&self, at: &str, b: GridBounds) -> Result<Vec<f64>, InvalidInput> {
        let check = |field: String, v: f64| -> Result<f64, InvalidInput> {
            let low = if b.exclusive_min {
                v > b.min
            } else {
                v >= b.min
            };
            if v.is_finite() && low && v <= b.max {
                return Ok(v);
            }
            let unit = if b.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", b.unit)
            };
            let from = if b.exclusive_min { "above" } else { "at least" };
            Err(InvalidInput::new(
                field,
                format!(
                    "must be {from} {} and at most {}{unit}, got {}",
                    compact(b.min),
                    compact(b.max),
                    compact(v)
                ),
            ))
        };
        let count = self.count();
        if count == 0 || count > b.max_count {
            return Err(InvalidInput::new(
                self.count_field(at),
                match self {
                    Self::List(_) => format!("give 1 to {} values, got {count}", b.max_count),
                    Self::Range(_) => format!("must be between 1 and {}, got {count}", b.max_count),
                },
            ));
        }
        match self {
            Self::List(v) => v
                .iter()
                .enumerate()
                .map(|(i, x)| check(format!("{at}[{i}]"), *x))
                .collect(),
            Self::Range(r) => {
                let lo = check(format!("{at}.min"), r.min)?;
                let hi = check(format!("{at}.max"), r.max)?;
                if hi < lo {
                    return Err(InvalidInput::new(
                        format!("{at}.max"),
                        format!(
                            "must be at least min ({}), got {}",
                            compact(lo),
                            compact(hi)
                        ),
                    ));
                }
                Ok(evenly_spaced(lo, hi, r.count))
            }
        }
    }
}

impl GridInput {
    /// Rates (m/s): a range through [`crate::numerics::string::chart::rate_grid`]
    /// (its checks and values), a list checked value by value (each above
    /// 0 and at most 1000, at most `MAX_CHART_POINTS`); `at` names the grid.
    pub fn rates(&self, at: &str) -> Result<Vec<f64>, InvalidInput> {
        match self {
            Self::Range(r) => crate::numerics::string::chart::rate_grid(r.min, r.max, r.count)
                .map_err(|e| InvalidInput::new(e.field.replacen("rates_m_s", at, 1), e.reason)),
            Self::List(_) => self.values(at, RateGridInput::BOUNDS),
        }
    }
}

/// `count` values from `lo` to `hi`: `lo + (hi − lo) i/(count − 1)` (the
/// formula every grid of the service has used).
pub fn evenly_spaced(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    if count == 1 {
        return vec![lo];
    }
    (0..count)
        .map(|i| lo + (hi - lo) * i as f64 / (count - 1) as f64)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const B: GridBounds = GridBounds {
        min: 0.0,
        exclusive_min: false,
        max: 100.0,
        max_count: 5,
        unit: "m/s",
    };

    #[test]
    fn a_list_and_a_range_give_the_same_values() {
        let r: GridInput = serde_json::from_str(r#"{"min": 0, "max": 10, "count": 3}"#).unwrap();
        let l: GridInput = serde_json::from_str("[0, 5, 10]").unwrap();
        assert_eq!(r.values("g", B).unwrap(), l.values("g", B).unwrap());
        let e = GridInput::List(vec![1.0; 6]).values("g", B).unwrap_err();
        assert_eq!(e.field, "g");
        let e = serde_json::from_str::<GridInput>(r#"{"min": 0, "max": 10, "count": 1000000000}"#)
            .unwrap()
            .values("lengths", B)
            .unwrap_err();
        assert_eq!(e.field, "lengths.count");
        let e = GridInput::List(vec![1.0, 200.0])
            .values("g", B)
            .unwrap_err();
        assert_eq!(e.field, "g[1]");
    }
}

/// The schema of a grid with its bounds (a list, or `{min, max, count}`).
fn bounded_schema(b: GridBounds, description: &str) -> serde_json::Value {
    let mut value = serde_json::json!({"type": "number", "format": "double", "maximum": b.max});
    value[if b.exclusive_min {
        "exclusiveMinimum"
    } else {
        "minimum"
    }] = serde_json::json!(b.min);
    serde_json::json!({
        "description": description,
        "oneOf": [
            {"title": "list", "type": "array", "items": value, "minItems": 1, "maxItems": b.max_count},
            {"title": "even grid", "type": "object", "required": ["min", "max", "count"],
             "additionalProperties": false,
             "properties": {
                 "min": value, "max": value,
                 "count": {"type": "integer", "minimum": 1, "maximum": b.max_count}
             }}
        ]
    })
}

/// A [`GridInput`] of one quantity, with the bounds its schema states and
/// its validation applies (the same numbers).
macro_rules! bounded_grid {
    ($(#[$doc:meta])* $name:ident, $desc:literal, $bounds:expr) => {
        $(#[$doc])*
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(transparent)]
        pub struct $name(pub GridInput);

        impl $name {
            pub const BOUNDS: GridBounds = $bounds;
        }

        impl std::ops::Deref for $name {
            type Target = GridInput;
            fn deref(&self) -> &GridInput {
                &self.0
            }
        }

        impl utoipa::PartialSchema for $name {
            fn schema() -> utoipa::openapi::RefOr<utoipa::openapi::schema::Schema> {
                serde_json::from_value(bounded_schema(Self::BOUNDS, $desc)).expect("a valid schema")
            }
        }

        impl utoipa::ToSchema for $name {}
    };
}

bounded_grid!(
    /// Wind speeds of the envelope (m/s).
    WindSpeedGrid,
    "Wind speeds (m/s): a list, or {min, max, count} evenly spaced.",
    GridBounds {
        min: 0.0,
        exclusive_min: false,
        max: 150.0,
        max_count: 1000,
        unit: "m/s",
    }
);

bounded_grid!(
    /// Tether lengths of the envelope (m).
    LengthGrid,
    "Tether lengths (m): a list, or {min, max, count} evenly spaced.",
    GridBounds {
        min: 0.0,
        exclusive_min: true,
        max: 1e5,
        max_count: 1000,
        unit: "m",
    }
);

bounded_grid!(
    /// Winch rates of a chart (m/s).
    RateGridInput,
    "Rates (m/s): a list, or {min, max, count} evenly spaced.",
    GridBounds {
        min: 1e-6,
        exclusive_min: false,
        max: 1000.0,
        max_count: crate::numerics::string::chart::MAX_CHART_POINTS,
        unit: "m/s",
    }
);

bounded_grid!(
    /// Forcing frequencies of the wind frequency response (rad/s).
    FrequencyGridInput,
    "Forcing frequencies ω (rad/s): a list, or {min, max, count} evenly spaced.",
    GridBounds {
        min: 0.0,
        exclusive_min: false,
        max: 1e4,
        max_count: crate::numerics::string::frequency_response::MAX_FREQUENCIES,
        unit: "rad/s",
    }
);

bounded_grid!(
    /// Platform frequencies of the GE base-excitation response (rad/s).
    BaseFrequencyGridInput,
    "Platform frequencies ω0 (rad/s): a list, or {min, max, count} evenly spaced.",
    GridBounds {
        min: 0.0,
        exclusive_min: true,
        max: 1e4,
        max_count: crate::numerics::ge::base::MAX_FREQUENCIES,
        unit: "rad/s",
    }
);

bounded_grid!(
    /// Winch rates of uncertainty bands (m/s): at most 1000 rates, each a
    /// Monte-Carlo ensemble.
    BandsRateGridInput,
    "Rates (m/s): a list, or {min, max, count} evenly spaced (at most 1000).",
    GridBounds {
        min: 1e-6,
        exclusive_min: false,
        max: 1000.0,
        max_count: 1000,
        unit: "m/s",
    }
);
