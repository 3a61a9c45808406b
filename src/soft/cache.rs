//! The plan caches of the SOFT layer: a [`Cache`] per plan type (the SO(3) [`Plan`]s here,
//! the S^2 plans in `s2::transforms`), one plan per bandwidth made on first use and kept
//! for the life of the process, and the optional wisdom file (`SO3FFT_SOFT_WISDOM`).

use super::SoftResult;
use crate::ffi::CallError;
use crate::system::ForkLock;
use crate::workers::{thread_count, WorkerPool};
use crate::{wisdom, Direction, FftThreading, Options, Plan, Rigor};
use std::cell::UnsafeCell;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, Once, OnceLock, PoisonError};

/// One slot per bandwidth; the slot's own lock serialises creation of that plan only.
type Slot<P> = Arc<Mutex<Option<Arc<P>>>>;

/// The lock of every cache's map (slot look-ups are short; one lock keeps the `fork()`
/// handlers simple).
static MAP_LOCK: ForkLock = ForkLock::new();

/// The slots of one plan type, keyed by process id and bandwidth: a child made by `fork()`
/// never touches a slot whose lock a thread of its parent held at the fork (it would wait
/// forever). Lives in a `static`.
pub(super) struct Cache<P> {
    map: UnsafeCell<BTreeMap<(u32, usize), Slot<P>>>,
}

// SAFETY: `map` is only accessed while `MAP_LOCK` is held (`Cache::slot`); the plans it
// holds are shared between threads through `Arc`, hence `P: Send + Sync`.
unsafe impl<P: Send + Sync> Sync for Cache<P> {}

impl<P> Cache<P> {
    /// An empty cache.
    pub(super) const fn new() -> Cache<P> {
        Cache {
            map: UnsafeCell::new(BTreeMap::new()),
        }
    }

    /// The plan of bandwidth `b` in this process if it has been made (and no thread is
    /// making it right now), without making it.
    fn made(&self, b: usize) -> Option<Arc<P>> {
        let slot = {
            let _guard = MAP_LOCK.lock();
            // SAFETY: the lock is held, so no other reference to the map exists.
            let map = unsafe { &*self.map.get() };
            map.get(&(std::process::id(), b))?.clone()
        };
        let g = match slot.try_lock() {
            Ok(g) => g,
            Err(std::sync::TryLockError::Poisoned(e)) => e.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => return None,
        };
        g.as_ref().map(Arc::clone)
    }

    /// The slot of bandwidth `b` in this process, made empty on first use.
    fn slot(&self, b: usize) -> Slot<P> {
        let _guard = MAP_LOCK.lock();
        // SAFETY: the lock is held, so no other reference to the map exists.
        let map = unsafe { &mut *self.map.get() };
        map.entry((std::process::id(), b)).or_default().clone()
    }
}

/// SO(3) plans (`Direction::Both`).
static SO3_PLANS: Cache<Plan> = Cache::new();

/// Registers the map lock's `fork()` handlers (once, before the first use).
fn register_fork_handlers() {
    static REGISTERED: Once = Once::new();
    REGISTERED.call_once(|| {
        extern "C" fn prepare() {
            MAP_LOCK.before_fork();
        }
        extern "C" fn release() {
            MAP_LOCK.after_fork();
        }
        // SAFETY: plain functions living as long as the process. If registration fails,
        // a fork at the moment a thread looks up a slot may leave the child's lock held.
        unsafe { libc::pthread_atfork(Some(prepare), Some(release), Some(release)) };
    });
}

/// The wisdom file named by `SO3FFT_SOFT_WISDOM` (read once), if any.
fn wisdom_file() -> Option<&'static PathBuf> {
    static FILE: OnceLock<Option<PathBuf>> = OnceLock::new();
    FILE.get_or_init(|| {
        std::env::var_os("SO3FFT_SOFT_WISDOM")
            .filter(|s| !s.is_empty())
            .map(PathBuf::from)
    })
    .as_ref()
}

/// One line on stderr about the wisdom file (the layer's only channel; never fatal).
fn wisdom_warning(what: &str, err: &crate::Error) {
    let _ = writeln!(std::io::stderr(), "so3fft (SOFT layer): {what}: {err}");
}

/// Worker threads of the cached plans: `SO3FFT_SOFT_THREADS` (read once), 0 = all cores.
fn env_threads() -> usize {
    static THREADS: OnceLock<usize> = OnceLock::new();
    *THREADS.get_or_init(|| {
        std::env::var("SO3FFT_SOFT_THREADS")
            .ok()
            .and_then(|s| s.trim().parse::<usize>().ok())
            .unwrap_or(0)
    })
}

