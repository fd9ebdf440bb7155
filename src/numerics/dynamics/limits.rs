//! The bounds of one dynamic run (mesh, steps, work, outputs), in a file
//! of their own so the run's files import them without importing the
//! module's root.

/// Fewest and most segments.
pub const MIN_SEGMENTS: usize = 2;
pub const MAX_SEGMENTS: usize = 2000;
/// Most time steps of one run.
pub const MAX_STEPS: usize = 20_000_000;
/// Most `steps × segments` of one run.
pub const MAX_WORK: f64 = 2e9;
/// Most halvings of a step whose Newton iteration fails.
pub const MAX_HALVINGS: usize = 6;
/// Most samples one run keeps.
pub const MAX_SAMPLES: usize = 200_000;
/// Most shapes one run keeps.
pub const MAX_SHAPES: usize = 1000;
