//! The worker threads of plans: a rayon pool shared by the plans of a process with the same
//! worker count, which the last of them waits for when dropped, and which a child made by
//! `fork()` never waits for (its threads are the parent's); and [`SendPtr`], the address the
//! tasks of one execution share.

use crate::error::{Error, Result};
use crate::system::ForkLock;
use std::cell::UnsafeCell;
use std::sync::{Arc, Condvar, Mutex, Once, Weak};

/// Largest worker count a plan accepts.
pub(crate) const MAX_THREADS: usize = 1024;

/// The worker count of a `threads` option: 0 means all cores; more than
/// [`MAX_THREADS`] is an error.
pub(crate) fn thread_count(threads: usize) -> Result<usize> {
    let n = if threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        threads
    };
    if n > MAX_THREADS {
        return Err(Error::InvalidArgument(format!(
            "{n} threads requested (at most {MAX_THREADS})"
        )));
    }
    Ok(n)
}

/// Stack of each worker thread (the kernels keep their state in per-worker scratch).
pub(crate) const WORKER_STACK_BYTES: usize = 2 << 20;

/// Pools of plans dropped in a child made by `fork()`: kept reachable until the process
/// ends, since dropping them would wait for threads that do not exist there.
static ORPHAN_POOLS: Mutex<Vec<rayon::ThreadPool>> = Mutex::new(Vec::new());

/// The process's pools by worker count, held weakly: a pool lives while a plan holds it, so
/// a program that makes many plans runs one set of workers per thread count, and one that
/// drops all its plans has no threads left. Accessed only under [`REGISTRY_LOCK`].
struct PoolRegistry(UnsafeCell<Vec<(usize, Weak<Workers>)>>);

// SAFETY: the vector is only accessed while `REGISTRY_LOCK` is held (`WorkerPool::process`).
unsafe impl Sync for PoolRegistry {}

static PROCESS_POOLS: PoolRegistry = PoolRegistry(UnsafeCell::new(Vec::new()));

/// Guards [`PROCESS_POOLS`]; a child made by `fork()` never inherits it locked.
static REGISTRY_LOCK: ForkLock = ForkLock::new();

/// A plan's worker threads. Clones share the threads (plans run one after another by one
/// caller, such as a correlation's transforms, share a pool: a task already on its
/// workers calls the next plan's stages directly instead of waking the workers again);
/// the last clone dropped waits for them.
#[derive(Clone)]
pub(crate) struct WorkerPool(Arc<Workers>);

/// The threads behind a [`WorkerPool`].
struct Workers {
    /// The pool (an `Option` so `Drop` can release it before waiting for the workers).
    pool: Option<rayon::ThreadPool>,
    /// Number of pool threads still running; `Drop` waits for zero.
    live: Arc<(Mutex<usize>, Condvar)>,
    /// The process that started the threads.
    pid: u32,
}

impl WorkerPool {
    /// Starts `threads` workers named `<name>-<i>`; [`Error::Resources`] if the system
    /// refuses them.
    pub(crate) fn new(threads: usize, name: &'static str) -> Result<WorkerPool> {
        let live = Arc::new((Mutex::new(threads), Condvar::new()));
        let on_exit = live.clone();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(move |i| format!("{name}-{i}"))
            .stack_size(WORKER_STACK_BYTES)
            .exit_handler(move |_| {
                let (n, cv) = &*on_exit;
                *n.lock().unwrap_or_else(|e| e.into_inner()) -= 1;
                cv.notify_all();
            })
            .build()
            .map_err(|e| Error::Resources(format!("cannot start {threads} worker threads: {e}")))?;
        Ok(WorkerPool(Arc::new(Workers {
            pool: Some(pool),
            live,
            pid: std::process::id(),
        })))
    }

    /// The process's pool of `threads` workers (named `so3fft-<i>`), started if no plan
    /// of this process holds one; [`Error::Resources`] if the system refuses the threads.
    pub(crate) fn process(threads: usize) -> Result<WorkerPool> {
        static HANDLERS: Once = Once::new();
        HANDLERS.call_once(|| {
            extern "C" fn prepare() {
                REGISTRY_LOCK.before_fork();
            }
            extern "C" fn release() {
                REGISTRY_LOCK.after_fork();
            }
            // SAFETY: the handlers are plain functions that live as long as the process. If
            // registration fails (ENOMEM), a fork during a plan's construction may leave
            // the registry locked in the child, as without it.
            unsafe { libc::pthread_atfork(Some(prepare), Some(release), Some(release)) };
        });
        let _guard = REGISTRY_LOCK.lock();
        // SAFETY: the lock is held, so no other reference to the vector exists.
        let pools = unsafe { &mut *PROCESS_POOLS.0.get() };
        pools.retain(|(_, w)| w.strong_count() > 0);
        // A parent's pool in a child made by `fork()` has no threads here: it is passed over
        // (and stays listed while the parent's plans live in the child's memory).
        let found = pools
            .iter()
            .filter(|(n, _)| *n == threads)
            .find_map(|(_, w)| w.upgrade().filter(|w| w.in_own_process()));
        if let Some(w) = found {
            return Ok(WorkerPool(w));
        }
        let pool = WorkerPool::new(threads, "so3fft")?;
        pools.push((threads, Arc::downgrade(&pool.0)));
        Ok(pool)
    }

    /// `shared` if given (an error unless it has `threads` workers), else the process's
    /// pool of `threads` workers ([`WorkerPool::process`]).
    pub(crate) fn shared_or_new(shared: Option<&WorkerPool>, threads: usize) -> Result<WorkerPool> {
        match shared {
            Some(w) if w.pool().current_num_threads() == threads => Ok(w.clone()),
            Some(w) => Err(Error::InvalidArgument(format!(
                "a plan of {threads} threads on a pool of {}",
                w.pool().current_num_threads()
            ))),
            None => WorkerPool::process(threads),
        }
    }

