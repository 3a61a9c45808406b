//! Sharing between the worker tasks of one execution: raw-pointer wrappers that may be
//! sent across rayon tasks, and per-worker pools of scratch.
//!
//! A transform hands its arrays (samples, coefficients, chunk buffers) to the workers as
//! raw pointers, because the tasks write disjoint parts of one array: a cluster's block
//! and coefficient rows, a pair of beta slices, a range of rows. The wrappers carry no
//! guarantee themselves; each use says why its accesses are disjoint (see the SAFETY
//! comments at the dereferences).

use std::sync::Mutex;

pub(super) use crate::workers::SendPtr;

/// A pointer to memory that the tasks of one execution only read (a transform's input).
#[derive(Clone, Copy, Debug)]
pub(super) struct SendConstPtr<T>(pub(super) *const T);

// SAFETY: the pointed-to values are only read through it, by all tasks, while the array
// is borrowed for the execution; a forward that may overwrite its input writes chunk
// buffers only into slices whose reads are finished (see `Spare::consumed` and
// `Schedule::chain`), and never through this pointer.
unsafe impl<T> Send for SendConstPtr<T> {}
// SAFETY: as for `Send`.
unsafe impl<T> Sync for SendConstPtr<T> {}

impl<T> SendConstPtr<T> {
    /// The pointer (a method, so closures capture the whole `Send` wrapper).
    pub(super) fn get(self) -> *const T {
        self.0
    }
}

/// Lock a free entry of `pool`, trying the current worker's own first; `None` if all are
/// in use (possible only when one plan is executed from several threads at once).
pub(super) fn lock_free<T>(pool: &[Mutex<T>]) -> Option<std::sync::MutexGuard<'_, T>> {
    let n = pool.len();
    let tid = rayon::current_thread_index().unwrap_or(0);
    (0..n).find_map(|i| match pool[(tid + i) % n].try_lock() {
        Ok(g) => Some(g),
        Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => None,
    })
}
