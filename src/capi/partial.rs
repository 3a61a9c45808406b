//! Partial plans (guru interface): a shape, options, planner, execute, sizes and index.
//!
//! The shape, the options and their functions serve both precisions. The bodies of the
//! planner, destroy, sizes and executes are generic over the plan's handle
//! ([`PartialHandle`]), whose element type is the precision: the `so3fft_partial*` functions
//! here and the `so3fftf_partial*` ones of `single.rs` are one-line wrappers over them.

use super::{direction_of, guarded, guarded_code, guarded_count, rigor_of, threads_of};
use super::{so3fft_complex, SO3FFT_DESTROY_INPUT, SO3FFT_REAL};
use crate::ffi::checks::{input_output, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::options::{Betas, Direction, Options};
use crate::{Batch, PartialPlan, Shape};
use crate::{Complex, Real};
use std::ffi::{c_int, c_uint};

/// What a partial plan computes: degrees `L0 <= l < L`, orders `|m| <= m_max`,
/// `|mp| <= mp_max`, on `2 B_grid` betas x `n_alpha` alphas x `n_gamma` gammas.
/// `so3fft_shape_default(L)` gives the full transform on SOFT's grid.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct so3fft_shape {
    /// Degree limit: degrees `l < L`.
    pub L: c_int,
    /// Lowest degree.
    pub L0: c_int,
    /// Order limit of `m` (paired with alpha).
    pub m_max: c_int,
    /// Order limit of `mp` (paired with gamma).
    pub mp_max: c_int,
    /// Beta grid: `2 B_grid` points.
    pub B_grid: c_int,
    /// Alpha samples (`>= 2 m_max + 1`).
    pub n_alpha: c_int,
    /// Gamma samples (`>= 2 mp_max + 1`).
    pub n_gamma: c_int,
}

/// Options of a partial plan; all zero means: both directions, all cores, the default
/// workspace, every beta.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct so3fft_partial_options {
    /// `SO3FFT_FORWARD`, `SO3FFT_INVERSE`, `SO3FFT_BOTH` (0: both).
    pub direction: c_int,
    /// Worker threads (0: all cores).
    pub nthreads: c_int,
    /// Number of betas the inverse evaluates (0: every beta of the grid).
    pub nbetas: c_int,
    /// `nbetas` grid indices (or NULL).
    pub beta_indices: *const c_int,
    /// `nbetas` beta values in `[0, pi]` (or NULL; exactly one of the two is given).
    pub beta_values: *const f64,
    /// Cap on the chunk buffer in bytes (0: default).
    pub max_workspace: usize,
}

/// Opaque partial plan object.
pub struct so3fft_partial_s {
    plan: PartialPlan,
}

/// A partial plan: a pointer to an opaque object.
pub type so3fft_partial = *mut so3fft_partial_s;

/// The opaque object behind the partial plan handles of one precision (`so3fft_partial_s`,
/// `so3fftf_partial_s`): it owns a `PartialPlan` of its element type.
pub(super) trait PartialHandle: Sized + 'static {
    /// The element type of the plan (`f64` or `f32`).
    type T: Real;
    /// The object owning `plan`.
    fn wrap(plan: PartialPlan<Self::T>) -> Self;
    /// The plan it owns.
    fn plan(&self) -> &PartialPlan<Self::T>;
}

impl PartialHandle for so3fft_partial_s {
    type T = f64;
    fn wrap(plan: PartialPlan<f64>) -> Self {
        so3fft_partial_s { plan }
    }
    fn plan(&self) -> &PartialPlan<f64> {
        &self.plan
    }
}

