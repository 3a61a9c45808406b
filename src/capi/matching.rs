//! Rotational matching: correlation plans, the grid peak and its refinement off the grid.
//!
//! The bodies are generic over the plan's handle ([`CorrelationHandle`], whose element type
//! is the precision) or over the grid's element type: the `so3fft_*` functions here and the
//! `so3fftf_*` ones of `single_matching.rs` are one-line wrappers over them. Peaks, angles
//! and refinement are `f64` in both precisions.

use super::{guarded, guarded_code, rigor_of, so3fft_complex, threads_of, SO3FFT_REAL};
use super::{SO3FFT_DESTROY_INPUT, SO3FFT_ENULL};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::matching::{
    self, Correlation, CorrelationOptions, DegreeWeights, Match, Peak, Rotation, Spectra,
};
use crate::options::Options;
use crate::{Complex, Complex64, Real};
use std::ffi::{c_double, c_int, c_uint};

/// Correlation planner flag: normalised cross-correlation (means left out, divided by the
/// norms; `|C| <= 1`).
pub const SO3FFT_NORMALIZED: c_uint = 64;

/// Correlation planner flag: degree weights estimated from the inputs' noise at each call
/// (`so3fft_correlation_weights` shows them).
pub const SO3FFT_NOISE_WEIGHTS: c_uint = 128;

/// The flags of a correlation plan besides a planner rigour.
const CORRELATION_FLAGS: c_uint = SO3FFT_REAL | SO3FFT_NORMALIZED | SO3FFT_NOISE_WEIGHTS;

/// Opaque correlation plan (made by `so3fft_plan_correlation`).
pub struct so3fft_correlation_s {
    plan: Correlation<f64>,
}

/// A correlation plan: a pointer to an opaque object.
pub type so3fft_correlation = *mut so3fft_correlation_s;

/// The opaque object behind the correlation plan handles of one precision
/// (`so3fft_correlation_s`, `so3fftf_correlation_s`): it owns a `Correlation` of its
/// element type.
pub(super) trait CorrelationHandle: Sized + 'static {
    /// The element type of the samples and the grid (`f64` or `f32`).
    type T: Real;
    /// The object owning `plan`.
    fn wrap(plan: Correlation<Self::T>) -> Self;
    /// The plan it owns.
    fn plan(&self) -> &Correlation<Self::T>;
}

impl CorrelationHandle for so3fft_correlation_s {
    type T = f64;
    fn wrap(plan: Correlation<f64>) -> Self {
        so3fft_correlation_s { plan }
    }
    fn plan(&self) -> &Correlation<f64> {
        &self.plan
    }
}

/// An array of interleaved complex values `{re, im}` as `Complex<T>` (`#[repr(C)]`, the
/// same layout and alignment).
fn complex<T>(a: *mut [T; 2]) -> *mut Complex<T> {
    a.cast()
}

/// The body of `so3fft_plan_correlation` (`weights` None) and of
/// `so3fft_plan_correlation_weighted` (`weights` the caller's pointer) for the handle type
/// `H`: a new plan, or NULL on error.
///
/// # Safety
/// A non-NULL `weights` holds `D + 1` doubles, `D` the resolved degree limit (the API's
/// contract).
pub(super) unsafe fn plan_correlation<H: CorrelationHandle>(
    L: c_int,
    B_out: c_int,
    deg_lim: c_int,
    flags: c_uint,
    nthreads: c_int,
    weights: Option<*const c_double>,
) -> *mut H {
    guarded(std::ptr::null_mut(), || {
        let l = checks::bandwidth(L)?;
        let b_out = match B_out {
            0 => None,
            b => Some(checks::bandwidth(b)?),
        };
        let deg_lim = match deg_lim {
            -1 => None,
            d => Some(usize::try_from(d).map_err(|_| {
                CallError::invalid(format!("degree limit {d}: must be >= 0 (or -1)"))
            })?),
        };
        if flags & SO3FFT_DESTROY_INPUT != 0 {
            return Err(CallError::invalid(
                "SO3FFT_DESTROY_INPUT does not apply to correlation plans",
            ));
        }
        let automatic = flags & SO3FFT_NOISE_WEIGHTS != 0;
        let weights = match weights {
            None if automatic => DegreeWeights::Automatic,
            None => DegreeWeights::Uniform,
            Some(_) if automatic => {
                return Err(CallError::invalid(
                    "SO3FFT_NOISE_WEIGHTS with given weights: the plan takes one or the other",
                ))
            }
            Some(w) => {
                // The degree limit the plan resolves; one it refuses is reported by the
                // planner below, without reading the weights.
                let m = l.min(b_out.unwrap_or(l));
                let d = deg_lim.unwrap_or(m - 1);
                if d < m {
                    Array::new(w, d + 1, "weights").check()?;
                    // SAFETY: checked non-NULL and aligned; `d + 1` doubles (this
                    // function's contract).
                    DegreeWeights::Given(unsafe { std::slice::from_raw_parts(w, d + 1) }.to_vec())
                } else {
                    DegreeWeights::Uniform
                }
            }
        };
        let options = CorrelationOptions {
            b_out,
            deg_lim,
            real: flags & SO3FFT_REAL != 0,
            normalized: flags & SO3FFT_NORMALIZED != 0,
            plans: Options {
                threads: threads_of(nthreads)?,
                rigor: rigor_of(flags & !CORRELATION_FLAGS)?,
                ..Options::default()
            },
            weights,
        };
        let plan = Correlation::<H::T>::new(l, &options)?;
        Ok(Box::into_raw(Box::new(H::wrap(plan))))
    })
}

