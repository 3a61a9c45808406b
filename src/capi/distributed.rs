//! Distributed plans for libso3fft_mpi: private C entry points `so3fft_dist_*` that take the
//! group of processes as a table of C callbacks ([`so3fft_dist_exchange`]), so libso3fft
//! itself never links MPI. libso3fft_mpi (`src/distributed/so3fft_mpi.c`, built by CMake with
//! MPI) fills the table with MPI calls and defines the public `so3fft_mpi_*` functions of
//! `include/so3fft_mpi.h` as forwarders to these. None is in `so3fft.h` (every item carries
//! `cbindgen:ignore`); the C declarations are in `so3fft_mpi.c`, which must match.
//!
//! Planners and executes are collective: a rank whose arguments are bad still takes part, so
//! that every rank returns the same error and none waits.

use super::partial::{checked_shape, options_of, so3fft_partial_options, so3fft_shape};
use super::{guarded, guarded_code, guarded_count, so3fft_complex};
use crate::distributed::{DistributedPlan, Exchange};
use crate::error::Error;
use crate::ffi::{CallError, ErrorKind};
use crate::options::Betas;
use crate::Complex64;
use std::ffi::{c_int, c_uint, c_void};

/// The group of processes of a distributed plan, as C callbacks. Every callback is collective
/// and returns 0 or the transport's error code; `context` is passed back to each.
///
/// cbindgen:ignore
#[repr(C)]
#[derive(Clone, Copy)]
pub struct so3fft_dist_exchange {
    /// The caller's handle of the group (libso3fft_mpi: the communicator's Fortran handle).
    pub context: *mut c_void,
    /// Writes this process's rank and the number of ranks; [`GROUP_NOT_READY`] if the
    /// transport is not initialised.
    pub group: Option<unsafe extern "C" fn(*mut c_void, *mut c_int, *mut c_int) -> c_int>,
    /// Sends `ns` doubles to rank `dest` while receiving `nr` from rank `src`.
    pub sendrecv: Option<
        unsafe extern "C" fn(
            *mut c_void,
            *const f64,
            usize,
            c_int,
            *mut f64,
            usize,
            c_int,
        ) -> c_int,
    >,
    /// Replaces `*value` by the largest of the ranks' values.
    pub max_u64: Option<unsafe extern "C" fn(*mut c_void, *mut u64) -> c_int>,
}

/// What `group` returns when the transport (MPI) is not initialised.
const GROUP_NOT_READY: c_int = -1;

/// An [`Exchange`] over a caller's callbacks.
pub(crate) struct CallbackExchange {
    table: so3fft_dist_exchange,
    rank: usize,
    size: usize,
}

fn transport_error(what: &str, code: c_int) -> Error {
    Error::Resources(format!("MPI: {what} failed with error code {code}"))
}

impl CallbackExchange {
    /// Copies the caller's table and asks it for the group.
    ///
    /// # Safety
    /// `table` is NULL or a valid table whose callbacks may be called with its context for as
    /// long as the exchange lives.
    unsafe fn new(table: *const so3fft_dist_exchange) -> crate::error::Result<CallbackExchange> {
        // SAFETY: the function's contract.
        let t = unsafe { table.as_ref() }
            .ok_or_else(|| Error::InvalidArgument("the exchange table is NULL".into()))?;
        let (Some(group), Some(_), Some(_)) = (t.group, t.sendrecv, t.max_u64) else {
            return Err(Error::InvalidArgument(
                "the exchange table has a NULL callback".into(),
            ));
        };
        let (mut rank, mut size) = (0, 0);
        // SAFETY: the table's callbacks are callable with its context; the out-pointers are
        // valid.
        let e = unsafe { group(t.context, &mut rank, &mut size) };
        if e == GROUP_NOT_READY {
            return Err(Error::InvalidArgument(
                "MPI is not initialised (or already finalised)".into(),
            ));
        }
        if e != 0 {
            return Err(transport_error("MPI_Comm_rank or MPI_Comm_size", e));
        }
        if size < 1 || rank < 0 || rank >= size {
            return Err(Error::InvalidArgument(format!(
                "the group reports rank {rank} of {size}"
            )));
        }
        Ok(CallbackExchange {
            table: *t,
            rank: rank as usize,
            size: size as usize,
        })
    }
}

// SAFETY: the table is a context pointer and C functions; the plan calls them only from the
// thread that executes it (MPI_THREAD_SERIALIZED), never from its workers.
unsafe impl Sync for CallbackExchange {}