/// The shape of a C shape (values checked for sign; `Shape::validate` does the rest).
fn shape_of(s: &so3fft_shape) -> Result<Shape, CallError> {
    let u = |v: c_int, what: &str| {
        usize::try_from(v)
            .map_err(|_| CallError::invalid(format!("shape: {what} = {v} is negative")))
    };
    Ok(Shape {
        degree_limit: u(s.L, "L")?,
        degree_min: u(s.L0, "L0")?,
        order_limit_alpha: u(s.m_max, "m_max")?,
        order_limit_gamma: u(s.mp_max, "mp_max")?,
        grid_bandwidth: u(s.B_grid, "B_grid")?,
        n_alpha: u(s.n_alpha, "n_alpha")?,
        n_gamma: u(s.n_gamma, "n_gamma")?,
    })
}

/// The shape behind a pointer, validated.
///
/// # Safety
/// `s` is NULL or points to a shape.
pub(super) unsafe fn checked_shape(s: *const so3fft_shape) -> Result<Shape, CallError> {
    // SAFETY: a non-NULL `s` points to a shape (the API's contract), only read.
    let s = unsafe { s.as_ref() }
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the shape is NULL"))?;
    let shape = shape_of(s)?;
    shape.validate()?;
    Ok(shape)
}

/// The full transform of bandwidth `L` on SOFT's grid (`2L x 2L x 2L`); a shape with
/// `L = 0` (rejected by the planner) for `L` outside `1..=SO3FFT_MAX_BANDWIDTH`.
#[no_mangle]
pub extern "C" fn so3fft_shape_default(L: c_int) -> so3fft_shape {
    guarded(
        so3fft_shape {
            L: 0,
            L0: 0,
            m_max: 0,
            mp_max: 0,
            B_grid: 0,
            n_alpha: 0,
            n_gamma: 0,
        },
        || {
            let l = crate::ffi::checks::bandwidth(L)?;
            let s = Shape::new(l);
            let c = |v: usize| v as c_int;
            Ok(so3fft_shape {
                L: c(s.degree_limit),
                L0: 0,
                m_max: c(s.order_limit_alpha),
                mp_max: c(s.order_limit_gamma),
                B_grid: c(s.grid_bandwidth),
                n_alpha: c(s.n_alpha),
                n_gamma: c(s.n_gamma),
            })
        },
    )
}

/// `SO3FFT_OK` if a plan of `direction` can be made for `shape` (the forward needs
/// `B_grid >= L`), else `SO3FFT_EINVAL` with the violated condition in the message.
#[no_mangle]
pub unsafe extern "C" fn so3fft_shape_check(shape: *const so3fft_shape, direction: c_int) -> c_int {
    guarded_code(|| {
        // SAFETY: the API's contract.
        let s = unsafe { checked_shape(shape) }?;
        if direction_of(direction)? != Direction::Inverse {
            s.check_forward()?;
        }
        Ok(())
    })
}

/// Number of coefficients of `shape` (a negative code if invalid).
#[no_mangle]
pub unsafe extern "C" fn so3fft_shape_num_coeffs(shape: *const so3fft_shape) -> isize {
    guarded_count(|| {
        // SAFETY: the API's contract.
        Ok(unsafe { checked_shape(shape) }?.num_coeffs() as isize)
    })
}

/// Number of samples of `shape` with every beta, `2 B_grid n_alpha n_gamma`.
#[no_mangle]
pub unsafe extern "C" fn so3fft_shape_num_samples(shape: *const so3fft_shape) -> isize {
    guarded_count(|| {
        // SAFETY: the API's contract.
        Ok(unsafe { checked_shape(shape) }?.num_samples() as isize)
    })
}

/// Index of `fhat(l, m, mp)` in the coefficients of `shape`; `SO3FFT_EINVAL` if the
/// shape does not hold it.
#[no_mangle]
pub unsafe extern "C" fn so3fft_shape_coef_index(
    shape: *const so3fft_shape,
    l: c_int,
    m: c_int,
    mp: c_int,
) -> isize {
    guarded_count(|| {
        // SAFETY: the API's contract.
        let s = unsafe { checked_shape(shape) }?;
        usize::try_from(l)
            .ok()
            .and_then(|l| s.coef_index(l, m as isize, mp as isize))
            .map(|i| i as isize)
            .ok_or_else(|| {
                CallError::invalid(format!(
                    "the shape holds no coefficient (l={l}, m={m}, mp={mp})"
                ))
            })
    })
}

