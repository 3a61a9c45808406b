//! Rotational matching: correlation plans, the grid peak and its refinement off the grid.

use super::{guarded, guarded_code, rigor_of, so3fft_complex, threads_of, SO3FFT_REAL};
use super::{SO3FFT_DESTROY_INPUT, SO3FFT_ENULL};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::matching::{
    grid_argmax, grid_argmax_real, top_peaks, top_peaks_real, Correlation, CorrelationOptions,
    Peak, Rotation,
};
use crate::options::Options;
use crate::Complex64;
use std::ffi::{c_double, c_int, c_uint};

/// Correlation planner flag: normalised cross-correlation (means left out, divided by the
/// norms; `|C| <= 1`).
pub const SO3FFT_NORMALIZED: c_uint = 64;

/// Opaque correlation plan (made by `so3fft_plan_correlation`).
pub struct so3fft_correlation_s {
    plan: Correlation,
}

/// A correlation plan: a pointer to an opaque object.
pub type so3fft_correlation = *mut so3fft_correlation_s;

/// Plans the correlation `C(g) = int f(x) conj(h(g^-1 x)) dx` of functions of bandwidth `L`
/// on the SO(3) grid of bandwidth `B_out` (0 = `L`), degrees up to `deg_lim` (-1 =
/// `min(L, B_out) - 1`). `flags`: a planner rigour, `SO3FFT_REAL` for real inputs,
/// `SO3FFT_NORMALIZED` for the normalised cross-correlation.
/// NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_correlation(
    L: c_int,
    B_out: c_int,
    deg_lim: c_int,
    flags: c_uint,
    nthreads: c_int,
) -> so3fft_correlation {
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
        let options = CorrelationOptions {
            b_out,
            deg_lim,
            real: flags & SO3FFT_REAL != 0,
            normalized: flags & SO3FFT_NORMALIZED != 0,
            plans: Options {
                threads: threads_of(nthreads)?,
                rigor: rigor_of(flags & !(SO3FFT_REAL | SO3FFT_NORMALIZED))?,
                ..Options::default()
            },
        };
        let plan = Correlation::new(l, &options)?;
        Ok(Box::into_raw(Box::new(so3fft_correlation_s { plan })))
    })
}

/// Destroys a correlation plan; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fft_destroy_correlation(p: so3fft_correlation) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw in `so3fft_plan_correlation` and
            // is destroyed once, while no other thread uses it (the caller's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

/// The plan behind a handle; an error for NULL.
///
/// # Safety
/// `p` is NULL or a live correlation plan.
unsafe fn plan_ref<'a>(p: so3fft_correlation) -> Result<&'a Correlation, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract), only read.
    unsafe { p.as_ref() }
        .map(|s| &s.plan)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the correlation plan is NULL"))
}

/// Number of values `(2 B_out)^3` of a plan's correlation grid (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_correlation_grid_size(p: so3fft_correlation) -> isize {
    guarded(SO3FFT_ENULL as isize, || {
        // SAFETY: `p` is NULL or a live plan (the API's contract).
        Ok(unsafe { plan_ref(p) }?.num_grid() as isize)
    })
}

/// Input slices of a correlation call, checked (non-NULL, aligned, and disjoint from `out`
/// when given).
///
/// # Safety
/// Non-NULL pointers hold `n` values each, only read during the call.
unsafe fn inputs<'a, T>(
    signal: *const T,
    pattern: *const T,
    n: usize,
    out: Option<&Array<u8>>,
) -> Result<(&'a [T], &'a [T]), CallError> {
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

/// The plan and arrays of a correlation call, checked: samples of `T`, a grid of `G`.
type CallArgs<'a, T, G> = (&'a Correlation, (&'a [T], &'a [T]), &'a mut [G]);

/// [`CallArgs`] of a call on `p` with `signal`, `pattern` (`(2L)^2` values each) and the
/// grid `out` (`(2 B_out)^3` values).
///
/// # Safety
/// `p` is NULL or a live plan; the arrays are NULL or hold those sizes (the API's
/// contract).
unsafe fn call_args<'a, T, G>(
    p: so3fft_correlation,
    (signal, pattern): (*const T, *const T),
    out: *mut G,
) -> Result<CallArgs<'a, T, G>, CallError> {
    // SAFETY: this function's contract.
    unsafe {
        let plan = plan_ref(p)?;
        let (ns, ng) = (4 * plan.b_in() * plan.b_in(), plan.num_grid());
        let grid = Array::new(out.cast_const().cast::<u8>(), ng * size_of::<G>(), "out");
        let inputs = inputs(signal, pattern, ns, Some(&grid))?;
        Ok((plan, inputs, std::slice::from_raw_parts_mut(out, ng)))
    }
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
    guarded_code(|| {
        // SAFETY: `p` NULL or live; arrays of the documented sizes (the API's contract);
        // `so3fft_complex` is layout-identical to `Complex64`.
        let (plan, (s, h), out) = unsafe {
            call_args::<Complex64, Complex64>(p, (signal.cast(), pattern.cast()), out.cast())
        }?;
        Ok(plan.correlate(s, h, out)?)
    })
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
    guarded_code(|| {
        // SAFETY: as in `so3fft_correlate`.
        let (plan, (s, h), out) = unsafe { call_args(p, (signal, pattern), out) }?;
        Ok(plan.correlate_real(s, h, out)?)
    })
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
    guarded(-1, || {
        // SAFETY: as in `so3fft_correlate`.
        let (plan, (s, h), out) = unsafe {
            call_args::<Complex64, Complex64>(p, (signal.cast(), pattern.cast()), out.cast())
        }?;
        let peak = plan.correlate_argmax(s, h, out)?;
        // SAFETY: `angles` NULL or 3 doubles (the API's contract).
        Ok(unsafe { put_angles(peak, angles) })
    })
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
    guarded(-1, || {
        // SAFETY: as in `so3fft_correlate`.
        let (plan, (s, h), out) = unsafe { call_args(p, (signal, pattern), out) }?;
        let peak = plan.correlate_real_argmax(s, h, out)?;
        // SAFETY: `angles` NULL or 3 doubles (the API's contract).
        Ok(unsafe { put_angles(peak, angles) })
    })
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

