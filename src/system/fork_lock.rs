//! A process-wide mutex that a child made by `fork()` never inherits locked.
//!
//! A lock held by another thread at `fork()` stays held forever in the child (that thread
//! does not exist there). A [`ForkLock`] lives in a `static`; its owner registers
//! [`ForkLock::before_fork`] and [`ForkLock::after_fork`] with `pthread_atfork`, so `fork()`
//! waits until no one holds the lock and both processes continue with it free.

use std::cell::UnsafeCell;

/// A mutex (no data) for `static`s, safe across `fork()` once its handlers are registered.
pub(crate) struct ForkLock(UnsafeCell<libc::pthread_mutex_t>);

// SAFETY: the pthread mutex is made to be shared between threads; it is only used through
// the pthread calls below, which synchronise.
unsafe impl Sync for ForkLock {}

/// Holds a [`ForkLock`] until dropped (on the thread that locked it: not `Send`).
pub(crate) struct ForkLockGuard<'a>(&'a ForkLock, std::marker::PhantomData<*const ()>);

impl ForkLock {
    /// An unlocked lock (for a `static`).
    pub(crate) const fn new() -> ForkLock {
        ForkLock(UnsafeCell::new(libc::PTHREAD_MUTEX_INITIALIZER))
    }

    /// Waits for the lock and holds it until the guard is dropped.
    pub(crate) fn lock(&self) -> ForkLockGuard<'_> {
        // SAFETY: the mutex is initialised (static initializer) and never moved (it is in
        // a `static`, the only use); a default mutex locked twice by one thread would
        // deadlock, which the callers' non-reentrant use rules out.
        unsafe { libc::pthread_mutex_lock(self.0.get()) };
        ForkLockGuard(self, std::marker::PhantomData)
    }

    /// The `prepare` handler's part: takes the lock, so no other thread holds it at the
    /// fork.
    pub(crate) fn before_fork(&self) {
        // SAFETY: as in `lock`; released by `after_fork` in parent and child.
        unsafe { libc::pthread_mutex_lock(self.0.get()) };
    }

    /// The `parent` and `child` handlers' part: releases the lock taken by `before_fork`.
    pub(crate) fn after_fork(&self) {
        // SAFETY: the calling thread took the lock in `before_fork` (in the child it is the
        // copy of that thread, the owner of the copied mutex).
        unsafe { libc::pthread_mutex_unlock(self.0.get()) };
    }
}

impl Drop for ForkLockGuard<'_> {
    fn drop(&mut self) {
        // SAFETY: this guard's thread locked the mutex in `ForkLock::lock`.
        unsafe { libc::pthread_mutex_unlock(self.0 .0.get()) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn excludes_other_threads() {
        static LOCK: ForkLock = ForkLock::new();
        static INSIDE: AtomicUsize = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| {
                    for _ in 0..1000 {
                        let _g = LOCK.lock();
                        assert_eq!(INSIDE.fetch_add(1, Ordering::SeqCst), 0);
                        INSIDE.fetch_sub(1, Ordering::SeqCst);
                    }
                });
            }
        });
    }
}
