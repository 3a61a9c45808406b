//! FFTW's global state: the planner lock, the one-time initialisation of FFTW's threads, and
//! owned FFTW plans (destroyed under the lock).

use fftw_sys as fftw;
use std::ffi::c_int;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard, Once};

/// Serialises every FFTW planner call (plan creation and destruction) of this crate.
static PLANNER_LOCK: Mutex<()> = Mutex::new(());
/// `fftw_make_planner_thread_safe()` is called once, before the first planner call.
static PLANNER_THREAD_SAFE: Once = Once::new();

/// The global lock around FFTW planner calls. The first call also makes FFTW's planner
/// thread-safe process-wide, so the host's own planner calls are serialised with ours.
pub(crate) fn planner_lock() -> MutexGuard<'static, ()> {
    PLANNER_THREAD_SAFE.call_once(|| {
        // SAFETY: takes no arguments; FFTW allows it at any time before or between planner
        // calls, and `call_once` makes it run once.
        unsafe { fftw::fftw_make_planner_thread_safe() }
    });
    PLANNER_LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// An FFTW plan owned by this crate, destroyed under the planner lock.
pub(crate) struct RawPlan(pub(crate) fftw::fftw_plan);

// SAFETY: FFTW plans may be executed from any thread and concurrently (new-array execute is
// thread-safe); creation and destruction hold the planner lock.
unsafe impl Send for RawPlan {}
// SAFETY: as for Send: shared references only execute the plan, which FFTW allows
// concurrently.
unsafe impl Sync for RawPlan {}

impl Drop for RawPlan {
    fn drop(&mut self) {
        let _lock = planner_lock();
        // SAFETY: the plan was made by FFTW, is owned by this value and destroyed once,
        // under the planner lock; no execution can be running (we hold it by value).
        unsafe { fftw::fftw_destroy_plan(self.0) }
    }
}

/// FFTW's current thread count for new plans. `fftw_planner_nthreads` exists from FFTW
/// 3.3.9 on and is looked up at run time, so the library still loads with 3.3.8 (where the
/// host's setting cannot be read and is taken to be FFTW's default, 1).
fn fftw_planner_nthreads() -> c_int {
    type PlannerNthreads = unsafe extern "C" fn() -> c_int;
    // SAFETY: dlsym with a NUL-terminated name; RTLD_DEFAULT searches the loaded objects.
    let sym = unsafe { libc::dlsym(libc::RTLD_DEFAULT, c"fftw_planner_nthreads".as_ptr()) };
    if sym.is_null() {
        return 1;
    }
    // SAFETY: the symbol, when present, is FFTW's `int fftw_planner_nthreads(void)`, which
    // only reads FFTW's planner setting (we hold the planner lock, see `with_nthreads`).
    unsafe { std::mem::transmute::<*mut libc::c_void, PlannerNthreads>(sym)() }
}

/// `fftw_init_threads()` is called once, the first time a threaded plan is asked for.
static THREADS_INIT: Once = Once::new();
/// `fftw_init_threads()` succeeded.
static THREADS_OK: AtomicBool = AtomicBool::new(false);
/// The process that initialised FFTW's threads: in a child made by `fork()` FFTW's worker
/// threads do not exist, and a threaded FFTW plan would wait for them forever, so plans
/// made there are single-threaded.
static THREADS_PID: AtomicU32 = AtomicU32::new(0);

/// Whether FFTW's own threads can be used in this process (initialising them on the first
/// call). Call with the planner lock held.
fn fftw_threads_usable(_lock: &MutexGuard<'static, ()>) -> bool {
    THREADS_INIT.call_once(|| {
        // SAFETY: called once per process, under the planner lock (no planner call runs).
        let ok = unsafe { fftw::fftw_init_threads() } != 0;
        THREADS_OK.store(ok, Ordering::Relaxed);
        THREADS_PID.store(std::process::id(), Ordering::Relaxed);
    });
    THREADS_OK.load(Ordering::Relaxed) && THREADS_PID.load(Ordering::Relaxed) == std::process::id()
}

/// Runs the FFTW planner call `plan` under the planner lock, with FFTW's thread count for
/// new plans set to `nthreads` when that is more than 1 and FFTW's threads are usable here;
/// the previous thread count is restored before the lock is released.
pub(crate) fn with_nthreads(
    nthreads: usize,
    plan: impl FnOnce() -> fftw::fftw_plan,
) -> fftw::fftw_plan {
    let lock = planner_lock();
    let threaded = nthreads > 1 && fftw_threads_usable(&lock);
    if !threaded {
        return plan();
    }
    let host = fftw_planner_nthreads();
    let count = c_int::try_from(nthreads).unwrap_or(c_int::MAX);
    // SAFETY: FFTW's threads are initialised (fftw_threads_usable); the setting is changed
    // under the planner lock and restored below, before the lock is released.
    unsafe { fftw::fftw_plan_with_nthreads(count) };
    let made = plan();
    // SAFETY: as above.
    unsafe { fftw::fftw_plan_with_nthreads(host) };
    made
}
