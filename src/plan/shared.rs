//! Sharing between the worker tasks of one execution: raw-pointer wrappers that may be
//! sent across rayon tasks, and per-worker pools of scratch.

use std::sync::Mutex;

/// Shared mutable pointer for disjoint parallel writes.
#[derive(Clone, Copy)]
pub(super) struct SyncPtr<T>(pub(super) *mut T);
// SAFETY: used only for writes to disjoint index sets from different tasks.
unsafe impl<T> Send for SyncPtr<T> {}
// SAFETY: as for `Send`.
unsafe impl<T> Sync for SyncPtr<T> {}

impl<T> SyncPtr<T> {
    /// The pointer (a method, so closures capture the whole `Sync` wrapper).
    pub(super) fn get(self) -> *mut T {
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