/// The body of `so3fft_destroy_correlation` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a plan made by [`plan_correlation`] with the same `H`, not destroyed yet
/// and used by no other thread.
pub(super) unsafe fn destroy_correlation<H: CorrelationHandle>(p: *mut H) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw of a `Box<H>` in
            // `plan_correlation` and is destroyed once, while no other thread uses it (this
            // function's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

/// Plans the correlation `C(g) = int f(x) conj(h(g^-1 x)) dx` of functions of bandwidth `L`
/// on the SO(3) grid of bandwidth `B_out` (0 = `L`), degrees up to `deg_lim` (-1 =
/// `min(L, B_out) - 1`). `flags`: a planner rigour, `SO3FFT_REAL` for real inputs,
/// `SO3FFT_NORMALIZED` for the normalised cross-correlation, `SO3FFT_NOISE_WEIGHTS` for
/// degree weights estimated from the inputs' noise.
/// NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_correlation(
    L: c_int,
    B_out: c_int,
    deg_lim: c_int,
    flags: c_uint,
    nthreads: c_int,
) -> so3fft_correlation {
    // SAFETY: no weights array.
    unsafe { plan_correlation(L, B_out, deg_lim, flags, nthreads, None) }
}

/// `so3fft_plan_correlation` with the caller's degree weights: `C(g) = sum_l w_l
/// <f_l, (g h)_l>`, `weights` = `w_0 .. w_D` (`D + 1` doubles, copied; finite, >= 0, not all
/// 0), `D` = `deg_lim`, or `min(L, B_out) - 1` for -1 (`so3fft_correlation_degree_limit`).
/// Not with `SO3FFT_NOISE_WEIGHTS`. NULL on error.
#[no_mangle]
pub unsafe extern "C" fn so3fft_plan_correlation_weighted(
    L: c_int,
    B_out: c_int,
    deg_lim: c_int,
    flags: c_uint,
    nthreads: c_int,
    weights: *const c_double,
) -> so3fft_correlation {
    // SAFETY: `weights` NULL or `D + 1` doubles (the API's contract).
    unsafe { plan_correlation(L, B_out, deg_lim, flags, nthreads, Some(weights)) }
}

/// Destroys a correlation plan; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fft_destroy_correlation(p: so3fft_correlation) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_correlation(p) }
}

/// The plan behind a handle; an error for NULL.
///
/// # Safety
/// `p` is NULL or a live correlation plan, not destroyed during the returned reference's
/// use.
unsafe fn plan_ref<'a, H: CorrelationHandle>(
    p: *mut H,
) -> Result<&'a Correlation<H::T>, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract), only read.
    unsafe { p.as_ref() }
        .map(H::plan)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the correlation plan is NULL"))
}

/// The body of `so3fft_correlation_grid_size` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`.
pub(super) unsafe fn correlation_grid_size<H: CorrelationHandle>(p: *mut H) -> isize {
    guarded(SO3FFT_ENULL as isize, || {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        Ok(unsafe { plan_ref(p) }?.num_grid() as isize)
    })
}

/// Number of values `(2 B_out)^3` of a plan's correlation grid (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_grid_size(p: so3fft_correlation) -> isize {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { correlation_grid_size(p) }
}

/// Input slices of a correlation call, checked (non-NULL, aligned, and disjoint from `out`
/// when given).
///
/// # Safety
/// Non-NULL pointers hold `n` values each, only read during the call.
unsafe fn inputs<'a, X, G>(
    signal: *const X,
    pattern: *const X,
    n: usize,
    out: Option<&Array<G>>,
) -> Result<(&'a [X], &'a [X]), CallError> {
    for input in [
        Array::new(signal, n, "signal"),
        Array::new(pattern, n, "pattern"),
    ] {
        match out {
            Some(out) => input_output(&input, out)?,
            None => input.check()?,
        }
    }
    // SAFETY: checked non-NULL and aligned; `n` values each (this function's contract).
    Ok(unsafe {
        (
            std::slice::from_raw_parts(signal, n),
            std::slice::from_raw_parts(pattern, n),
        )
    })
}

/// The plan and arrays of a correlation call, checked: samples of `X`, a grid of `G`.
type CallArgs<'a, T, X, G> = (&'a Correlation<T>, (&'a [X], &'a [X]), &'a mut [G]);