    /// The rayon pool.
    pub(crate) fn pool(&self) -> &rayon::ThreadPool {
        self.0.pool.as_ref().expect("pool lives until drop")
    }

    /// Whether the worker threads exist in this process: `false` in a child made by
    /// `fork()` after the pool was started.
    pub(crate) fn in_own_process(&self) -> bool {
        self.0.in_own_process()
    }

    /// Whether `self` and `other` are the same workers (for tests).
    #[cfg(test)]
    pub(crate) fn same_as(&self, other: &WorkerPool) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }

    /// An error unless the workers exist in this process: a plan made before `fork()`,
    /// used in the child, has none there.
    pub(crate) fn check_process(&self) -> Result<()> {
        if self.in_own_process() {
            Ok(())
        } else {
            Err(Error::InvalidArgument(
                "plan made in another process (before fork()): its worker threads do not \
                 exist here; make a new plan in this process"
                    .into(),
            ))
        }
    }

    /// Number of worker threads still running (for tests).
    #[cfg(test)]
    pub(crate) fn live_count(&self) -> Arc<(Mutex<usize>, Condvar)> {
        self.0.live.clone()
    }
}

impl Workers {
    fn in_own_process(&self) -> bool {
        std::process::id() == self.pid
    }
}

impl Drop for Workers {
    /// Releases the pool and waits until its threads have finished, so that nothing of the
    /// plan runs after it is gone (a C host may unload the library right after).
    fn drop(&mut self) {
        // Dropping on one of its own workers would wait for itself; no code outside the
        // library runs on these workers, so this cannot happen through the public API.
        debug_assert!(self
            .pool
            .as_ref()
            .is_none_or(|p| p.current_thread_index().is_none()));
        if !self.in_own_process() {
            if let Some(pool) = self.pool.take() {
                ORPHAN_POOLS
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(pool);
            }
            return;
        }
        drop(self.pool.take());
        let (n, cv) = &*self.live;
        let mut g = n.lock().unwrap_or_else(|e| e.into_inner());
        while *g > 0 {
            g = cv.wait(g).unwrap_or_else(|e| e.into_inner());
        }
    }
}

/// A pointer to memory that the tasks of one execution write (and read) at disjoint
/// places.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SendPtr<T>(pub(crate) *mut T);

// SAFETY: a `SendPtr` is only an address. It is dereferenced only inside one execution,
// while the array it points into is borrowed for that execution by the public entry point,
// and the tasks that receive copies of it write disjoint index sets (or only read).
unsafe impl<T> Send for SendPtr<T> {}
// SAFETY: as for `Send`: shared references give only copies of the address.
unsafe impl<T> Sync for SendPtr<T> {}

impl<T> SendPtr<T> {
    /// The pointer (a method, so closures capture the whole `Send` wrapper).
    pub(crate) fn get(self) -> *mut T {
        self.0
    }
}

/// A pointer to memory that the tasks of one execution only read (a transform's input).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SendConstPtr<T>(pub(crate) *const T);

// SAFETY: the pointed-to values are only read through it, by all tasks, while the array
// is borrowed for the execution; writers of the same memory (a forward that may overwrite
// its input) say at their dereferences why those writes come after every read.
unsafe impl<T> Send for SendConstPtr<T> {}
// SAFETY: as for `Send`.
unsafe impl<T> Sync for SendConstPtr<T> {}

impl<T> SendConstPtr<T> {
    /// The pointer (a method, so closures capture the whole `Send` wrapper).
    pub(crate) fn get(self) -> *const T {
        self.0
    }
}

/// Lock a free entry of `pool`, trying the current worker's own first; `None` if all are
/// in use (possible only when one plan is executed from several threads at once).
pub(crate) fn lock_free<T>(pool: &[Mutex<T>]) -> Option<std::sync::MutexGuard<'_, T>> {
    let n = pool.len();
    let tid = rayon::current_thread_index().unwrap_or(0);
    (0..n).find_map(|i| match pool[(tid + i) % n].try_lock() {
        Ok(g) => Some(g),
        Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => None,
    })
}

#[cfg(test)]
mod tests {
    use super::WorkerPool;

    /// In a child made by `fork()`, the parent's pool (still listed, its plans still in
    /// the child's memory) is passed over, and the child's plans share one pool of their own.
    #[test]
    fn a_forked_child_shares_a_pool_of_its_own() {
        // A thread count no other test uses, so that this pool is the parent's own.
        let parent = WorkerPool::process(3).unwrap();
        // SAFETY: the child makes and compares pools, then leaves by `_exit` without
        // running anything of the test harness; the registry's lock is free in the child
        // (its fork handlers).
        let pid = unsafe { libc::fork() };
        assert!(pid >= 0, "fork failed");
        if pid == 0 {
            let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let a = WorkerPool::process(3).unwrap();
                let b = WorkerPool::process(3).unwrap();
                a.same_as(&b) && !a.same_as(&parent)
            }))
            .unwrap_or(false);
            // SAFETY: ends the child at once (no destructors, no atexit handlers).
            unsafe { libc::_exit(if ok { 0 } else { 1 }) };
        }
        let mut status = 0;
        // SAFETY: waits for the child made above; `status` is a valid out-pointer.
        let waited = unsafe { libc::waitpid(pid, &mut status, 0) };
        assert_eq!(waited, pid);
        assert!(
            libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
            "the child's plans did not share one pool of its own (status {status})"
        );
        assert!(parent.same_as(&WorkerPool::process(3).unwrap()));
    }
}
