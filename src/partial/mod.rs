//! Partial plans: SO(3) transforms that compute only what a [`Shape`] holds (degree and
//! order limits, other sample grids), at selected betas ([`Betas`](crate::Betas)), several at once
//! ([`Batch`]), complex or real. See `docs/partial-plans.md`.
//!
//! [`PartialPlan`] lives in `plan`; the shape, the batch layout and the distributed plans
//! have their own modules and are re-exported here, where earlier releases had them.

mod plan;

pub use crate::batch::Batch;
#[cfg(feature = "mpi")]
pub use crate::distributed::{mpi_finalize, mpi_init, MpiExchange};
pub use crate::distributed::{DistributedPlan, Exchange, ThreadExchange};
pub use crate::shape::{Shape, MAX_GRID_SIDE};
pub use plan::PartialPlan;