/// Index of the largest `|C|^2` of a complex grid of bandwidth `B` (ties: the lowest index;
/// SOFT's rule), its Euler angles `(alpha, beta, gamma)` into `angles` (3 doubles, or NULL);
/// -1 on error.
#[no_mangle]
pub unsafe extern "C" fn so3fft_grid_argmax(
    B: c_int,
    grid: *mut so3fft_complex,
    angles: *mut c_double,
) -> isize {
    guarded(-1, || {
        let b = checks::bandwidth(B)?;
        let n = crate::num_samples(b);
        Array::new(grid.cast_const(), n, "grid").check()?;
        // SAFETY: checked non-NULL and aligned; (2B)^3 values (the API's contract).
        let values =
            unsafe { std::slice::from_raw_parts(grid.cast_const().cast::<Complex64>(), n) };
        // SAFETY: `angles` NULL or 3 doubles (the API's contract).
        Ok(unsafe { put_angles(grid_argmax(b, values), angles) })
    })
}

/// [`so3fft_grid_argmax`] of a real grid.
#[no_mangle]
pub unsafe extern "C" fn so3fft_grid_argmax_real(
    B: c_int,
    grid: *const c_double,
    angles: *mut c_double,
) -> isize {
    guarded(-1, || {
        let b = checks::bandwidth(B)?;
        let n = crate::num_samples(b);
        Array::new(grid, n, "grid").check()?;
        // SAFETY: as in `so3fft_grid_argmax`.
        let values = unsafe { std::slice::from_raw_parts(grid, n) };
        // SAFETY: as in `so3fft_grid_argmax`.
        Ok(unsafe { put_angles(grid_argmax_real(b, values), angles) })
    })
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
    guarded(-1, || {
        let b = checks::bandwidth(B)?;
        let n = crate::num_samples(b);
        Array::new(grid.cast_const(), n, "grid").check()?;
        check_peak_arrays(k, min_angle, angles, values, indices)?;
        // SAFETY: checked non-NULL and aligned; (2B)^3 values (the API's contract), only
        // read (non-const in the prototype like every complex array of this API).
        let grid = unsafe { std::slice::from_raw_parts(grid.cast_const().cast::<Complex64>(), n) };
        let peaks = top_peaks(b, grid, k, min_angle);
        // SAFETY: the arrays' sizes were checked for `k >= peaks.len()` peaks.
        Ok(unsafe { put_peaks(&peaks, angles, values, indices) })
    })
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
    guarded(-1, || {
        let b = checks::bandwidth(B)?;
        let n = crate::num_samples(b);
        Array::new(grid, n, "grid").check()?;
        check_peak_arrays(k, min_angle, angles, values, indices)?;
        // SAFETY: as in `so3fft_grid_top_peaks`.
        let grid = unsafe { std::slice::from_raw_parts(grid, n) };
        let peaks = top_peaks_real(b, grid, k, min_angle);
        // SAFETY: as in `so3fft_grid_top_peaks`.
        Ok(unsafe { put_peaks(&peaks, angles, values, indices) })
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
    unsafe { so3fft_correlation_refine_many(p, signal, pattern, 1, angles, value) }
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
        // SAFETY: as in `so3fft_correlate`; `angles` holds `3 npeaks` doubles (checked for
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
                let (s, h) = inputs(signal, pattern, ns, None)?;
                plan.coefficients_real(s, h, &mut coeffs)?;
            } else {
                let (s, h) = inputs(signal.cast::<Complex64>(), pattern.cast(), ns, None)?;
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