/// [`CallArgs`] of a call on `p` with `signal`, `pattern` (`(2L)^2` values each) and the
/// grid `out` (`(2 B_out)^3` values).
///
/// # Safety
/// `p` is NULL or a live plan; the arrays are NULL or hold those sizes (the API's
/// contract).
unsafe fn call_args<'a, H: CorrelationHandle, X, G>(
    p: *mut H,
    (signal, pattern): (*const X, *const X),
    out: *mut G,
) -> Result<CallArgs<'a, H::T, X, G>, CallError> {
    // SAFETY: this function's contract.
    unsafe {
        let plan = plan_ref(p)?;
        let (ns, ng) = (4 * plan.b_in() * plan.b_in(), plan.num_grid());
        let grid = Array::new(out.cast_const(), ng, "out");
        let inputs = inputs(signal, pattern, ns, Some(&grid))?;
        Ok((plan, inputs, std::slice::from_raw_parts_mut(out, ng)))
    }
}

/// The body of `so3fft_correlate` for the handle type `H` (element `H::T`).
///
/// # Safety
/// `p` is NULL or a live plan of type `H`; non-NULL arrays hold the plan's sizes (the API's
/// contract).
pub(super) unsafe fn correlate<H: CorrelationHandle>(
    p: *mut H,
    signal: *mut [H::T; 2],
    pattern: *mut [H::T; 2],
    out: *mut [H::T; 2],
) -> c_int {
    guarded_code(|| {
        // SAFETY: this function's contract.
        let (plan, (s, h), out) = unsafe {
            call_args(
                p,
                (complex(signal).cast_const(), complex(pattern).cast_const()),
                complex(out),
            )
        }?;
        Ok(plan.correlate(s, h, out)?)
    })
}

/// The body of `so3fft_correlate_real` for the handle type `H`.
///
/// # Safety
/// As [`correlate`].
pub(super) unsafe fn correlate_real<H: CorrelationHandle>(
    p: *mut H,
    signal: *const H::T,
    pattern: *const H::T,
    out: *mut H::T,
) -> c_int {
    guarded_code(|| {
        // SAFETY: this function's contract.
        let (plan, (s, h), out) = unsafe { call_args(p, (signal, pattern), out) }?;
        Ok(plan.correlate_real(s, h, out)?)
    })
}

/// The body of `so3fft_correlate_argmax` for the handle type `H`.
///
/// # Safety
/// As [`correlate`]; `angles` is NULL or holds 3 doubles.
pub(super) unsafe fn correlate_argmax<H: CorrelationHandle>(
    p: *mut H,
    signal: *mut [H::T; 2],
    pattern: *mut [H::T; 2],
    out: *mut [H::T; 2],
    angles: *mut c_double,
) -> isize {
    guarded(-1, || {
        // SAFETY: this function's contract.
        let (plan, (s, h), out) = unsafe {
            call_args(
                p,
                (complex(signal).cast_const(), complex(pattern).cast_const()),
                complex(out),
            )
        }?;
        let peak = plan.correlate_argmax(s, h, out)?;
        // SAFETY: `angles` NULL or 3 doubles (this function's contract).
        Ok(unsafe { put_angles(peak, angles) })
    })
}

/// The body of `so3fft_correlate_real_argmax` for the handle type `H`.
///
/// # Safety
/// As [`correlate_argmax`].
pub(super) unsafe fn correlate_real_argmax<H: CorrelationHandle>(
    p: *mut H,
    signal: *const H::T,
    pattern: *const H::T,
    out: *mut H::T,
    angles: *mut c_double,
) -> isize {
    guarded(-1, || {
        // SAFETY: this function's contract.
        let (plan, (s, h), out) = unsafe { call_args(p, (signal, pattern), out) }?;
        let peak = plan.correlate_real_argmax(s, h, out)?;
        // SAFETY: `angles` NULL or 3 doubles (this function's contract).
        Ok(unsafe { put_angles(peak, angles) })
    })
}

/// The correlation of complex S^2 samples (`(2L)^2` each) into the grid `out`
/// (`(2 B_out)^3` values, SO(3) sample order). `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlate(
    p: so3fft_correlation,
    signal: *mut so3fft_complex,
    pattern: *mut so3fft_complex,
    out: *mut so3fft_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; non-NULL arrays hold the plan's sizes (the API's
    // contract).
    unsafe { correlate(p, signal, pattern, out) }
}

/// The correlation of real S^2 samples into the real grid `out` (plan made with
/// `SO3FFT_REAL`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlate_real(
    p: so3fft_correlation,
    signal: *const c_double,
    pattern: *const c_double,
    out: *mut c_double,
) -> c_int {
    // SAFETY: as in `so3fft_correlate`.
    unsafe { correlate_real(p, signal, pattern, out) }
}

/// [`so3fft_correlate`] and the index of the grid's largest `|C|^2` (the point
/// [`so3fft_grid_argmax`] gives), found while the grid is computed; its Euler angles into
/// `angles` (3 doubles, or NULL). -1 on error.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlate_argmax(
    p: so3fft_correlation,
    signal: *mut so3fft_complex,
    pattern: *mut so3fft_complex,
    out: *mut so3fft_complex,
    angles: *mut c_double,
) -> isize {
    // SAFETY: as in `so3fft_correlate`; `angles` NULL or 3 doubles (the API's contract).
    unsafe { correlate_argmax(p, signal, pattern, out, angles) }
}

