//! Distributed plans over MPI (feature `mpi`): the C entry points declared in the
//! hand-written `include/so3fft_mpi.h` (not in the generated `so3fft.h`). The planner taking
//! an `MPI_Comm` is in `src/distributed/mpi_shim.c`; it passes the communicator's Fortran handle
//! here. Planners and executes are collective: a rank whose arguments are bad still takes
//! part, so that every rank returns the same error and none waits.

use super::partial::{checked_shape, options_of, so3fft_partial_options, so3fft_shape};
use super::{guarded, guarded_code, guarded_count, so3fft_complex};
use crate::distributed::{DistributedPlan, MpiExchange};
use crate::ffi::{CallError, ErrorKind};
use crate::options::Betas;
use crate::Complex64;
use std::ffi::{c_int, c_uint};

/// Opaque distributed plan object.
pub struct so3fft_mpi_plan_s {
    plan: DistributedPlan<MpiExchange>,
}

/// A distributed plan: a pointer to an opaque object.
pub type so3fft_mpi_plan = *mut so3fft_mpi_plan_s;

/// `so3fft_mpi_plan_partial` with the communicator as its Fortran handle (collective).
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_plan_partial_fortran(
    shape: *const so3fft_shape,
    options: *const so3fft_partial_options,
    flags: c_uint,
    comm: c_int,
) -> so3fft_mpi_plan {
    guarded(std::ptr::null_mut(), || {
        let comm = MpiExchange::from_fortran_handle(comm)?;
        // SAFETY: the API's contract (NULL or valid shape and options).
        let args = unsafe { checked_shape(shape) }
            .and_then(|s| unsafe { options_of(options, flags) }.map(|o| (s, o)));
        let (s, o) = match args {
            Ok((_, o)) if o.betas != Betas::All => {
                DistributedPlan::refuse_collectively(&comm)?;
                return Err(CallError::invalid(
                    "a distributed plan evaluates every beta (nbetas must be 0)",
                ));
            }
            Ok(v) => v,
            Err(e) => {
                DistributedPlan::refuse_collectively(&comm)?;
                return Err(e);
            }
        };
        let plan = DistributedPlan::new(comm, &s, &o)?;
        Ok(Box::into_raw(Box::new(so3fft_mpi_plan_s { plan })))
    })
}

/// Destroys a distributed plan (not collective); NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_destroy_plan(p: so3fft_mpi_plan) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw in the planner and is destroyed
            // once, while no other thread uses it (the caller's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

/// The plan behind a handle; an error for NULL.
///
/// # Safety
/// `p` is NULL or a live distributed plan.
unsafe fn plan_ref<'a>(p: so3fft_mpi_plan) -> Result<&'a DistributedPlan<MpiExchange>, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract), only read.
    unsafe { p.as_ref() }
        .map(|s| &s.plan)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the distributed plan is NULL"))
}

/// This rank's lane pairs `j0 .. j1`: it holds the beta slices `j0 .. j1`, then
/// `2 B_grid - j1 .. 2 B_grid - j0`.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_local_pairs(
    p: so3fft_mpi_plan,
    j0: *mut c_int,
    j1: *mut c_int,
) -> c_int {
    guarded_code(|| {
        // SAFETY: the API's contract.
        let (a, b) = unsafe { plan_ref(p) }?.local_pairs();
        // SAFETY: non-NULL out-pointers are valid for a write (the API's contract).
        unsafe {
            if let Some(x) = j0.as_mut() {
                *x = a as c_int;
            }
            if let Some(x) = j1.as_mut() {
                *x = b as c_int;
            }
        }
        Ok(())
    })
}

/// Samples this rank holds.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_local_num_samples(p: so3fft_mpi_plan) -> isize {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.local_num_samples() as isize))
}

/// Coefficients this rank holds.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_local_num_coeffs(p: so3fft_mpi_plan) -> isize {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.local_num_coeffs() as isize))
}

/// Bytes this rank's transforms hold besides its arrays (the lane-row buffers, allocated
/// at the first transform and kept until destroy).
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_local_workspace(p: so3fft_mpi_plan) -> isize {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.local_workspace_bytes() as isize))
}

/// Groups of pairs a transform runs in (1: results bitwise those of one process).
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_groups(p: so3fft_mpi_plan) -> c_int {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.groups() as isize)) as c_int
}

