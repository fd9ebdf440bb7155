//! Duplicate keys in a JSON object are refused (RFC 8259 leaves their
//! meaning open; serde_json silently keeps the last), naming the key with
//! its path: `{"cable": {"mass_per_length_kg_m": 1, "mass_per_length_kg_m": 2}}`
//! is 422 at `cable.mass_per_length_kg_m`. Every door checks it: the API's
//! JSON body extractor and the CLI's input reader.

use std::collections::HashSet;
use std::fmt;

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};

use crate::contract::RequestError;
use crate::numerics::params::InvalidInput;

const MARK: &str = "duplicate key\u{1}";

/// `Err` (422 naming the key's path) when an object of `body` repeats a
/// key; `Ok` otherwise, also when `body` is not JSON at all (the parser
/// that follows says why, with its own 400).
pub fn reject_duplicate_keys(body: &[u8]) -> Result<(), RequestError> {
    let mut de = serde_json::Deserializer::from_slice(body);
    match (Node {
        path: String::new(),
    })
    .deserialize(&mut de)
    {
        Ok(()) => Ok(()),
        Err(e) => {
            let text = e.to_string();
            match text.strip_prefix(MARK) {
                Some(rest) => {
                    let path = rest.split('\u{1}').next().unwrap_or("body").to_string();
                    let key = path.rsplit('.').next().unwrap_or(&path).to_string();
                    Err(RequestError::Invalid(InvalidInput::new(
                        path,
                        format!(
                            "duplicate key `{key}`: each key may appear once in an object (JSON does not say which would count)"
                        ),
                    )))
                }
                None => Ok(()),
            }
        }
    }
}

/// A JSON value at `path`, checked and thrown away.
struct Node {
    path: String,
}

impl<'de> DeserializeSeed<'de> for Node {
    type Value = ();
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl Node {
    fn child(&self, key: &str) -> Node {
        Node {
            path: if self.path.is_empty() {
                key.to_string()
            } else {
                format!("{}.{key}", self.path)
            },
        }
    }
}

impl<'de> Visitor<'de> for Node {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
    fn visit_none<E>(self) -> Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0usize;
        while seq
            .next_element_seed(Node {
                path: format!("{}[{i}]", self.path),
            })?
            .is_some()
        {
            i += 1;
        }
        Ok(())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen: HashSet<String> = HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let child = self.child(&key);
            if !seen.insert(key) {
                return Err(de::Error::custom(format!("{MARK}{}\u{1}", child.path)));
            }
            map.next_value_seed(child)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(body: &str) -> Option<String> {
        match reject_duplicate_keys(body.as_bytes()) {
            Ok(()) => None,
            Err(RequestError::Invalid(e)) => Some(e.field),
            Err(other) => panic!("{other:?}"),
        }
    }

    #[test]
    fn duplicate_keys_are_named_with_their_path() {
        assert_eq!(field(r#"{"a": 1, "b": {"c": 2}}"#), None);
        assert_eq!(field(r#"{"a": 1, "a": 2}"#).as_deref(), Some("a"));
        assert_eq!(
            field(r#"{"cable": {"m": 1, "x": [], "m": 2}}"#).as_deref(),
            Some("cable.m")
        );
        assert_eq!(
            field(r#"{"p": {"points": [{"t": 0}, {"t": 1, "t": 2}]}}"#).as_deref(),
            Some("p.points[1].t")
        );
        // the same key in sibling objects is fine
        assert_eq!(field(r#"[{"t": 0}, {"t": 1}]"#), None);
        // not JSON: left to the parser's 400
        assert_eq!(field(r#"{"a": 1, "b""#), None);
    }
}