/// An empty vector with room for `n` values, or an out-of-memory error (never an abort).
fn vec_for<T>(n: usize) -> Result<Vec<T>, CallError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        CallError::from(crate::Error::OutOfMemory {
            bytes: n.saturating_mul(std::mem::size_of::<T>()),
        })
    })?;
    Ok(v)
}

/// The Rust options of C options (`NULL`: defaults).
///
/// # Safety
/// `o` is NULL or points to options whose non-NULL beta array holds `nbetas` values.
pub(super) unsafe fn options_of(
    o: *const so3fft_partial_options,
    flags: c_uint,
) -> Result<Options, CallError> {
    if flags & SO3FFT_DESTROY_INPUT != 0 {
        return Err(CallError::invalid(
            "SO3FFT_DESTROY_INPUT: a partial plan never overwrites its input".to_string(),
        ));
    }
    let mut opts = Options {
        rigor: rigor_of(flags & !SO3FFT_REAL)?,
        real: flags & SO3FFT_REAL != 0,
        ..Options::default()
    };
    // SAFETY: the API's contract.
    let Some(o) = (unsafe { o.as_ref() }) else {
        return Ok(opts);
    };
    opts.direction = if o.direction == 0 {
        Direction::Both
    } else {
        direction_of(o.direction)?
    };
    opts.threads = threads_of(o.nthreads)?;
    if o.max_workspace > 0 {
        opts.max_workspace_bytes = Some(o.max_workspace);
    }
    let n = usize::try_from(o.nbetas)
        .map_err(|_| CallError::invalid(format!("nbetas = {} is negative", o.nbetas)))?;
    if n > 0 {
        opts.betas =
            match (o.beta_indices.is_null(), o.beta_values.is_null()) {
                (false, true) => {
                    Array::new(o.beta_indices, n, "beta_indices").check()?;
                    // SAFETY: non-NULL, aligned, `nbetas` values (the API's contract).
                    let ks = unsafe { std::slice::from_raw_parts(o.beta_indices, n) };
                    let mut v = vec_for(n)?;
                    for &k in ks {
                        v.push(usize::try_from(k).map_err(|_| {
                            CallError::invalid(format!("beta index {k} is negative"))
                        })?);
                    }
                    Betas::Indices(v)
                }
                (true, false) => {
                    Array::new(o.beta_values, n, "beta_values").check()?;
                    let mut v = vec_for(n)?;
                    // SAFETY: as above.
                    v.extend_from_slice(unsafe { std::slice::from_raw_parts(o.beta_values, n) });
                    Betas::Values(v)
                }
                _ => {
                    return Err(CallError::invalid(
                        "nbetas > 0 needs exactly one of beta_indices and beta_values".to_string(),
                    ))
                }
            };
    }
    Ok(opts)
}

/// The body of `so3fft_plan_partial` for the handle type `H`: a new plan, or NULL on error.
///
/// # Safety
/// `shape` is NULL or points to a shape; `options` is NULL or points to options whose
/// non-NULL beta array holds `nbetas` values (the API's contract).
pub(super) unsafe fn plan_partial<H: PartialHandle>(
    shape: *const so3fft_shape,
    options: *const so3fft_partial_options,
    flags: c_uint,
) -> *mut H {
    guarded(std::ptr::null_mut(), || {
        // SAFETY: this function's contract.
        let s = unsafe { checked_shape(shape) }?;
        // SAFETY: this function's contract.
        let o = unsafe { options_of(options, flags) }?;
        let plan = PartialPlan::<H::T>::new(&s, &o)?;
        Ok(Box::into_raw(Box::new(H::wrap(plan))))
    })
}

