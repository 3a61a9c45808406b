//! Partial plans: SO(3) transforms that compute only what a [`Shape`] holds (degree and
//! order limits, other sample grids), at selected betas ([`Betas`](crate::Betas)), several at once
//! ([`Batch`]), complex or real. See `docs/partial-plans.md`.
//!
//! - `shape`: [`Shape`], its validation and coefficient layout;
//! - `betas`: [`Betas`](crate::Betas) (options) and the kernels' lane pairs of a beta and its mirror;
//! - `coeffs`: copies of coefficient rows between the kernels' rows and the array;
//! - `dwt_stage`: the clusters of a shape and their kernel calls;
//! - `fft_stage`: pruned slice DFTs;
//! - `options`: [`Batch`];
//! - `plan`: [`PartialPlan`], its construction, argument checks and transforms;
//! - `general`: the engine every shape runs on (the full one too, see [`Plan`](crate::Plan)):
//!   the chunk loop;
//! - `slots`: where a slice's values are in the lane rows (`LaneRows`, `SlotTable`);
//! - `distributed`: [`DistributedPlan`], the transforms spread over ranks;
//! - `exchange`: [`Exchange`], what they need of their group, and [`ThreadExchange`];
//! - `mpi`: `MpiExchange`, the exchange over MPI (feature `mpi`).

mod betas;
mod coeffs;
mod distributed;
mod dwt_stage;
mod exchange;
mod fft_stage;
mod general;
#[cfg(feature = "mpi")]
mod mpi;
mod options;
mod plan;
mod shape;
mod slots;

pub use distributed::DistributedPlan;
pub use exchange::{Exchange, ThreadExchange};
pub(crate) use fft_stage::SliceRef;
#[cfg(feature = "mpi")]
pub use mpi::{mpi_finalize, mpi_init, MpiExchange};
pub use options::Batch;
pub use plan::PartialPlan;
pub use shape::{Shape, MAX_GRID_SIDE};
