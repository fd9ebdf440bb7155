//! The one grid type of every request (rates, tether lengths, wind
//! speeds, frequencies): a list of values, or `{min, max, count}` evenly
//! spaced (ends included). Both forms give the same values, so the same
//! answer.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::numerics::params::{InvalidInput, compact};

/// Values: a list `[..]`, or `{min, max, count}` evenly spaced, ends included.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(untagged)]
pub enum GridInput {
    /// The values, in the order given.
    List(Vec<f64>),
    /// `count` values from `min` to `max`, evenly spaced (one value: `min`).
    Range(GridRangeInput),
}

/// An evenly spaced grid.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GridRangeInput {
    #[schema(example = 1.0)]
    pub min: f64,
    #[schema(example = 10.0)]
    pub max: f64,
    #[schema(example = 10, minimum = 1)]
    pub count: usize,
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
