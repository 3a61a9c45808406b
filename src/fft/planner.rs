//! FFTW's global state: the planner lock and owned FFTW plans (destroyed under the lock).
//!
//! When the library is loaded (before `main`, or at `dlopen`), FFTW's planner is made
//! thread-safe process-wide and the planner lock's `fork()` handlers are registered: a host
//! thread that is already planning with FFTW when so3fft plans for the first time would
//! otherwise run its planner call unlocked. (Where the loader runs no constructors, the
//! first planner call does the same.)

use crate::error::{Error, Result};
use crate::system::{check_headroom, ForkLock, ForkLockGuard};
use fftw_sys as fftw;
use std::ffi::c_int;
use std::sync::Once;

/// Serialises every FFTW planner call (plan creation and destruction, wisdom) of this
/// crate; free in a child made by `fork()`.
static PLANNER_LOCK: ForkLock = ForkLock::new();
/// The process-wide set-up below runs once.
static SETUP: Once = Once::new();

/// Makes FFTW's planner thread-safe and registers the planner lock's `fork()` handlers.
fn setup() {
    SETUP.call_once(|| {
        // SAFETY: takes no arguments; FFTW allows it at any time before or between planner
        // calls (it installs the planner's lock hooks).
        unsafe { fftw::fftw_make_planner_thread_safe() };
        extern "C" fn prepare() {
            PLANNER_LOCK.before_fork();
        }
        extern "C" fn release() {
            PLANNER_LOCK.after_fork();
        }
        // SAFETY: the handlers are plain functions that live as long as the process. If
        // registration fails (ENOMEM), forking while planning stays unsafe, as without it.
        unsafe { libc::pthread_atfork(Some(prepare), Some(release), Some(release)) };
    });
}

/// Runs [`setup`] when the library is loaded, so no host planner call can be in flight
/// while FFTW's planner hooks are installed.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static SETUP_AT_LOAD: extern "C" fn() = {
    extern "C" fn at_load() {
        setup();
    }
    at_load
};

/// The global lock around FFTW planner calls (see the module documentation).
pub(crate) fn planner_lock() -> ForkLockGuard<'static> {
    setup();
    PLANNER_LOCK.lock()
}

/// Bytes FFTW's planner may allocate for a plan of `elements` complex values: 2 MiB plus
/// 32 bytes per element (plans, twiddles, buffers).
pub(crate) fn planning_bytes(elements: usize) -> usize {
    (2usize << 20).saturating_add(elements.saturating_mul(32))
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
    // only reads FFTW's planner setting (we hold the planner lock, see `plan_guarded`).
    unsafe { std::mem::transmute::<*mut libc::c_void, PlannerNthreads>(sym)() }
}

/// Runs the FFTW planner call `plan` for a transform of `elements` values under the
/// planner lock, as a single-threaded plan (the plans run inside the library's own
/// workers): where the host has set FFTW's thread count for new plans above 1, it is set
/// to 1 for this call and restored before the lock is released. FFTW aborts the process
/// when an allocation fails inside its planner, so the call is not made without
/// [`planning_bytes`] of headroom ([`Error::OutOfMemory`]); a null plan is
/// [`Error::Fftw`].
pub(crate) fn plan_guarded(
    elements: usize,
    plan: impl FnOnce() -> fftw::fftw_plan,
) -> Result<RawPlan> {
    let lock = planner_lock();
    check_headroom(planning_bytes(elements))?;
    let host = fftw_planner_nthreads();
    let made = if host > 1 {
        // SAFETY: a count above 1 means the host initialised FFTW's threads; the setting
        // is changed under the planner lock and restored below, before it is released.
        unsafe { fftw::fftw_plan_with_nthreads(1) };
        let made = plan();
        // SAFETY: as above.
        unsafe { fftw::fftw_plan_with_nthreads(host) };
        made
    } else {
        plan()
    };
    drop(lock);
    if made.is_null() {
        return Err(Error::Fftw(format!(
            "could not plan a DFT of {elements} values"
        )));
    }
    Ok(RawPlan(made))
}