/// [`so3fft_correlate_real`] and the index of the grid's largest `C^2`, as
/// [`so3fft_correlate_argmax`].
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlate_real_argmax(
    p: so3fft_correlation,
    signal: *const c_double,
    pattern: *const c_double,
    out: *mut c_double,
    angles: *mut c_double,
) -> isize {
    // SAFETY: as in `so3fft_correlate_argmax`.
    unsafe { correlate_real_argmax(p, signal, pattern, out, angles) }
}

/// Writes a peak's angles and returns its index.
///
/// # Safety
/// `angles` is NULL or holds 3 doubles.
unsafe fn put_angles(peak: Peak, angles: *mut c_double) -> isize {
    if !angles.is_null() {
        // SAFETY: 3 doubles (this function's contract).
        unsafe {
            *angles = peak.alpha;
            *angles.add(1) = peak.beta;
            *angles.add(2) = peak.gamma;
        }
    }
    peak.index as isize
}

/// The `(2B)^3` values of a grid of bandwidth `B`, checked (non-NULL, aligned).
///
/// # Safety
/// `grid` is NULL or holds `(2B)^3` values, only read during the call.
unsafe fn grid_values<'a, G>(B: c_int, grid: *const G) -> Result<(usize, &'a [G]), CallError> {
    let b = checks::bandwidth(B)?;
    let n = crate::num_samples(b);
    Array::new(grid, n, "grid").check()?;
    // SAFETY: checked non-NULL and aligned; (2B)^3 values (this function's contract).
    Ok((b, unsafe { std::slice::from_raw_parts(grid, n) }))
}

/// The body of `so3fft_grid_argmax` for complex grids of `T`.
///
/// # Safety
/// `grid` is NULL or holds `(2B)^3` values; `angles` is NULL or holds 3 doubles.
pub(super) unsafe fn grid_argmax<T: Real>(
    B: c_int,
    grid: *mut [T; 2],
    angles: *mut c_double,
) -> isize {
    guarded(-1, || {
        // SAFETY: this function's contract; the grid is only read (non-const in the
        // prototype like every complex array of this API).
        let (b, values) = unsafe { grid_values(B, complex(grid).cast_const()) }?;
        // SAFETY: `angles` NULL or 3 doubles (this function's contract).
        Ok(unsafe { put_angles(matching::grid_argmax(b, values), angles) })
    })
}

/// The body of `so3fft_grid_argmax_real` for real grids of `T`.
///
/// # Safety
/// As [`grid_argmax`].
pub(super) unsafe fn grid_argmax_real<T: Real>(
    B: c_int,
    grid: *const T,
    angles: *mut c_double,
) -> isize {
    guarded(-1, || {
        // SAFETY: this function's contract.
        let (b, values) = unsafe { grid_values(B, grid) }?;
        // SAFETY: `angles` NULL or 3 doubles (this function's contract).
        Ok(unsafe { put_angles(matching::grid_argmax_real(b, values), angles) })
    })
}

/// Index of the largest `|C|^2` of a complex grid of bandwidth `B` (ties: the lowest index;
/// SOFT's rule), its Euler angles `(alpha, beta, gamma)` into `angles` (3 doubles, or NULL);
/// -1 on error.
#[no_mangle]
pub unsafe extern "C" fn so3fft_grid_argmax(
    B: c_int,
    grid: *mut so3fft_complex,
    angles: *mut c_double,
) -> isize {
    // SAFETY: `grid` NULL or (2B)^3 values, `angles` NULL or 3 doubles (the API's contract).
    unsafe { grid_argmax(B, grid, angles) }
}

/// [`so3fft_grid_argmax`] of a real grid.
#[no_mangle]
pub unsafe extern "C" fn so3fft_grid_argmax_real(
    B: c_int,
    grid: *const c_double,
    angles: *mut c_double,
) -> isize {
    // SAFETY: as in `so3fft_grid_argmax`.
    unsafe { grid_argmax_real(B, grid, angles) }
}

/// The rotation matrix (row-major, acting on column vectors) of the rotation with Euler
/// angles `angles` = `(alpha, beta, gamma)`, `Rz(alpha) Ry(beta) Rz(gamma)`, into `matrix`
/// (9 doubles). `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_rotation_matrix(
    angles: *const c_double,
    matrix: *mut c_double,
) -> c_int {
    guarded_code(|| {
        let g = read_rotation(angles)?;
        Array::new(matrix.cast_const(), 9, "matrix").check()?;
        // SAFETY: checked non-NULL, aligned, 9 doubles (the API's contract).
        let out = unsafe { std::slice::from_raw_parts_mut(matrix, 9) };
        out.copy_from_slice(g.matrix().as_flattened());
        Ok(())
    })
}

/// The unit quaternion `(w, x, y, z)`, `w >= 0`, of the rotation with Euler angles
/// `angles` (as in `so3fft_rotation_matrix`) into `q` (4 doubles). `SO3FFT_OK` or an error
/// code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_rotation_quaternion(
    angles: *const c_double,
    q: *mut c_double,
) -> c_int {
    guarded_code(|| {
        let g = read_rotation(angles)?;
        Array::new(q.cast_const(), 4, "q").check()?;
        // SAFETY: checked non-NULL, aligned, 4 doubles (the API's contract).
        let out = unsafe { std::slice::from_raw_parts_mut(q, 4) };
        out.copy_from_slice(&g.quaternion());
        Ok(())
    })
}

