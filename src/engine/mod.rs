//! The engine every plan runs on: samples -> FFT stage -> lane rows -> DWT stage ->
//! coefficients (forward), and back (inverse). See `docs/design.md`.
//!
//! - `betas`: the lane pairs of a beta and its mirror that the kernels run on;
//! - `fft_stage`: pruned slice DFTs and the workers' slice buffers;
//! - `slots`: where a slice's values are in the lane rows (`LaneRows`, `SlotTable`);
//! - `dwt_stage`: the clusters of a shape and their kernel calls;
//! - `coeffs`: copies of coefficient rows between the kernels' rows and the array;
//! - `footprint`: [`Footprint`], what a plan holds, known before it is made;
//! - `chunks`: [`Engine`], its construction and the chunks of lane pairs it runs;
//! - `inverse`, `forward`: the two directions, chunk by chunk;
//! - `copies`: values between a slice's buffer and its slots in the lane rows.

mod betas;
mod chunks;
mod coeffs;
mod copies;
mod dwt_stage;
mod fft_stage;
mod footprint;
mod forward;
mod inverse;
mod slots;

pub(crate) use betas::LanePairs;
pub(crate) use chunks::{Data, Engine};
pub(crate) use dwt_stage::{padded_row, ChunkLanes, ClusterPlan};
pub(crate) use fft_stage::{SliceRef, SliceWatch};
pub(crate) use footprint::Footprint;
pub(crate) use slots::LaneRows;
