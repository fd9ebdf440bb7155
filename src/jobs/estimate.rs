//! The answer-size estimates' old path (`jobs::estimate::…`): they are a
//! property of each analysis kind, in [`crate::contract::estimate`].

pub use crate::contract::estimate::*;