/// The body of `so3fft_destroy_partial` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a plan made by [`plan_partial`] with the same `H`, not destroyed yet and
/// used by no other thread.
pub(super) unsafe fn destroy_partial<H: PartialHandle>(p: *mut H) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw of a `Box<H>` in
            // `plan_partial` and is destroyed once, while no other thread uses it (this
            // function's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

/// Plans the transforms of `shape` with `options` (NULL: defaults); `flags` a planner
/// rigour, `| SO3FFT_REAL` for the real-signal executes too. A beta selection makes an
/// inverse-only plan. NULL on error.
#[no_mangle]
pub unsafe extern "C" fn so3fft_plan_partial(
    shape: *const so3fft_shape,
    options: *const so3fft_partial_options,
    flags: c_uint,
) -> so3fft_partial {
    // SAFETY: the API's contract.
    unsafe { plan_partial(shape, options, flags) }
}

/// Destroys a partial plan; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fft_destroy_partial(p: so3fft_partial) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_partial(p) }
}

/// The plan behind a handle; an error for NULL.
///
/// # Safety
/// `p` is NULL or a live partial plan, not destroyed during the reference's use.
unsafe fn partial_ref<'a, H: PartialHandle>(p: *mut H) -> Result<&'a PartialPlan<H::T>, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract), only read.
    unsafe { p.as_ref() }
        .map(H::plan)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the partial plan is NULL"))
}

/// The body of `so3fft_partial_num_coeffs` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`.
pub(super) unsafe fn partial_num_coeffs<H: PartialHandle>(p: *mut H) -> isize {
    // SAFETY: this function's contract.
    guarded_count(|| Ok(unsafe { partial_ref(p) }?.num_coeffs() as isize))
}

/// The body of `so3fft_partial_num_samples` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`.
pub(super) unsafe fn partial_num_samples<H: PartialHandle>(p: *mut H) -> isize {
    // SAFETY: this function's contract.
    guarded_count(|| Ok(unsafe { partial_ref(p) }?.num_samples() as isize))
}

/// Coefficients of one transform of the plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_num_coeffs(p: so3fft_partial) -> isize {
    // SAFETY: the API's contract.
    unsafe { partial_num_coeffs(p) }
}

/// Samples of one transform of the plan (`n_alpha n_gamma` per beta evaluated).
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_num_samples(p: so3fft_partial) -> isize {
    // SAFETY: the API's contract.
    unsafe { partial_num_samples(p) }
}

/// The batch of a `_many` call: `howmany > 0`, distances `>= 0`.
fn batch_of(howmany: c_int, idist: isize, odist: isize) -> Result<Batch, CallError> {
    let count = usize::try_from(howmany)
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| CallError::invalid(format!("howmany = {howmany}: must be positive")))?;
    let d = |v: isize, what: &str| {
        usize::try_from(v).map_err(|_| CallError::invalid(format!("{what} = {v} is negative")))
    };
    Ok(Batch {
        count,
        in_dist: d(idist, "idist")?,
        out_dist: d(odist, "odist")?,
    })
}

/// Extent of a batch's array: `(count - 1) dist + len` values.
fn extent(b: &Batch, dist: usize, len: usize) -> Result<usize, CallError> {
    dist.checked_mul(b.count - 1)
        .and_then(|x| x.checked_add(len))
        .ok_or_else(|| CallError::invalid("batch extent overflows".to_string()))
}

/// Which transform a `_many` call runs.
#[derive(Clone, Copy, PartialEq)]
enum Op {
    Forward,
    Inverse,
    ForwardReal,
    InverseReal,
}

