//! The plan cache of the SOFT layer: one plan per bandwidth, made on first use and kept for
//! the life of the process, and the optional wisdom file (`SO3FFT_SOFT_WISDOM`).

use super::SoftResult;
use crate::ffi::CallError;
use crate::system::ForkLock;
use crate::{wisdom, Direction, FftThreading, Plan, PlanOptions, Rigor};
use std::cell::UnsafeCell;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, Once, OnceLock, PoisonError};

/// One slot per bandwidth; the slot's own lock serialises creation of that plan only.
type Slot = Arc<Mutex<Option<Arc<Plan>>>>;

/// The slots, keyed by process id and bandwidth: a child made by `fork()` never touches a
/// slot whose lock a thread of its parent held at the fork (it would wait forever).
struct Cache {
    lock: ForkLock,
    map: UnsafeCell<BTreeMap<(u32, usize), Slot>>,
}

// SAFETY: `map` is only accessed while `lock` is held (`Cache::slot`).
unsafe impl Sync for Cache {}

impl Cache {
    /// The slot of bandwidth `b` in this process, made empty on first use.
    fn slot(&self, b: usize) -> Slot {
        let _guard = self.lock.lock();
        // SAFETY: the lock is held, so no other reference to the map exists.
        let map = unsafe { &mut *self.map.get() };
        map.entry((std::process::id(), b)).or_default().clone()
    }
}

static CACHE: Cache = Cache {
    lock: ForkLock::new(),
    map: UnsafeCell::new(BTreeMap::new()),
};

/// Registers the cache lock's `fork()` handlers (once, before the first use).
fn register_fork_handlers() {
    static REGISTERED: Once = Once::new();
    REGISTERED.call_once(|| {
        extern "C" fn prepare() {
            CACHE.lock.before_fork();
        }
        extern "C" fn release() {
            CACHE.lock.after_fork();
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

/// Plan options of the cached plans (environment read once).
fn cache_options() -> &'static PlanOptions {
    static OPTS: OnceLock<PlanOptions> = OnceLock::new();
    OPTS.get_or_init(|| {
        let threads = std::env::var("SO3FFT_SOFT_THREADS")
            .ok()
            .and_then(|s| s.trim().parse::<usize>().ok())
            .unwrap_or(0);
        let rigor = match std::env::var("SO3FFT_SOFT_RIGOR")
            .unwrap_or_default()
            .trim()
            .to_ascii_lowercase()
            .as_str()
        {
            "estimate" => Rigor::Estimate,
            "patient" => Rigor::Patient,
            "exhaustive" => Rigor::Exhaustive,
            _ => Rigor::Measure,
        };
        PlanOptions {
            direction: Direction::Both,
            threads,
            rigor,
            // flag = 1 calls use the engine's real-signal path.
            real: true,
            // With a wisdom file the FFT plans are recorded, and the FFT stage's threading
            // is fixed rather than timed: planning is fast and results are reproducible.
            fft_threading: if wisdom_file().is_some() {
                FftThreading::SlicesAcrossWorkers
            } else {
                FftThreading::Auto
            },
            ..PlanOptions::default()
        }
    })
}

/// The cached plan of bandwidth `b`, created on first use. A failed creation is not cached.
pub(super) fn plan_for(b: usize) -> SoftResult<Arc<Plan>> {
    register_fork_handlers();
    let slot = CACHE.slot(b);
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
        Plan::new(b, cache_options())
            .map_err(|e| CallError::from(e).context(&format!("cannot plan bandwidth {b}")))?,
    );
    if let Some(path) = file {
        if let Err(e) = wisdom::export_to_file(path) {
            wisdom_warning("SO3FFT_SOFT_WISDOM", &e);
        }
    }
    *g = Some(Arc::clone(&p));
    Ok(p)
}
