//! Crate-internal kernels and stages, exposed for the measuring tools in `benches/`
//! (feature `internals`). Not part of the public API: no stability promise.

pub use crate::plan::{fft_stage_alone, BlockCopies};
