//! The last guard of every answer: a number the schema calls a number is
//! never sent as `null` (serde_json writes NaN and ±∞ as `null`). Before an
//! answer is written, [`check`] walks it with a serializer that writes
//! nothing and stops at the first non-finite `f64` or `f32`, with the path
//! of the output (`tensions[3].max_n`); the route answers 422 instead.
//! The routes refuse the inputs they know to be out of range themselves,
//! naming them; this catches what they do not know of.

use std::fmt;

use serde::Serialize;
use serde::ser;

use crate::contract::RequestError;
use crate::numerics::params::InvalidInput;

/// Where in the answer a non-finite number was met.
#[derive(Debug)]
pub struct NonFinite {
    pub path: String,
    pub value: f64,
}

impl fmt::Display for NonFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}", self.path, self.value)
    }
}

impl std::error::Error for NonFinite {}

impl ser::Error for NonFinite {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self {
            path: msg.to_string(),
            value: f64::NAN,
        }
    }
}

/// `Ok` when every number of `value` is finite; else the path of the first
/// that is not.
pub fn find_non_finite(value: &impl Serialize) -> Result<(), NonFinite> {
    let mut walker = Walker { path: Vec::new() };
    value.serialize(&mut walker)
}

/// [`find_non_finite`] as the request error of a route: 422 naming the
/// body (the input that made it is not known here) and the output.
pub fn check(value: &impl Serialize) -> Result<(), RequestError> {
    find_non_finite(value).map_err(|e| {
        tracing::warn!(output = %e.path, "refused an answer holding a non-finite number");
        RequestError::Invalid(InvalidInput::new(
            "body",
            format!(
                "this input gives a non-finite number ({}) at `{}` of the answer: some input lies outside the range where the model stays finite (extreme magnitudes, subnormal or huge values)",
                e.value, e.path
            ),
        ))
    })
}

/// `serde_json::to_vec` of an answer after [`check`].
pub fn to_vec(value: &impl Serialize) -> Result<Vec<u8>, RequestError> {
    check(value)?;
    Ok(serde_json::to_vec(value).expect("answers serialise"))
}

/// `serde_json::to_string` of an answer after [`check`].
pub fn to_string(value: &impl Serialize) -> Result<String, RequestError> {
    check(value)?;
    Ok(serde_json::to_string(value).expect("answers serialise"))
}

enum Seg {
    Key(String),
    Index(usize),
}

struct Walker {
    path: Vec<Seg>,
}

impl Walker {
    fn path(&self) -> String {
        let mut s = String::new();
        for seg in &self.path {
            match seg {
                Seg::Key(k) => {
                    if !s.is_empty() {
                        s.push('.');
                    }
                    s.push_str(k);
                }
                Seg::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        if s.is_empty() { "(answer)".into() } else { s }
    }

    fn float(&self, v: f64) -> Result<(), NonFinite> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(NonFinite {
                path: self.path(),
                value: v,
            })
        }
    }

    fn at<T: ?Sized + Serialize>(&mut self, seg: Seg, value: &T) -> Result<(), NonFinite> {
        self.path.push(seg);
        let r = value.serialize(&mut *self);
        self.path.pop();
        r
    }
}

/// Compound values: counts their elements for the path.
struct Compound<'a> {
    w: &'a mut Walker,
    index: usize,
    key: Option<String>,
}

/// Serializer methods of values that hold no number: nothing to check.
macro_rules! no_number {
    ($($m:ident($($t:ty),*)),* $(,)?) => {$(
        fn $m(self, $(_: $t),*) -> Result<(), NonFinite> {
            Ok(())
        }
    )*};
}

/// Serializer methods that open a compound value.
macro_rules! compound {
    ($($m:ident($($t:ty),*)),* $(,)?) => {$(
        fn $m(self, $(_: $t),*) -> Result<Compound<'a>, NonFinite> {
            Ok(self.compound())
        }
    )*};
}

impl<'a> ser::Serializer for &'a mut Walker {
    type Ok = ();
    type Error = NonFinite;
    type SerializeSeq = Compound<'a>;
    type SerializeTuple = Compound<'a>;
    type SerializeTupleStruct = Compound<'a>;
    type SerializeTupleVariant = Compound<'a>;
    type SerializeMap = Compound<'a>;
    type SerializeStruct = Compound<'a>;
    type SerializeStructVariant = Compound<'a>;