/// The rotation with the 3 finite Euler angles at `angles`.
fn read_rotation(angles: *const c_double) -> Result<Rotation, CallError> {
    Array::new(angles, 3, "angles").check()?;
    // SAFETY: checked non-NULL and aligned; 3 doubles (the API's contract).
    let a = unsafe { std::slice::from_raw_parts(angles, 3) };
    let g = Rotation::new(a[0], a[1], a[2]);
    if !g.is_finite() {
        return Err(CallError::invalid(format!("angles {a:?} are not finite")));
    }
    Ok(g)
}

/// Writes `peaks` to the caller's arrays: Euler angles to `angles` (3 per peak), `|C|^2`
/// to `values` and flat indices to `indices` (each NULL or one per peak); their count.
///
/// # Safety
/// `angles` holds 3 doubles per peak; `values` and `indices` are NULL or hold one entry
/// per peak.
unsafe fn put_peaks(
    peaks: &[Peak],
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    for (i, p) in peaks.iter().enumerate() {
        // SAFETY: the sizes of this function's contract.
        unsafe {
            put_angles(*p, angles.add(3 * i));
            if !values.is_null() {
                *values.add(i) = p.value;
            }
            if !indices.is_null() {
                *indices.add(i) = p.index as isize;
            }
        }
    }
    peaks.len() as isize
}

/// Checks the arrays of a top-peaks call for `k` peaks and the separation angle.
fn check_peak_arrays(
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> Result<(), CallError> {
    if !(min_angle >= 0.0 && min_angle.is_finite()) {
        return Err(CallError::invalid(format!(
            "min_angle {min_angle} is not a finite angle >= 0"
        )));
    }
    let count = k
        .checked_mul(3)
        .filter(|&n| n <= isize::MAX as usize / 8)
        .ok_or_else(|| CallError::invalid(format!("k {k} too large")))?;
    Array::new(angles.cast_const(), count, "angles").check()?;
    if !values.is_null() {
        Array::new(values.cast_const(), k, "values").check()?;
    }
    if !indices.is_null() {
        Array::new(indices.cast_const(), k, "indices").check()?;
    }
    Ok(())
}

/// The body of `so3fft_grid_top_peaks` for complex grids of `T`.
///
/// # Safety
/// `grid` is NULL or holds `(2B)^3` values; `angles` is NULL or holds `3 k` doubles,
/// `values` and `indices` NULL or `k` entries each.
pub(super) unsafe fn grid_top_peaks<T: Real>(
    B: c_int,
    grid: *mut [T; 2],
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    guarded(-1, || {
        // SAFETY: this function's contract; the grid is only read (non-const in the
        // prototype like every complex array of this API).
        let (b, grid) = unsafe { grid_values(B, complex(grid).cast_const()) }?;
        check_peak_arrays(k, min_angle, angles, values, indices)?;
        let peaks = matching::top_peaks(b, grid, k, min_angle);
        // SAFETY: the arrays' sizes were checked for `k >= peaks.len()` peaks.
        Ok(unsafe { put_peaks(&peaks, angles, values, indices) })
    })
}

/// The body of `so3fft_grid_top_peaks_real` for real grids of `T`.
///
/// # Safety
/// As [`grid_top_peaks`].
pub(super) unsafe fn grid_top_peaks_real<T: Real>(
    B: c_int,
    grid: *const T,
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    guarded(-1, || {
        // SAFETY: this function's contract.
        let (b, grid) = unsafe { grid_values(B, grid) }?;
        check_peak_arrays(k, min_angle, angles, values, indices)?;
        let peaks = matching::top_peaks_real(b, grid, k, min_angle);
        // SAFETY: the arrays' sizes were checked for `k >= peaks.len()` peaks.
        Ok(unsafe { put_peaks(&peaks, angles, values, indices) })
    })
}

/// The (up to) `k` largest local maxima of `|C|^2` on a complex grid of bandwidth `B`, at
/// least `min_angle` radians (geodesic) apart, largest first: Euler angles into `angles`
/// (`3 k` doubles), `|C|^2` into `values` and flat indices into `indices` (each NULL or `k`
/// entries). A local maximum is at least as large as its 26 grid neighbours (alpha and
/// gamma periodic). Returns the number of peaks written, or -1 on error.
#[no_mangle]
pub unsafe extern "C" fn so3fft_grid_top_peaks(
    B: c_int,
    grid: *mut so3fft_complex,
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    // SAFETY: `grid` NULL or (2B)^3 values, the peak arrays NULL or of `k` peaks (the API's
    // contract).
    unsafe { grid_top_peaks(B, grid, k, min_angle, angles, values, indices) }
}

/// `so3fft_grid_top_peaks` of a real grid (`C^2`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_grid_top_peaks_real(
    B: c_int,
    grid: *const c_double,
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    // SAFETY: as in `so3fft_grid_top_peaks`.
    unsafe { grid_top_peaks_real(B, grid, k, min_angle, angles, values, indices) }
}

