//! FFTW's global state: the planner lock and owned FFTW plans (destroyed under the lock), for
//! both FFTW libraries (`fftw_*` for f64 and `fftwf_*` for f32, see [`FftwApi`]).
//!
//! When the library is loaded (before `main`, or at `dlopen`), the planners of both FFTW
//! libraries are made thread-safe process-wide and the planner lock's `fork()` handlers are
//! registered: a host thread that is already planning with FFTW when so3fft plans for the
//! first time would otherwise run its planner call unlocked. (Where the loader runs no
//! constructors, the first planner call does the same.)
//!
//! One lock serves both libraries: they are separate FFTW instances, but one lock keeps the
//! rules simple (a planner call of either precision holds it) and costs nothing, as
//! planning is rare.

use super::api::FftwApi;
use crate::error::{Error, Result};
use crate::system::{check_headroom, ForkLock, ForkLockGuard};
use std::ffi::c_int;
use std::sync::Once;

/// Serialises every FFTW planner call (plan creation and destruction, wisdom) of this
/// crate; free in a child made by `fork()`.
static PLANNER_LOCK: ForkLock = ForkLock::new();
/// The process-wide set-up below runs once.
static SETUP: Once = Once::new();

/// Makes the planners of both FFTW libraries thread-safe and registers the planner lock's
/// `fork()` handlers.
fn setup() {
    SETUP.call_once(|| {
        // SAFETY: they take no arguments; FFTW allows them at any time before or between
        // planner calls (they install each planner's lock hooks).
        unsafe {
            f64::make_planner_thread_safe();
            f32::make_planner_thread_safe();
        }
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

/// An FFTW plan of precision `T` (`fftw_plan` for f64, `fftwf_plan` for f32) owned by this
/// crate, destroyed under the planner lock.
pub(crate) struct RawPlan<T: FftwApi = f64>(pub(crate) *mut T::PlanS);

// SAFETY: FFTW plans may be executed from any thread and concurrently (new-array execute is
// thread-safe); creation and destruction hold the planner lock.
unsafe impl<T: FftwApi> Send for RawPlan<T> {}
// SAFETY: as for Send: shared references only execute the plan, which FFTW allows
// concurrently.
unsafe impl<T: FftwApi> Sync for RawPlan<T> {}

impl<T: FftwApi> Drop for RawPlan<T> {
    fn drop(&mut self) {
        let _lock = planner_lock();
        // SAFETY: the plan was made by this FFTW library (`T`'s, the type says so), is owned
        // by this value and destroyed once, under the planner lock; no execution can be
        // running (we hold it by value).
        unsafe { T::destroy_plan(self.0) }
    }
}

/// FFTW's current thread count for new plans of precision `T`. `fftw_planner_nthreads`
/// (and `fftwf_planner_nthreads`) exists from FFTW 3.3.9 on and is looked up at run time,
/// so the library still loads with 3.3.8 (where the host's setting cannot be read and is
/// taken to be FFTW's default, 1).
pub(super) fn planner_nthreads<T: FftwApi>() -> c_int {
    type PlannerNthreads = unsafe extern "C" fn() -> c_int;
    // SAFETY: dlsym with a NUL-terminated name; RTLD_DEFAULT searches the loaded objects.
    let sym = unsafe { libc::dlsym(libc::RTLD_DEFAULT, T::PLANNER_NTHREADS.as_ptr()) };
    if sym.is_null() {
        return 1;
    }
    // SAFETY: the symbol, when present, is FFTW's `int fftw_planner_nthreads(void)` (of
    // `T`'s library), which only reads FFTW's planner setting (we hold the planner lock,
    // see `plan_guarded`).
    unsafe { std::mem::transmute::<*mut libc::c_void, PlannerNthreads>(sym)() }
}

/// Runs the FFTW planner call `plan` (of `T`'s library) for a transform of `elements` values
/// under the planner lock, as a single-threaded plan (the plans run inside the library's own
/// workers): where the host has set that library's thread count for new plans above 1, it
/// is set to 1 for this call and restored before the lock is released. FFTW aborts the process
/// when an allocation fails inside its planner, so the call is not made without
/// [`planning_bytes`] of headroom ([`Error::OutOfMemory`]); a null plan is
/// [`Error::Fftw`].
pub(crate) fn plan_guarded<T: FftwApi>(
    elements: usize,
    plan: impl FnOnce() -> *mut T::PlanS,
) -> Result<RawPlan<T>> {
    let lock = planner_lock();
    check_headroom(planning_bytes(elements))?;
    let host = planner_nthreads::<T>();
    let made = if host > 1 {
        // SAFETY: a count above 1 means the host initialised this library's threads; the
        // setting is changed under the planner lock and restored below, before it is
        // released.
        unsafe { T::plan_with_nthreads(1) };
        let made = plan();
        // SAFETY: as above.
        unsafe { T::plan_with_nthreads(host) };
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