impl Exchange for CallbackExchange {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.size
    }

    fn sendrecv(
        &self,
        send: &[f64],
        dest: usize,
        recv: &mut [f64],
        src: usize,
    ) -> crate::error::Result<()> {
        let f = self.table.sendrecv.expect("checked at construction");
        // SAFETY: `send` and `recv` are valid for their lengths during the call; the callback
        // is callable with the context (construction's contract).
        let e = unsafe {
            f(
                self.table.context,
                send.as_ptr(),
                send.len(),
                dest as c_int,
                recv.as_mut_ptr(),
                recv.len(),
                src as c_int,
            )
        };
        if e != 0 {
            return Err(transport_error("MPI_Sendrecv", e));
        }
        Ok(())
    }

    fn max(&self, value: u64) -> crate::error::Result<u64> {
        let f = self.table.max_u64.expect("checked at construction");
        let mut v = value;
        // SAFETY: `v` is a valid in/out value; the callback is callable with the context.
        let e = unsafe { f(self.table.context, &mut v) };
        if e != 0 {
            return Err(transport_error("MPI_Allreduce", e));
        }
        Ok(v)
    }
}

/// Opaque distributed plan object.
///
/// cbindgen:ignore
pub struct so3fft_dist_plan_s {
    plan: DistributedPlan<CallbackExchange>,
}

/// A distributed plan: a pointer to an opaque object.
///
/// cbindgen:ignore
pub type so3fft_dist_plan = *mut so3fft_dist_plan_s;

/// Plans the transforms of `shape` over the group of `exchange` (collective). The table is
/// copied; its context must stay valid until the plan is destroyed.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_plan_partial(
    shape: *const so3fft_shape,
    options: *const so3fft_partial_options,
    flags: c_uint,
    exchange: *const so3fft_dist_exchange,
) -> so3fft_dist_plan {
    guarded(std::ptr::null_mut(), || {
        // SAFETY: the API's contract (NULL or a valid table, usable for the plan's life).
        let comm = unsafe { CallbackExchange::new(exchange) }?;
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
        Ok(Box::into_raw(Box::new(so3fft_dist_plan_s { plan })))
    })
}

/// Destroys a distributed plan (not collective); NULL is a no-op.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_destroy_plan(p: so3fft_dist_plan) {
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
unsafe fn plan_ref<'a>(
    p: so3fft_dist_plan,
) -> Result<&'a DistributedPlan<CallbackExchange>, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract), only read.
    unsafe { p.as_ref() }
        .map(|s| &s.plan)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the distributed plan is NULL"))
}

/// This rank's lane pairs `j0 .. j1`: it holds the beta slices `j0 .. j1`, then
/// `2 B_grid - j1 .. 2 B_grid - j0`.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_local_pairs(
    p: so3fft_dist_plan,
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
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_local_num_samples(p: so3fft_dist_plan) -> isize {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.local_num_samples() as isize))
}

/// Coefficients this rank holds.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_local_num_coeffs(p: so3fft_dist_plan) -> isize {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.local_num_coeffs() as isize))
}

/// Bytes this rank's transforms hold besides its arrays (the lane-row buffers, allocated
/// at the first transform and kept until destroy).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_local_workspace(p: so3fft_dist_plan) -> isize {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.local_workspace_bytes() as isize))
}

/// Groups of pairs a transform runs in (1: results bitwise those of one process).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_groups(p: so3fft_dist_plan) -> c_int {
    // SAFETY: the API's contract.
    guarded_count(|| Ok(unsafe { plan_ref(p) }?.groups() as isize)) as c_int
}

/// Where `fhat(l, m, mp)` is: its index in the coefficients of rank `*rank` (written when
/// `rank` is not NULL); `SO3FFT_EINVAL` if the shape does not hold it.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_coef_owner(
    p: so3fft_dist_plan,
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
    p: so3fft_dist_plan,
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
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_forward(
    p: so3fft_dist_plan,
    samples: *mut so3fft_complex,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe { execute(p, Op::Forward, samples.cast_const().cast(), coeffs.cast()) })
}

/// Inverse (collective): this rank's coefficients to this rank's samples.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_inverse(
    p: so3fft_dist_plan,
    coeffs: *mut so3fft_complex,
    samples: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe { execute(p, Op::Inverse, coeffs.cast_const().cast(), samples.cast()) })
}

/// Forward of real samples (collective; plan made with `SO3FFT_REAL`).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_forward_real(
    p: so3fft_dist_plan,
    samples: *const f64,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the API's contract.
    guarded_code(|| unsafe { execute(p, Op::ForwardReal, samples.cast(), coeffs.cast()) })
}

/// Inverse to real samples (collective; plan made with `SO3FFT_REAL`).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3fft_dist_inverse_real(
    p: so3fft_dist_plan,
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

#[cfg(test)]
mod tests {
    use super::super::errors::{so3fft_last_error, so3fft_last_error_code};
    use super::super::partial::so3fft_shape_default;
    use super::super::{SO3FFT_EINVAL, SO3FFT_ESTIMATE, SO3FFT_OK};
    use super::*;
    use crate::distributed::ThreadExchange;
    use std::ffi::CStr;