/// The body of `so3fft_correlation_refine_many` for the handle type `H`: samples of
/// `H::T` (complex ones interleaved), angles and values in `f64`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`; `signal` and `pattern` NULL or `(2L)^2` samples
/// each; `angles` NULL or `3 npeaks` doubles, `values` NULL or `npeaks` doubles (the API's
/// contract).
pub(super) unsafe fn correlation_refine_many<H: CorrelationHandle>(
    p: *mut H,
    signal: *const H::T,
    pattern: *const H::T,
    npeaks: usize,
    angles: *mut c_double,
    values: *mut c_double,
) -> c_int {
    guarded_code(|| {
        if angles.is_null() {
            return Err(CallError::new(ErrorKind::Null, "angles is NULL"));
        }
        let count = npeaks
            .checked_mul(3)
            .filter(|&n| n <= isize::MAX as usize / 8)
            .ok_or_else(|| {
                CallError::new(ErrorKind::Invalid, format!("npeaks {npeaks} too large"))
            })?;
        Array::new(angles.cast_const(), count, "angles").check()?;
        if !values.is_null() {
            Array::new(values.cast_const(), npeaks, "values").check()?;
        }
        // SAFETY: this function's contract; `angles` holds `3 npeaks` doubles (checked for
        // NULL, alignment and range above), `values` NULL or `npeaks`; both are read and
        // written through raw pointers (they may overlap).
        unsafe {
            let starts: Vec<Rotation> = (0..npeaks)
                .map(|k| {
                    let a = angles.add(3 * k);
                    Rotation::new(*a, *a.add(1), *a.add(2))
                })
                .collect();
            if let Some(g) = starts.iter().find(|g| !g.is_finite()) {
                return Err(CallError::invalid(format!(
                    "start rotation {g:?} is not finite"
                )));
            }
            let plan = plan_ref(p)?;
            if npeaks == 0 {
                return Ok(());
            }
            let b_out = plan.b_out();
            let mut coeffs = vec![Complex64::default(); crate::num_coeffs(b_out)];
            let ns = 4 * plan.b_in() * plan.b_in();
            if plan.is_real() {
                let (s, h) = inputs::<_, u8>(signal, pattern, ns, None)?;
                plan.coefficients_real(s, h, &mut coeffs)?;
            } else {
                let (s, h) = inputs::<Complex<H::T>, u8>(signal.cast(), pattern.cast(), ns, None)?;
                plan.coefficients(s, h, &mut coeffs)?;
            }
            let refined = plan.refine_many(&coeffs, &starts)?;
            for (k, (g, v)) in refined.into_iter().enumerate() {
                let a = angles.add(3 * k);
                (*a, *a.add(1), *a.add(2)) = (g.alpha, g.beta, g.gamma);
                if !values.is_null() {
                    *values.add(k) = v;
                }
            }
            Ok(())
        }
    })
}

/// Refines a peak off the grid: from the Euler angles in `angles` (3 doubles, e.g. from
/// `so3fft_grid_argmax`), the nearby maximum of the band-limited `|C|^2` of `signal` and
/// `pattern` (complex samples as interleaved doubles, or real ones for a plan made with
/// `SO3FFT_REAL`), written
/// back to `angles`; `|C|^2` there into `value` (or NULL). `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_refine(
    p: so3fft_correlation,
    signal: *const c_double,
    pattern: *const c_double,
    angles: *mut c_double,
    value: *mut c_double,
) -> c_int {
    // SAFETY: the caller's contract is `so3fft_correlation_refine_many`'s with one peak.
    unsafe { correlation_refine_many(p, signal, pattern, 1, angles, value) }
}

/// `so3fft_correlation_refine` for `npeaks` peaks at once (one correlation, one pass over
/// its coefficients per step for all peaks): `angles` holds `3 npeaks` doubles (alpha,
/// beta, gamma per peak), each triple replaced by its refined peak; `values` (NULL or
/// `npeaks` doubles) receives `|C|^2` there. `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_refine_many(
    p: so3fft_correlation,
    signal: *const c_double,
    pattern: *const c_double,
    npeaks: usize,
    angles: *mut c_double,
    values: *mut c_double,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; the arrays hold the documented sizes (the API's
    // contract).
    unsafe { correlation_refine_many(p, signal, pattern, npeaks, angles, values) }
}