/// Where `fhat(l, m, mp)` is: its index in the coefficients of rank `*rank` (written when
/// `rank` is not NULL); `SO3FFT_EINVAL` if the shape does not hold it.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_coef_owner(
    p: so3fft_mpi_plan,
    l: c_int,
    m: c_int,
    mp: c_int,
    rank: *mut c_int,
) -> isize {
    guarded_count(|| {
        // SAFETY: the API's contract.
        let plan = unsafe { plan_ref(p) }?;
        let (r, at) = usize::try_from(l)
            .ok()
            .and_then(|l| plan.coef_owner(l, m as isize, mp as isize))
            .ok_or_else(|| {
                CallError::invalid(format!(
                    "the shape holds no coefficient (l={l}, m={m}, mp={mp})"
                ))
            })?;
        // SAFETY: a non-NULL `rank` is valid for a write (the API's contract).
        if let Some(x) = unsafe { rank.as_mut() } {
            *x = r as c_int;
        }
        Ok(at as isize)
    })
}

/// A caller's array as a slice of `len` values, or an empty one when NULL or misaligned
/// (the plan then fails its collective length check on every rank).
///
/// # Safety
/// A non-NULL, aligned `ptr` is valid for `len` values (the API's contract).
unsafe fn slice_or_empty<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if ptr.is_null() || !(ptr as usize).is_multiple_of(std::mem::align_of::<T>()) {
        return &[];
    }
    // SAFETY: the function's contract.
    unsafe { std::slice::from_raw_parts(ptr, len) }
}

/// [`slice_or_empty`] for an output array.
///
/// # Safety
/// As for [`slice_or_empty`], valid for writes and not accessed by others meanwhile.
unsafe fn slice_or_empty_mut<'a, T>(ptr: *mut T, len: usize) -> &'a mut [T] {
    if ptr.is_null() || !(ptr as usize).is_multiple_of(std::mem::align_of::<T>()) {
        return &mut [];
    }
    // SAFETY: the function's contract.
    unsafe { std::slice::from_raw_parts_mut(ptr, len) }
}

/// Which transform an execute runs.
#[derive(Clone, Copy)]
enum Op {
    Forward,
    Inverse,
    ForwardReal,
    InverseReal,
}

/// Runs one collective execute.
///
/// # Safety
/// The API's contract: non-NULL arrays hold the rank's local sizes.
unsafe fn execute(
    p: so3fft_mpi_plan,
    op: Op,
    inp: *const u8,
    out: *mut u8,
) -> Result<(), CallError> {
    // SAFETY: the API's contract.
    let plan = unsafe { plan_ref(p) }?;
    let (ns, nc) = (plan.local_num_samples(), plan.local_num_coeffs());
    // SAFETY: the arrays hold the local sizes (the API's contract); so3fft_complex is
    // `double[2]`, the layout of Complex64.
    unsafe {
        match op {
            Op::Forward => plan.forward(
                slice_or_empty(inp.cast::<Complex64>(), ns),
                slice_or_empty_mut(out.cast::<Complex64>(), nc),
            ),
            Op::Inverse => plan.inverse(
                slice_or_empty(inp.cast::<Complex64>(), nc),
                slice_or_empty_mut(out.cast::<Complex64>(), ns),
            ),
            Op::ForwardReal => plan.forward_real(
                slice_or_empty(inp.cast::<f64>(), ns),
                slice_or_empty_mut(out.cast::<Complex64>(), nc),
            ),
            Op::InverseReal => plan.inverse_real(
                slice_or_empty(inp.cast::<Complex64>(), nc),
                slice_or_empty_mut(out.cast::<f64>(), ns),
            ),
        }
    }
    .map(|_| ())
    .map_err(CallError::from)
}

/// Forward (collective): this rank's samples to this rank's coefficients.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_forward(
    p: so3fft_mpi_plan,
    samples: *mut so3fft_complex,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe { execute(p, Op::Forward, samples.cast_const().cast(), coeffs.cast()) })
}

/// Inverse (collective): this rank's coefficients to this rank's samples.
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_inverse(
    p: so3fft_mpi_plan,
    coeffs: *mut so3fft_complex,
    samples: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe { execute(p, Op::Inverse, coeffs.cast_const().cast(), samples.cast()) })
}

/// Forward of real samples (collective; plan made with `SO3FFT_REAL`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_forward_real(
    p: so3fft_mpi_plan,
    samples: *const f64,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe { execute(p, Op::ForwardReal, samples.cast(), coeffs.cast()) })
}

/// Inverse to real samples (collective; plan made with `SO3FFT_REAL`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_mpi_inverse_real(
    p: so3fft_mpi_plan,
    coeffs: *mut so3fft_complex,
    samples: *mut f64,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe {
        execute(
            p,
            Op::InverseReal,
            coeffs.cast_const().cast(),
            samples.cast(),
        )
    })
}