    /// The table's context is a `ThreadExchange`: the callbacks a C transport would give.
    fn member(context: *mut c_void) -> &'static ThreadExchange {
        // SAFETY: every test table's context is a `ThreadExchange` that outlives its plan.
        unsafe { &*context.cast::<ThreadExchange>() }
    }

    unsafe extern "C" fn group(context: *mut c_void, rank: *mut c_int, size: *mut c_int) -> c_int {
        let x = member(context);
        // SAFETY: the library passes valid out-pointers.
        unsafe {
            *rank = x.rank() as c_int;
            *size = x.size() as c_int;
        }
        0
    }

    unsafe extern "C" fn sendrecv(
        context: *mut c_void,
        send: *const f64,
        ns: usize,
        dest: c_int,
        recv: *mut f64,
        nr: usize,
        src: c_int,
    ) -> c_int {
        // SAFETY: the library passes arrays valid for these lengths during the call.
        let (send, recv) = unsafe {
            (
                std::slice::from_raw_parts(send, ns),
                std::slice::from_raw_parts_mut(recv, nr),
            )
        };
        let r = member(context).sendrecv(send, dest as usize, recv, src as usize);
        if r.is_ok() {
            0
        } else {
            17
        }
    }

    unsafe extern "C" fn max_u64(context: *mut c_void, value: *mut u64) -> c_int {
        // SAFETY: the library passes a valid in/out value.
        match member(context).max(unsafe { *value }) {
            Ok(m) => {
                // SAFETY: as above.
                unsafe { *value = m };
                0
            }
            Err(_) => 17,
        }
    }

    unsafe extern "C" fn not_ready(_: *mut c_void, _: *mut c_int, _: *mut c_int) -> c_int {
        GROUP_NOT_READY
    }

    fn table(context: &ThreadExchange) -> so3fft_dist_exchange {
        so3fft_dist_exchange {
            context: (context as *const ThreadExchange).cast_mut().cast(),
            group: Some(group),
            sendrecv: Some(sendrecv),
            max_u64: Some(max_u64),
        }
    }

    fn last_error() -> String {
        // SAFETY: the library's error message is a NUL-terminated string.
        unsafe { CStr::from_ptr(so3fft_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    /// A NULL table, a NULL callback and a transport that is not initialised are errors with
    /// a message, never a call through a NULL pointer.
    #[test]
    fn bad_tables_are_errors() {
        let shape = so3fft_shape_default(4);
        let one = ThreadExchange::group(1).pop().unwrap();
        let mut t = table(&one);
        t.max_u64 = None;
        let not_initialised = so3fft_dist_exchange {
            group: Some(not_ready),
            ..table(&one)
        };
        for (exchange, says) in [
            (std::ptr::null(), "NULL"),
            (&t as *const _, "NULL callback"),
            (&not_initialised as *const _, "MPI is not initialised"),
        ] {
            // SAFETY: NULL or valid tables whose context outlives the call.
            let p = unsafe {
                so3fft_dist_plan_partial(&shape, std::ptr::null(), SO3FFT_ESTIMATE, exchange)
            };
            assert!(p.is_null());
            assert_eq!(so3fft_last_error_code(), SO3FFT_EINVAL);
            assert!(last_error().contains(says), "{}", last_error());
        }
    }

    /// Two members in two threads, through the callbacks: the inverse then the forward gives
    /// each rank's coefficients back (the quadrature is exact for band-limited data).
    #[test]
    fn round_trip_through_callbacks() {
        let shape = so3fft_shape_default(6);
        let members = ThreadExchange::group(2);
        std::thread::scope(|scope| {
            for m in &members {
                scope.spawn(move || {
                    let t = table(m);
                    // SAFETY: a valid table whose context outlives the plan.
                    let p = unsafe {
                        so3fft_dist_plan_partial(&shape, std::ptr::null(), SO3FFT_ESTIMATE, &t)
                    };
                    assert!(!p.is_null(), "{}", last_error());
                    // SAFETY: a live plan.
                    let (nc, ns) = unsafe {
                        (
                            so3fft_dist_local_num_coeffs(p) as usize,
                            so3fft_dist_local_num_samples(p) as usize,
                        )
                    };
                    let c: Vec<so3fft_complex> = (0..nc)
                        .map(|i| {
                            let x = (i + 100 * m.rank()) as f64;
                            [(0.7 * x).sin(), (1.3 * x).cos()]
                        })
                        .collect();
                    let mut s = vec![[0.0; 2]; ns];
                    let mut back = vec![[0.0; 2]; nc];
                    // SAFETY: arrays of the plan's local sizes.
                    unsafe {
                        assert_eq!(
                            so3fft_dist_inverse(p, c.as_ptr().cast_mut(), s.as_mut_ptr()),
                            SO3FFT_OK
                        );
                        assert_eq!(
                            so3fft_dist_forward(p, s.as_mut_ptr(), back.as_mut_ptr()),
                            SO3FFT_OK
                        );
                        so3fft_dist_destroy_plan(p);
                    }
                    let err = c
                        .iter()
                        .zip(&back)
                        .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
                        .fold(0.0, f64::max);
                    assert!(err < 1e-12, "rank {}: round trip error {err}", m.rank());
                });
            }
        });
    }
}