/// The result of `so3fft_correlation_find`: the peak refined off the grid, the grid peak it
/// started from, and how sure it is. Angles in radians; shared by both precisions.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct so3fft_match {
    /// Euler angles of the refined peak: the rotation `g` with `f(x) ~ h(g^-1 x)`.
    pub alpha: c_double,
    /// Beta of the refined peak.
    pub beta: c_double,
    /// Gamma of the refined peak.
    pub gamma: c_double,
    /// `|C|^2` at the refined peak.
    pub value: c_double,
    /// Euler angles of the grid's largest `|C|^2` (the point `so3fft_correlate_argmax`
    /// gives), where the refinement started.
    pub grid_alpha: c_double,
    /// Beta of the grid peak.
    pub grid_beta: c_double,
    /// Gamma of the grid peak.
    pub grid_gamma: c_double,
    /// `|C|^2` at the grid peak.
    pub grid_value: c_double,
    /// Flat index of the grid peak.
    pub grid_index: isize,
    /// `sqrt(trace(covariance))`: the rms angle of the refined peak's error from the noise
    /// in the inputs; infinite when the peak is not a maximum.
    pub sigma: c_double,
    /// Covariance (rad^2, row-major 3x3) of the error `xi`, a rotation vector in the
    /// refined rotation's frame: the true rotation is `g exp(xi)`.
    pub covariance: [c_double; 9],
    /// `|C|` at the peak over `|C|` at the next peak at least `separation` away (both
    /// refined): near 1, the inputs cannot tell them apart; infinite if there is none.
    pub peak_ratio: c_double,
    /// The angle beyond which another peak counts as separate: `2 pi / (L + 1)`, `L` the
    /// highest degree weighted at least a tenth of the largest weight.
    pub separation: c_double,
    /// White-noise power per S^2 coefficient of the signal, fitted at the high degrees (0
    /// for exactly band-limited inputs).
    pub signal_noise: c_double,
    /// The same for the pattern.
    pub pattern_noise: c_double,
}

impl From<&Match> for so3fft_match {
    fn from(m: &Match) -> so3fft_match {
        let (g, p) = (&m.rotation, &m.grid_peak);
        so3fft_match {
            alpha: g.alpha,
            beta: g.beta,
            gamma: g.gamma,
            value: m.value,
            grid_alpha: p.alpha,
            grid_beta: p.beta,
            grid_gamma: p.gamma,
            grid_value: p.value,
            grid_index: p.index as isize,
            sigma: m.uncertainty.sigma,
            covariance: *m
                .uncertainty
                .covariance
                .as_flattened()
                .first_chunk()
                .expect("9"),
            peak_ratio: m.peak_ratio,
            separation: m.separation,
            signal_noise: m.spectra.signal_noise,
            pattern_noise: m.spectra.pattern_noise,
        }
    }
}

/// The byte range of a checked array and its name.
fn extent<T>(a: &Array<T>) -> Result<(usize, usize, &'static str), CallError> {
    a.byte_range().map(|(s, e)| (s, e, a.what))
}

/// The body of the `find` functions: `find` of the plan on the checked arrays, written to
/// `out`.
///
/// # Safety
/// As [`correlate`], for samples of `X` and a grid of `G`; `out` is NULL or one
/// `so3fft_match`.
unsafe fn find_into<H: CorrelationHandle, X, G>(
    p: *mut H,
    (signal, pattern): (*const X, *const X),
    grid: *mut G,
    out: *mut so3fft_match,
    find: impl FnOnce(&Correlation<H::T>, (&[X], &[X]), &mut [G]) -> crate::Result<Match>,
) -> c_int {
    guarded_code(|| {
        // SAFETY: this function's contract.
        let (plan, inputs, values) = unsafe { call_args(p, (signal, pattern), grid) }?;
        let result = Array::new(out.cast_const(), 1, "match");
        result.check()?;
        let (r0, r1, _) = extent(&result)?;
        let n = inputs.0.len();
        for (s, e, what) in [
            extent(&Array::new(signal, n, "signal"))?,
            extent(&Array::new(pattern, n, "pattern"))?,
            extent(&Array::new(grid.cast_const(), values.len(), "out"))?,
        ] {
            if s < r1 && r0 < e {
                return Err(CallError::invalid(format!(
                    "the match result and the {what} array overlap"
                )));
            }
        }
        let m = find(plan, inputs, values)?;
        // SAFETY: checked non-NULL, aligned and apart from the other arrays.
        unsafe { out.write(so3fft_match::from(&m)) };
        Ok(())
    })
}

/// The body of `so3fft_correlation_find` for the handle type `H`.
///
/// # Safety
/// As [`correlate`]; `out` is NULL or one `so3fft_match`.
pub(super) unsafe fn correlation_find<H: CorrelationHandle>(
    p: *mut H,
    signal: *mut [H::T; 2],
    pattern: *mut [H::T; 2],
    grid: *mut [H::T; 2],
    out: *mut so3fft_match,
) -> c_int {
    let inputs = (complex(signal).cast_const(), complex(pattern).cast_const());
    // SAFETY: this function's contract.
    unsafe {
        find_into(p, inputs, complex(grid), out, |plan, (s, h), g| {
            plan.find(s, h, g)
        })
    }
}

/// The body of `so3fft_correlation_find_real` for the handle type `H`.
///
/// # Safety
/// As [`correlation_find`].
pub(super) unsafe fn correlation_find_real<H: CorrelationHandle>(
    p: *mut H,
    signal: *const H::T,
    pattern: *const H::T,
    grid: *mut H::T,
    out: *mut so3fft_match,
) -> c_int {
    // SAFETY: this function's contract.
    unsafe {
        find_into(p, (signal, pattern), grid, out, |plan, (s, h), g| {
            plan.find_real(s, h, g)
        })
    }
}