    no_number!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_none(),
        serialize_unit(),
        serialize_unit_struct(&'static str),
        serialize_unit_variant(&'static str, u32, &'static str),
    );
    compound!(
        serialize_seq(Option<usize>),
        serialize_tuple(usize),
        serialize_tuple_struct(&'static str, usize),
        serialize_tuple_variant(&'static str, u32, &'static str, usize),
        serialize_map(Option<usize>),
        serialize_struct(&'static str, usize),
        serialize_struct_variant(&'static str, u32, &'static str, usize),
    );

    fn serialize_f32(self, v: f32) -> Result<(), NonFinite> {
        self.float(f64::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), NonFinite> {
        self.float(v)
    }
    fn serialize_some<T: ?Sized + Serialize>(self, value: &T) -> Result<(), NonFinite> {
        value.serialize(self)
    }
    fn serialize_newtype_struct<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), NonFinite> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: ?Sized + Serialize>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), NonFinite> {
        self.at(Seg::Key(variant.into()), value)
    }
}

impl Walker {
    fn compound(&mut self) -> Compound<'_> {
        Compound {
            w: self,
            index: 0,
            key: None,
        }
    }
}

impl Compound<'_> {
    fn element<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), NonFinite> {
        let i = self.index;
        self.index += 1;
        self.w.at(Seg::Index(i), value)
    }
    fn field<T: ?Sized + Serialize>(&mut self, key: &str, value: &T) -> Result<(), NonFinite> {
        self.w.at(Seg::Key(key.into()), value)
    }
}

macro_rules! seq_like {
    ($($t:ident :: $m:ident),*) => {$(
        impl ser::$t for Compound<'_> {
            type Ok = ();
            type Error = NonFinite;
            fn $m<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), NonFinite> {
                self.element(value)
            }
            fn end(self) -> Result<(), NonFinite> {
                Ok(())
            }
        }
    )*};
}
seq_like!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

macro_rules! struct_like {
    ($($t:ident),*) => {$(
        impl ser::$t for Compound<'_> {
            type Ok = ();
            type Error = NonFinite;
            fn serialize_field<T: ?Sized + Serialize>(
                &mut self,
                key: &'static str,
                value: &T,
            ) -> Result<(), NonFinite> {
                self.field(key, value)
            }
            fn end(self) -> Result<(), NonFinite> {
                Ok(())
            }
        }
    )*};
}
struct_like!(SerializeStruct, SerializeStructVariant);

impl ser::SerializeMap for Compound<'_> {
    type Ok = ();
    type Error = NonFinite;
    fn serialize_key<T: ?Sized + Serialize>(&mut self, key: &T) -> Result<(), NonFinite> {
        self.key = Some(key_name(key));
        Ok(())
    }
    fn serialize_value<T: ?Sized + Serialize>(&mut self, value: &T) -> Result<(), NonFinite> {
        let key = self.key.take().unwrap_or_else(|| "?".into());
        self.field(&key, value)
    }
    fn end(self) -> Result<(), NonFinite> {
        Ok(())
    }
}

/// A map key as text (strings and numbers; anything else is `?`). Keys
/// are short: one small `Value` each.
fn key_name<T: ?Sized + Serialize>(key: &T) -> String {
    match key.serialize(serde_json::value::Serializer) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(v @ (serde_json::Value::Number(_) | serde_json::Value::Bool(_))) => v.to_string(),
        _ => "?".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[derive(Serialize)]
    struct Point {
        x: f64,
        y: Option<f64>,
    }

    #[derive(Serialize)]
    struct Answer {
        points: Vec<Point>,
        label: String,
    }

    #[test]
    fn finite_answers_pass_and_the_first_non_finite_is_named() {
        let ok = Answer {
            points: vec![
                Point { x: 1.0, y: None },
                Point {
                    x: -2.5,
                    y: Some(0.0),
                },
            ],
            label: "a".into(),
        };
        assert!(find_non_finite(&ok).is_ok());
        let bad = Answer {
            points: vec![
                Point { x: 1.0, y: None },
                Point {
                    x: 2.0,
                    y: Some(f64::INFINITY),
                },
            ],
            label: "a".into(),
        };
        let e = find_non_finite(&bad).unwrap_err();
        assert_eq!(e.path, "points[1].y");
        assert_eq!(e.value, f64::INFINITY);
        let map = json!({"a": {"b": [1.0, 2.0]}});
        assert!(find_non_finite(&map).is_ok());
        let e = find_non_finite(&std::collections::BTreeMap::from([("k", f64::NAN)])).unwrap_err();
        assert_eq!(e.path, "k");
        assert!(e.value.is_nan());
        // integer keys are named by their number
        let e = find_non_finite(&std::collections::BTreeMap::from([(
            7u32,
            [0.0, f64::NEG_INFINITY],
        )]))
        .unwrap_err();
        assert_eq!(e.path, "7[1]");
        // serde_json would have written `null` where a number belongs
        assert_eq!(
            serde_json::to_string(&bad).unwrap(),
            r#"{"points":[{"x":1.0,"y":null},{"x":2.0,"y":null}],"label":"a"}"#
        );
        assert!(matches!(check(&bad), Err(RequestError::Invalid(_))));
    }
}