/// Checks and runs one `_many` call of the plan `p` (element type `H::T`); `inp` and `out`
/// point to the first value (`T`, the real part of the first complex value).
///
/// # Safety
/// The API's contract: `p` is NULL or a live plan of type `H`; non-NULL arrays hold the
/// batch's extents.
unsafe fn run_many<H: PartialHandle>(
    p: *mut H,
    op: Op,
    (howmany, idist, odist): (c_int, isize, isize),
    inp: *const H::T,
    out: *mut H::T,
) -> Result<(), CallError> {
    // SAFETY: the API's contract.
    let plan = unsafe { partial_ref(p) }?;
    let b = batch_of(howmany, idist, odist)?;
    let (nc, ns) = (plan.num_coeffs(), plan.num_samples());
    let (ilen, olen) = match op {
        Op::Forward | Op::ForwardReal => (extent(&b, b.in_dist, ns)?, extent(&b, b.out_dist, nc)?),
        _ => (extent(&b, b.in_dist, nc)?, extent(&b, b.out_dist, ns)?),
    };
    let (iname, oname) = match op {
        Op::Forward | Op::ForwardReal => ("samples", "coefficients"),
        _ => ("coefficients", "samples"),
    };
    // The arrays are checked as values of T (its alignment): two per complex element.
    let values = |len: usize, complex: bool| {
        if !complex {
            return Ok(len);
        }
        len.checked_mul(2)
            .ok_or_else(|| CallError::invalid("batch extent overflows".to_string()))
    };
    let ivals = values(ilen, op != Op::ForwardReal)?;
    let ovals = values(olen, op != Op::InverseReal)?;
    input_output(
        &Array::new(inp, ivals, iname),
        &Array::new(out.cast_const(), ovals, oname),
    )?;
    // SAFETY: non-NULL, aligned like T, disjoint, extents per the API's contract;
    // Complex<T> is #[repr(C)] {re, im}, the layout of T[2].
    unsafe {
        let cin = || std::slice::from_raw_parts(inp.cast::<Complex<H::T>>(), ilen);
        let cout = || std::slice::from_raw_parts_mut(out.cast::<Complex<H::T>>(), olen);
        match op {
            Op::Forward => plan.forward_many(b, cin(), cout()),
            Op::Inverse => plan.inverse_many(b, cin(), cout()),
            Op::ForwardReal => {
                plan.forward_real_many(b, std::slice::from_raw_parts(inp, ilen), cout())
            }
            Op::InverseReal => {
                plan.inverse_real_many(b, cin(), std::slice::from_raw_parts_mut(out, olen))
            }
        }
    }
    .map(|_| ())
    .map_err(CallError::from)
}

/// The body of `so3fft_partial_forward_many` for the handle type `H`.
///
/// # Safety
/// The API's contract: `p` is NULL or a live plan of type `H`; non-NULL arrays hold the
/// batch's extents.
pub(super) unsafe fn partial_forward_many<H: PartialHandle>(
    p: *mut H,
    howmany: c_int,
    samples: *mut [H::T; 2],
    idist: isize,
    coeffs: *mut [H::T; 2],
    odist: isize,
) -> c_int {
    // SAFETY: this function's contract.
    guarded_code(|| unsafe {
        run_many(
            p,
            Op::Forward,
            (howmany, idist, odist),
            samples.cast_const().cast(),
            coeffs.cast(),
        )
    })
}

/// The body of `so3fft_partial_inverse_many` for the handle type `H`.
///
/// # Safety
/// As [`partial_forward_many`].
pub(super) unsafe fn partial_inverse_many<H: PartialHandle>(
    p: *mut H,
    howmany: c_int,
    coeffs: *mut [H::T; 2],
    idist: isize,
    samples: *mut [H::T; 2],
    odist: isize,
) -> c_int {
    // SAFETY: this function's contract.
    guarded_code(|| unsafe {
        run_many(
            p,
            Op::Inverse,
            (howmany, idist, odist),
            coeffs.cast_const().cast(),
            samples.cast(),
        )
    })
}

/// The body of `so3fft_partial_forward_real_many` for the handle type `H`.
///
/// # Safety
/// As [`partial_forward_many`].
pub(super) unsafe fn partial_forward_real_many<H: PartialHandle>(
    p: *mut H,
    howmany: c_int,
    samples: *const H::T,
    idist: isize,
    coeffs: *mut [H::T; 2],
    odist: isize,
) -> c_int {
    // SAFETY: this function's contract.
    guarded_code(|| unsafe {
        run_many(
            p,
            Op::ForwardReal,
            (howmany, idist, odist),
            samples,
            coeffs.cast(),
        )
    })
}