/// The body of the `weights` functions: the weights the plan applies to the checked
/// inputs (`spectra` for estimated ones), written to `w`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`; `signal` and `pattern` NULL or `(2L)^2` samples
/// of `X` each; `w` NULL or `D + 1` doubles.
unsafe fn weights_into<H: CorrelationHandle, X>(
    p: *mut H,
    (signal, pattern, real): (*const X, *const X, bool),
    w: *mut c_double,
    spectra: impl FnOnce(&Correlation<H::T>, (&[X], &[X])) -> crate::Result<Spectra>,
) -> c_int {
    guarded_code(|| {
        // SAFETY: this function's contract.
        let plan = unsafe { plan_ref(p) }?;
        let n = plan.deg_lim() + 1;
        let out = Array::new(w.cast_const(), n, "weights");
        let ns = 4 * plan.b_in() * plan.b_in();
        // SAFETY: this function's contract.
        let inputs = unsafe { inputs(signal, pattern, ns, Some(&out)) }?;
        plan.need(real)?;
        let weights = match plan.weights() {
            DegreeWeights::Uniform => vec![1.0; n],
            DegreeWeights::Given(w) => w.clone(),
            DegreeWeights::Automatic => spectra(plan, inputs)?.weights,
        };
        // SAFETY: checked non-NULL, aligned, `n` doubles apart from the inputs.
        unsafe { std::slice::from_raw_parts_mut(w, n) }.copy_from_slice(&weights);
        Ok(())
    })
}

/// The body of `so3fft_correlation_weights` for the handle type `H`.
///
/// # Safety
/// As [`weights_into`], complex samples.
pub(super) unsafe fn correlation_weights<H: CorrelationHandle>(
    p: *mut H,
    signal: *mut [H::T; 2],
    pattern: *mut [H::T; 2],
    w: *mut c_double,
) -> c_int {
    let (s, h) = (complex(signal).cast_const(), complex(pattern).cast_const());
    // SAFETY: this function's contract.
    unsafe { weights_into(p, (s, h, false), w, |plan, (s, h)| plan.spectra(s, h)) }
}

/// The body of `so3fft_correlation_weights_real` for the handle type `H`.
///
/// # Safety
/// As [`weights_into`], real samples.
pub(super) unsafe fn correlation_weights_real<H: CorrelationHandle>(
    p: *mut H,
    signal: *const H::T,
    pattern: *const H::T,
    w: *mut c_double,
) -> c_int {
    // SAFETY: this function's contract.
    unsafe {
        weights_into(p, (signal, pattern, true), w, |plan, (s, h)| {
            plan.spectra_real(s, h)
        })
    }
}

/// The body of `so3fft_correlation_degree_limit` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`.
pub(super) unsafe fn correlation_degree_limit<H: CorrelationHandle>(p: *mut H) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        Ok(unsafe { plan_ref(p) }?.deg_lim() as c_int)
    })
}

/// The highest degree `D` the plan combines (its weights are `w_0 .. w_D`);
/// `SO3FFT_ENULL` for NULL.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_degree_limit(p: so3fft_correlation) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { correlation_degree_limit(p) }
}

/// The whole matching of complex samples: the grid into `grid` (as `so3fft_correlate`), its
/// peak refined off the grid, its uncertainty from the inputs' noise and its ratio to the
/// next separate peak, into `*out`. `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_find(
    p: so3fft_correlation,
    signal: *mut so3fft_complex,
    pattern: *mut so3fft_complex,
    grid: *mut so3fft_complex,
    out: *mut so3fft_match,
) -> c_int {
    // SAFETY: as in `so3fft_correlate`; `out` NULL or one so3fft_match (the API's contract).
    unsafe { correlation_find(p, signal, pattern, grid, out) }
}

/// `so3fft_correlation_find` of real samples into the real grid `grid` (plan made with
/// `SO3FFT_REAL`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_find_real(
    p: so3fft_correlation,
    signal: *const c_double,
    pattern: *const c_double,
    grid: *mut c_double,
    out: *mut so3fft_match,
) -> c_int {
    // SAFETY: as in `so3fft_correlation_find`.
    unsafe { correlation_find_real(p, signal, pattern, grid, out) }
}

/// The degree weights `w_0 .. w_D` the plan applies to these complex inputs, into `w`
/// (`D + 1` doubles): 1, the given ones, or (`SO3FFT_NOISE_WEIGHTS`) those estimated from
/// them, largest 1. `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_weights(
    p: so3fft_correlation,
    signal: *mut so3fft_complex,
    pattern: *mut so3fft_complex,
    w: *mut c_double,
) -> c_int {
    // SAFETY: `p` NULL or a live plan, the inputs NULL or `(2L)^2` samples, `w` NULL or
    // `D + 1` doubles (the API's contract).
    unsafe { correlation_weights(p, signal, pattern, w) }
}

/// `so3fft_correlation_weights` of real inputs (plan made with `SO3FFT_REAL`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_weights_real(
    p: so3fft_correlation,
    signal: *const c_double,
    pattern: *const c_double,
    w: *mut c_double,
) -> c_int {
    // SAFETY: as in `so3fft_correlation_weights`.
    unsafe { correlation_weights_real(p, signal, pattern, w) }
}