/// FFTW rigour of the cached plans: `SO3FFT_SOFT_RIGOR` (read once), default `measure`.
fn env_rigor() -> Rigor {
    static RIGOR: OnceLock<Rigor> = OnceLock::new();
    *RIGOR.get_or_init(|| {
        match std::env::var("SO3FFT_SOFT_RIGOR")
            .unwrap_or_default()
            .trim()
            .to_ascii_lowercase()
            .as_str()
        {
            "estimate" => Rigor::Estimate,
            "patient" => Rigor::Patient,
            "exhaustive" => Rigor::Exhaustive,
            _ => Rigor::Measure,
        }
    })
}

/// Plan options of the cached SO(3) plans.
fn cache_options() -> &'static Options {
    static OPTS: OnceLock<Options> = OnceLock::new();
    OPTS.get_or_init(|| {
        Options {
            direction: Direction::Both,
            threads: env_threads(),
            rigor: env_rigor(),
            // flag = 1 calls use the engine's real-signal path.
            real: true,
            // With a wisdom file the FFT plans are recorded, and the FFT stage's threading
            // is fixed rather than timed: planning is fast and results are reproducible.
            fft_threading: if wisdom_file().is_some() {
                FftThreading::SlicesAcrossWorkers
            } else {
                FftThreading::Auto
            },
            ..Options::default()
        }
    })
}

/// The cached plan of bandwidth `b` in `cache`, made by `make` on first use (with the
/// wisdom file imported before the first plan and exported after each new one). A failed
/// creation is not cached.
pub(super) fn cached<P>(
    cache: &'static Cache<P>,
    b: usize,
    make: impl FnOnce() -> crate::Result<P>,
) -> SoftResult<Arc<P>> {
    register_fork_handlers();
    let slot = cache.slot(b);
    let mut g = slot.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(p) = g.as_ref() {
        return Ok(Arc::clone(p));
    }
    let file = wisdom_file();
    if let Some(path) = file {
        static IMPORTED: Once = Once::new();
        IMPORTED.call_once(|| {
            if path.exists() {
                if let Err(e) = wisdom::import_from_file(path) {
                    wisdom_warning("SO3FFT_SOFT_WISDOM", &e);
                }
            }
        });
    }
    let p = Arc::new(
        make().map_err(|e| CallError::from(e).context(&format!("cannot plan bandwidth {b}")))?,
    );
    if let Some(path) = file {
        if let Err(e) = wisdom::export_to_file(path) {
            wisdom_warning("SO3FFT_SOFT_WISDOM", &e);
        }
    }
    *g = Some(Arc::clone(&p));
    Ok(p)
}

/// The worker threads of every cached plan of this process: one pool, so that a client's
/// calls one after another (two S^2 transforms, the combine, the SO(3) inverse) reach the
/// same workers, which are often still awake from the call before, instead of waking those
/// of each plan in turn. Made on first use, anew in a child made by `fork()`.
pub(super) fn layer_workers() -> crate::Result<WorkerPool> {
    struct PoolSlot(UnsafeCell<Option<WorkerPool>>);
    // SAFETY: the cell is only accessed while `MAP_LOCK` is held (below).
    unsafe impl Sync for PoolSlot {}
    static POOL: PoolSlot = PoolSlot(UnsafeCell::new(None));
    register_fork_handlers();
    let _guard = MAP_LOCK.lock();
    // SAFETY: the lock is held, so no other reference to the cell exists.
    let slot = unsafe { &mut *POOL.0.get() };
    match slot {
        Some(w) if w.in_own_process() => Ok(w.clone()),
        _ => {
            let w = WorkerPool::new(thread_count(env_threads())?, "so3fft-soft")?;
            // A parent's pool is left to the orphan list by its drop (no waiting).
            *slot = Some(w.clone());
            Ok(w)
        }
    }
}

/// The cached SO(3) plan of bandwidth `b`, created on first use.
pub(super) fn plan_for(b: usize) -> SoftResult<Arc<Plan>> {
    cached(&SO3_PLANS, b, || {
        Plan::new_on(b, cache_options(), Some(&layer_workers()?))
    })
}

/// The cached SO(3) plan of bandwidth `b` if it exists already (for work that can use its
/// worker threads but should not make a plan).
pub(super) fn made_plan(b: usize) -> Option<Arc<Plan>> {
    register_fork_handlers();
    SO3_PLANS.made(b)
}

/// Options of the cached S^2 plans (threads and rigour as for the SO(3) plans).
pub(super) fn s2_options() -> Options {
    Options {
        threads: env_threads(),
        rigor: env_rigor(),
        ..Options::default()
    }
}
