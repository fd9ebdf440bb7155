//! How a job's independent items are cut into chunks ([`ChunkPlan`]): a
//! plain value the catalogue of kinds sizes and the chunk engine
//! (`chunks.rs`) runs, below both.

use std::ops::Range;

/// How a job's items are cut: `items` in chunks of `per_chunk`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChunkPlan {
    pub items: usize,
    pub per_chunk: usize,
}

impl ChunkPlan {
    /// The plan of `items` items costing about `item_cost_s` seconds each:
    /// chunks of about [`CHUNK_TARGET_S`] seconds, and at least
    /// [`MIN_CHUNKS`] chunks (when there are as many items) once the whole
    /// job is estimated above [`MIN_SPLIT_JOB_S`], so that several workers
    /// share it; a shorter job is one chunk.
    pub fn for_cost(items: usize, item_cost_s: f64) -> Self {
        let cost = item_cost_s.max(1e-9);
        if items as f64 * cost < MIN_SPLIT_JOB_S {
            return Self {
                items,
                per_chunk: items.max(1),
            };
        }
        let per = (CHUNK_TARGET_S / cost).floor();
        let by_cost = if per.is_finite() {
            (per as usize).clamp(1, MAX_ITEMS_PER_CHUNK)
        } else {
            MAX_ITEMS_PER_CHUNK
        };
        let by_count = items.div_ceil(MIN_CHUNKS).max(1);
        Self {
            items,
            per_chunk: by_cost.min(by_count),
        }
    }

    pub fn count(&self) -> usize {
        self.items.div_ceil(self.per_chunk.max(1))
    }

    /// The items of chunk `index`.
    pub fn range(&self, index: usize) -> Range<usize> {
        let start = (index * self.per_chunk).min(self.items);
        start..(start + self.per_chunk).min(self.items)
    }
}

/// Seconds of work aimed at per chunk.
pub const CHUNK_TARGET_S: f64 = 3.0;
/// Chunks of a split job at least (when it has as many items).
pub const MIN_CHUNKS: usize = 8;
/// Jobs estimated below this many seconds are not split.
pub const MIN_SPLIT_JOB_S: f64 = 0.5;
/// Items of one chunk at most (bounds a chunk's result size).
pub const MAX_ITEMS_PER_CHUNK: usize = 4096;