/// The body of `so3fft_partial_inverse_real_many` for the handle type `H`.
///
/// # Safety
/// As [`partial_forward_many`].
pub(super) unsafe fn partial_inverse_real_many<H: PartialHandle>(
    p: *mut H,
    howmany: c_int,
    coeffs: *mut [H::T; 2],
    idist: isize,
    samples: *mut H::T,
    odist: isize,
) -> c_int {
    // SAFETY: this function's contract.
    guarded_code(|| unsafe {
        run_many(
            p,
            Op::InverseReal,
            (howmany, idist, odist),
            coeffs.cast_const().cast(),
            samples,
        )
    })
}

/// `howmany` forward transforms: samples `idist` values apart (only read) to coefficients
/// `odist` apart. `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_forward_many(
    p: so3fft_partial,
    howmany: c_int,
    samples: *mut so3fft_complex,
    idist: isize,
    coeffs: *mut so3fft_complex,
    odist: isize,
) -> c_int {
    // SAFETY: the API's contract.
    unsafe { partial_forward_many(p, howmany, samples, idist, coeffs, odist) }
}

/// `howmany` inverse transforms: coefficients `idist` apart to samples `odist` apart.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_inverse_many(
    p: so3fft_partial,
    howmany: c_int,
    coeffs: *mut so3fft_complex,
    idist: isize,
    samples: *mut so3fft_complex,
    odist: isize,
) -> c_int {
    // SAFETY: the API's contract.
    unsafe { partial_inverse_many(p, howmany, coeffs, idist, samples, odist) }
}

/// `howmany` forward transforms of real samples (doubles, `idist` apart); every
/// coefficient written. Needs a plan made with `SO3FFT_REAL`.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_forward_real_many(
    p: so3fft_partial,
    howmany: c_int,
    samples: *const f64,
    idist: isize,
    coeffs: *mut so3fft_complex,
    odist: isize,
) -> c_int {
    // SAFETY: the API's contract.
    unsafe { partial_forward_real_many(p, howmany, samples, idist, coeffs, odist) }
}

/// `howmany` inverse transforms to real samples; reads the blocks `mp > 0`, or `mp = 0`
/// and `m >= 0` (the others follow by symmetry). Needs `SO3FFT_REAL`.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_inverse_real_many(
    p: so3fft_partial,
    howmany: c_int,
    coeffs: *mut so3fft_complex,
    idist: isize,
    samples: *mut f64,
    odist: isize,
) -> c_int {
    // SAFETY: the API's contract.
    unsafe { partial_inverse_real_many(p, howmany, coeffs, idist, samples, odist) }
}

/// One forward transform (`so3fft_partial_forward_many` with `howmany = 1`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_forward(
    p: so3fft_partial,
    samples: *mut so3fft_complex,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the same contract.
    unsafe { so3fft_partial_forward_many(p, 1, samples, 0, coeffs, 0) }
}

/// One inverse transform.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_inverse(
    p: so3fft_partial,
    coeffs: *mut so3fft_complex,
    samples: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the same contract.
    unsafe { so3fft_partial_inverse_many(p, 1, coeffs, 0, samples, 0) }
}

/// One forward transform of real samples.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_forward_real(
    p: so3fft_partial,
    samples: *const f64,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the same contract.
    unsafe { so3fft_partial_forward_real_many(p, 1, samples, 0, coeffs, 0) }
}

/// One inverse transform to real samples.
#[no_mangle]
pub unsafe extern "C" fn so3fft_partial_inverse_real(
    p: so3fft_partial,
    coeffs: *mut so3fft_complex,
    samples: *mut f64,
) -> c_int {
    // SAFETY: the same contract.
    unsafe { so3fft_partial_inverse_real_many(p, 1, coeffs, 0, samples, 0) }
}
