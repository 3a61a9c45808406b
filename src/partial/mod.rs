//! Partial plans: SO(3) transforms that compute only what a [`Shape`] holds (degree and
//! order limits, other sample grids), at selected betas ([`Betas`]), several at once
//! ([`Batch`]), complex or real. See `docs/partial-plans.md`.
//!
//! - `shape`: [`Shape`], its validation and coefficient layout;
//! - `betas`: [`Betas`] and the kernels' lane pairs of a beta and its mirror;
//! - `dwt_stage`: the clusters of a shape and their kernel calls;
//! - `fft_stage`: pruned slice DFTs;
//! - `plan`: [`PartialPlan`], construction and the chunk loop;
//! - `distributed`: [`DistributedPlan`], the transforms spread over ranks ([`Exchange`]).

mod betas;
mod distributed;
mod dwt_stage;
mod fft_stage;
#[cfg(feature = "mpi")]
mod mpi;
mod plan;
mod shape;
#[cfg(test)]
mod tests;

pub use betas::Betas;
pub use distributed::{DistributedPlan, DistributedTimes, Exchange, ThreadExchange};
#[cfg(feature = "mpi")]
pub use mpi::{mpi_finalize, mpi_init, MpiExchange};
pub use plan::{Batch, PartialOptions, PartialPlan};
pub use shape::{Shape, MAX_GRID_SIDE};
