//! Sharing between the worker tasks of one execution: raw-pointer wrappers that may be
//! sent across rayon tasks, and per-worker pools of scratch (defined in `workers`, shared
//! with the other plans).
//!
//! A transform hands its arrays (samples, coefficients, chunk buffers) to the workers as
//! raw pointers, because the tasks write disjoint parts of one array: a cluster's block
//! and coefficient rows, a pair of beta slices, a range of rows. The wrappers carry no
//! guarantee themselves; each use says why its accesses are disjoint (see the SAFETY
//! comments at the dereferences). A forward that may overwrite its input writes chunk
//! buffers only into slices whose reads are finished (see `Spare::consumed` and
//! `Schedule::chain`).

pub(super) use crate::workers::{lock_free, SendConstPtr, SendPtr};
