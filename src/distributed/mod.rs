//! Distributed plans: a partial plan's transforms spread over the ranks of a group.
//!
//! - `plan`: [`DistributedPlan`], its split of the betas and the coefficients, and its
//!   transforms;
//! - `exchange`: [`Exchange`], what a plan needs of its group, and [`ThreadExchange`];
//! - `mpi`: `MpiExchange`, the exchange over MPI (feature `mpi`).

mod exchange;
#[cfg(feature = "mpi")]
mod mpi;
mod plan;

pub use exchange::{Exchange, ThreadExchange};
#[cfg(feature = "mpi")]
pub use mpi::{mpi_finalize, mpi_init, MpiExchange};
pub use plan::DistributedPlan;
