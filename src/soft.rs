//! SOFT 2.0 drop-in layer: C entry points with the names, prototypes, array layouts and
//! semantics of Kostelec and Rockmore's SOFT 2.0 (`SPEC.md` sections 3 to 5), running on the
//! so3fft engine. The C declarations are the hand-written headers in `include/soft/`
//! (`soft_fftw.h`, `soft_fftw_pc.h`, `soft_fftw_nt.h`, `wrap_fftw.h`, `utils_so3.h`,
//! `makeweights.h`, `makeWigner.h`, `so3_correlate_fftw.h`, `csecond.h`); none of these
//! functions belongs to the native API in `so3fft.h` (every item carries `cbindgen:ignore`).
//!
//! Behaviour shared by all transform entry points:
//!
//! - **Plans.** One [`Plan`] per bandwidth is created on first use and cached for the life of
//!   the process (a global map, [`Direction::Both`]), so repeated calls at the same bandwidth
//!   pay set-up once. Plans use all cores and FFTW's `MEASURE` rigour by default; the
//!   environment variables `SO3FFT_SOFT_THREADS` (a positive number) and `SO3FFT_SOFT_RIGOR`
//!   (`estimate`, `measure`, `patient`, `exhaustive`), read once, override that. Calls from
//!   several client threads at once are safe (the cache is locked; plans execute concurrently).
//! - **Caller's FFTW plans and workspaces** are accepted and never used: the `fftw_plan *`
//!   argument is never dereferenced or executed and the workspaces are never read or written
//!   (all temporaries are private), so any buffer at least as large as SOFT documents (or
//!   smaller) is fine.
//! - **Inputs are never modified** (including the sample array of the `_nt` forward, which
//!   SOFT may overwrite).
//! - **Errors.** SOFT has no error channel: on invalid input (bandwidth outside
//!   `1..=MAX_BANDWIDTH`, NULL or misaligned arrays, overlapping input and output) or an
//!   internal error (e.g. out of memory), a function prints one line to stderr and returns
//!   without writing its output; functions returning `int` return -1. Panics never cross the
//!   C boundary.
//! - **Real data** (`flag != 0`): see [`Forward_SO3_Naive_fftw`] and [`Inverse_SO3_Naive_fftw`].

#![allow(non_snake_case)]
#![allow(clippy::missing_safety_doc)]

use crate::grid::block_start;
use crate::{num_coeffs, num_samples, Complex64, Direction, Plan, PlanOptions, Rigor};
use crate::{try_coef_index, MAX_BANDWIDTH};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::ffi::{c_double, c_int, c_void};
use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

/// `fftw_complex`: interleaved real and imaginary parts.
type FftwComplex = [f64; 2];

/// Result of an entry point's body: `Err` carries the message printed to stderr.
type SoftResult<T> = std::result::Result<T, String>;

// ----------------------------------------------------------------------------------------
// Boundary helpers
// ----------------------------------------------------------------------------------------

/// Print the one-line diagnostic of a failed call.
fn report(func: &str, msg: &str) {
    // Never panic here (eprintln! would on a closed stderr).
    let _ = writeln!(std::io::stderr(), "so3fft (SOFT layer): {func}: {msg}");
}

/// Run `body` with panics caught; on error print one line and return `fallback`.
fn guard<T>(func: &str, fallback: T, body: impl FnOnce() -> SoftResult<T>) -> T {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(v)) => v,
        Ok(Err(msg)) => {
            report(func, &msg);
            fallback
        }
        Err(_) => {
            report(func, "internal error (caught panic); output not written");
            fallback
        }
    }
}

/// Validate a transform bandwidth.
fn check_bw(bw: c_int) -> SoftResult<usize> {
    if bw < 1 || bw as usize > MAX_BANDWIDTH {
        return Err(format!(
            "invalid bandwidth {bw} (must be between 1 and {MAX_BANDWIDTH})"
        ));
    }
    Ok(bw as usize)
}

/// Check that `p` is non-NULL and aligned for `T`.
fn check_ptr<T>(p: *const T, what: &str) -> SoftResult<()> {
    if p.is_null() {
        return Err(format!("{what} is NULL"));
    }
    if !(p as usize).is_multiple_of(std::mem::align_of::<T>()) {
        return Err(format!(
            "{what} is not aligned to {} bytes",
            std::mem::align_of::<T>()
        ));
    }
    Ok(())
}

/// Reject an input range that overlaps an output range (SOFT's results would be garbage).
fn check_disjoint<A, B>(a: *const A, na: usize, b: *const B, nb: usize) -> SoftResult<()> {
    let (a0, b0) = (a as usize, b as usize);
    let a1 = a0.saturating_add(na.saturating_mul(std::mem::size_of::<A>()));
    let b1 = b0.saturating_add(nb.saturating_mul(std::mem::size_of::<B>()));
    if a0 < b1 && b0 < a1 {
        return Err("input and output arrays overlap".into());
    }
    Ok(())
}

/// Convert an index or size to the C `int` SOFT returns.
fn to_int(v: impl Into<i128> + Copy + std::fmt::Display) -> SoftResult<c_int> {
    c_int::try_from(v.into()).map_err(|_| format!("result {v} does not fit in a C int"))
}

// ----------------------------------------------------------------------------------------
// Plan cache
// ----------------------------------------------------------------------------------------

/// One slot per bandwidth; the slot's own lock serialises creation of that plan only.
type Slot = Arc<Mutex<Option<Arc<Plan>>>>;

static CACHE: Mutex<BTreeMap<usize, Slot>> = Mutex::new(BTreeMap::new());

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
            ..PlanOptions::default()
        }
    })
}

/// The cached plan of bandwidth `b`, created on first use. A failed creation is not cached.
fn plan_for(b: usize) -> SoftResult<Arc<Plan>> {
    let slot: Slot = {
        let mut map = CACHE.lock().unwrap_or_else(PoisonError::into_inner);
        map.entry(b).or_default().clone()
    };
    let mut g = slot.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(p) = g.as_ref() {
        if p.in_own_process() {
            return Ok(Arc::clone(p));
        }
        // A child after fork(): the cached plan's worker threads are the parent's. Make a
        // new one (dropping the old one in this process does not wait for them).
    }
    let p = Arc::new(
        Plan::new(b, cache_options()).map_err(|e| format!("cannot plan bandwidth {b}: {e}"))?,
    );
    *g = Some(Arc::clone(&p));
    Ok(p)
}

// ----------------------------------------------------------------------------------------
// Real-data symmetry
// ----------------------------------------------------------------------------------------

/// The order pairs `(M, M')` other than `(0, 0)` whose blocks a real transform reads:
/// `(0, M' > 0)`, `(M > 0, M' != -M)` and `(-m, m)` for `m > 0`. Each one's partner
/// `(-M, -M')` is in none of these; together with `(0, 0)` they cover every block once.
fn real_primary_pairs(b: usize) -> impl Iterator<Item = (isize, isize)> {
    let bi = b as isize;
    let zero = (1..bi).map(|mp| (0, mp));
    let pos = (1..bi).flat_map(move |m| {
        (-(bi - 1)..bi)
            .filter(move |&mp| mp != -m)
            .map(move |mp| (m, mp))
    });
    let anti = (1..bi).map(|m| (-m, m));
    zero.chain(pos).chain(anti)
}

/// Length of block `(m, m')`: `B - max(|m|, |m'|)`.
fn block_len(b: usize, m: isize, mp: isize) -> usize {
    b - m.unsigned_abs().max(mp.unsigned_abs())
}

/// `(-1)^(m - m')`.
fn parity(m: isize, mp: isize) -> f64 {
    if (m - mp).rem_euclid(2) == 0 {
        1.0
    } else {
        -1.0
    }
}

/// Make forward coefficients exactly real-symmetric: each block pair becomes the transform
/// of the real part of the samples, `(c(M,M') + (-1)^(M-M') conj(c(-M,-M'))) / 2`, and
/// `fhat(l, 0, 0)` becomes real.
fn symmetrize(b: usize, c: &mut [Complex64]) {
    let s00 = block_start(b, 0, 0);
    for v in &mut c[s00..s00 + b] {
        v.im = 0.0;
    }
    for (m, mp) in real_primary_pairs(b) {
        let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
        let s = parity(m, mp);
        for i in 0..block_len(b, m, mp) {
            let a = (c[p + i] + c[q + i].conj() * s) * 0.5;
            c[p + i] = a;
            c[q + i] = a.conj() * s;
        }
    }
}

/// Reusable coefficient buffers of the real inverse, one per bandwidth (taken out while in
/// use; a concurrent call allocates its own), so repeated calls do not pay page faults.
static REAL_BUFS: Mutex<BTreeMap<usize, Vec<Complex64>>> = Mutex::new(BTreeMap::new());

/// Private coefficient array for a real inverse: reads only `(0,0)` and the primary blocks
/// of `src`, fills each partner block by the symmetry (every entry is written). Hand it back
/// with [`release_real_buf`].
fn expand_real(b: usize, src: &[Complex64]) -> SoftResult<Vec<Complex64>> {
    let cached = REAL_BUFS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .remove(&b);
    let mut c = match cached {
        Some(v) if v.len() == src.len() => v,
        _ => try_zeroed(src.len())?,
    };
    let s00 = block_start(b, 0, 0);
    c[s00..s00 + b].copy_from_slice(&src[s00..s00 + b]);
    for (m, mp) in real_primary_pairs(b) {
        let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
        let s = parity(m, mp);
        for i in 0..block_len(b, m, mp) {
            let a = src[p + i];
            c[p + i] = a;
            c[q + i] = a.conj() * s;
        }
    }
    Ok(c)
}

/// Return a buffer of [`expand_real`] to the pool.
fn release_real_buf(b: usize, v: Vec<Complex64>) {
    REAL_BUFS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .insert(b, v);
}

/// A zeroed vector, with allocation failure reported instead of aborting.
fn try_zeroed(n: usize) -> SoftResult<Vec<Complex64>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| format!("out of memory allocating {} bytes", n.saturating_mul(16)))?;
    v.resize(n, Complex64::new(0.0, 0.0));
    Ok(v)
}

// ----------------------------------------------------------------------------------------
// Transform cores
// ----------------------------------------------------------------------------------------

/// Ratios `weights[k] / w_B(k)` when the caller's weights differ from the standard ones by
/// more than rounding, else `None` (the engine's own weights are then used as they are).
fn weight_ratios(b: usize, user: &[f64]) -> Option<Vec<f64>> {
    let std_w = crate::weights(b);
    let same = user
        .iter()
        .zip(&std_w)
        .all(|(u, w)| (u - w).abs() <= 1e-12 * w.abs().max(1e-300));
    if same {
        None
    } else {
        Some(user.iter().zip(&std_w).map(|(u, w)| u / w).collect())
    }
}

/// Forward transform of the `(2B)^3` samples at `data` into the `(4B^3-B)/3` coefficients
/// at `coeffs`, with SOFT's weights semantics and real flag.
unsafe fn forward_core(
    bw: c_int,
    data: *const FftwComplex,
    coeffs: *mut FftwComplex,
    weights: *const c_double,
    flag: c_int,
) -> SoftResult<()> {
    let b = check_bw(bw)?;
    check_ptr(data as *const Complex64, "data")?;
    check_ptr(coeffs as *const Complex64, "coeffs")?;
    let (ns, nc) = (num_samples(b), num_coeffs(b));
    check_disjoint(data, ns, coeffs as *const FftwComplex, nc)?;
    let ratios = if weights.is_null() {
        None
    } else {
        check_ptr(weights, "weights")?;
        // SAFETY: the caller passes 2B weights (SOFT's contract).
        weight_ratios(b, std::slice::from_raw_parts(weights, 2 * b))
    };
    let plan = plan_for(b)?;
    // SAFETY: SOFT's contract: data holds (2B)^3 and coeffs (4B^3-B)/3 fftw_complex values
    // (layout-identical to Complex64), checked non-NULL, aligned and disjoint above.
    let samples = std::slice::from_raw_parts(data as *const Complex64, ns);
    let out = std::slice::from_raw_parts_mut(coeffs as *mut Complex64, nc);
    match (ratios, flag != 0) {
        // Real data, standard weights: the real-signal path (half the work) reads the real
        // parts and writes exactly symmetric coefficients.
        (None, true) => {
            return plan
                .forward_real_parts(samples, out)
                .map(|_| ())
                .map_err(|e| e.to_string())
        }
        (None, false) => plan.forward(samples, out),
        (Some(r), _) => {
            // Custom weights: the forward is linear in each beta slice, so scaling slice k
            // by weights[k] / w_B(k) gives exactly SOFT's sum with the caller's weights.
            let mut scaled = try_zeroed(ns)?;
            let slice = 4 * b * b;
            for (k, (dst, src)) in scaled
                .chunks_exact_mut(slice)
                .zip(samples.chunks_exact(slice))
                .enumerate()
            {
                for (d, s) in dst.iter_mut().zip(src) {
                    *d = *s * r[k];
                }
            }
            plan.forward(&scaled, out)
        }
    }
    .map_err(|e| e.to_string())?;
    if flag != 0 {
        symmetrize(b, out);
    }
    Ok(())
}

/// Inverse transform of the coefficients at `coeffs` into the samples at `data`.
unsafe fn inverse_core(
    bw: c_int,
    coeffs: *const FftwComplex,
    data: *mut FftwComplex,
    flag: c_int,
) -> SoftResult<()> {
    let b = check_bw(bw)?;
    check_ptr(coeffs as *const Complex64, "coeffs")?;
    check_ptr(data as *const Complex64, "data")?;
    let (ns, nc) = (num_samples(b), num_coeffs(b));
    check_disjoint(coeffs, nc, data as *const FftwComplex, ns)?;
    let plan = plan_for(b)?;
    // SAFETY: SOFT's contract on the array sizes; checked non-NULL, aligned and disjoint.
    let input = std::slice::from_raw_parts(coeffs as *const Complex64, nc);
    let out = std::slice::from_raw_parts_mut(data as *mut Complex64, ns);
    if flag == 0 {
        return plan.inverse(input, out).map_err(|e| e.to_string());
    }
    let expanded = expand_real(b, input)?;
    let res = plan.inverse_real_to_complex(&expanded, out);
    release_real_buf(b, expanded);
    res.map_err(|e| e.to_string())
}

// ----------------------------------------------------------------------------------------
// soft_fftw.h
// ----------------------------------------------------------------------------------------

/// Forward SO(3) transform (`soft_fftw.h`): samples `data` (`(2B)^3`, SPEC layout) to
/// coefficients `coeffs` (`(4B^3-B)/3`, `so3CoefLoc` order).
///
/// `weights` (2B doubles, from `makeweights2` or the first half of `makeweights`) are the
/// quadrature weights: when they equal `w_B(k)` to rounding the engine's identical weights
/// are used; other values are honoured exactly (each beta slice is scaled by
/// `weights[k]/w_B(k)` in a private copy); NULL means the standard weights.
/// `flag != 0`: real data; the output is the transform of the real part of `data` and is
/// exactly symmetric, `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`, `fhat(l,0,0)` real.
/// The workspaces and the plan `p1` are accepted and not used; `data` is not modified.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw(
    bw: c_int,
    data: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    weights: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guard("Forward_SO3_Naive_fftw", (), || {
        forward_core(bw, data, coeffs, weights, flag)
    })
}

/// Inverse SO(3) transform (`soft_fftw.h`): coefficients `coeffs` to samples `data`.
///
/// `flag != 0`: real data; only the blocks `(0,0)`, `(0,M')` for `M' > 0`, `(M,M')` for
/// `M > 0, M' != -M` and `(-m,m)` for `m > 0` of `coeffs` are read (the others are rebuilt by
/// the real symmetry in a private array; they may hold anything) and the imaginary parts of
/// `data` are exactly 0. The workspaces and the plan `p1` are accepted and not used;
/// `coeffs` is not modified.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw(
    bw: c_int,
    coeffs: *mut FftwComplex,
    data: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guard("Inverse_SO3_Naive_fftw", (), || {
        inverse_core(bw, coeffs, data, flag)
    })
}

// ----------------------------------------------------------------------------------------
// soft_fftw_pc.h
// ----------------------------------------------------------------------------------------

/// Forward transform with a precomputed Wigner table (`soft_fftw_pc.h`): same as
/// [`Forward_SO3_Naive_fftw`]; the table `wigners` (from [`genWigAll`]) is not read.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw_pc(
    bw: c_int,
    data: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    weights: *mut c_double,
    _p1: *mut c_void,
    _wigners: *mut c_double,
    flag: c_int,
) {
    guard("Forward_SO3_Naive_fftw_pc", (), || {
        forward_core(bw, data, coeffs, weights, flag)
    })
}

/// Inverse transform with a precomputed Wigner table (`soft_fftw_pc.h`): same as
/// [`Inverse_SO3_Naive_fftw`]; the table `wignersTrans` (from [`genWigAllTrans`]) is not read.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw_pc(
    bw: c_int,
    coeffs: *mut FftwComplex,
    data: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    _p1: *mut c_void,
    _wigners_trans: *mut c_double,
    flag: c_int,
) {
    guard("Inverse_SO3_Naive_fftw_pc", (), || {
        inverse_core(bw, coeffs, data, flag)
    })
}

// ----------------------------------------------------------------------------------------
// soft_fftw_nt.h
// ----------------------------------------------------------------------------------------

/// Forward transform, "nt" variant (`soft_fftw_nt.h`; one complex workspace). Same as
/// [`Forward_SO3_Naive_fftw`]; unlike SOFT's, it does not overwrite `data`.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw_nt(
    bw: c_int,
    data: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_re: *mut c_double,
    weights: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guard("Forward_SO3_Naive_fftw_nt", (), || {
        forward_core(bw, data, coeffs, weights, flag)
    })
}

/// Inverse transform, "nt" variant (`soft_fftw_nt.h`; one complex workspace). Same as
/// [`Inverse_SO3_Naive_fftw`]; `coeffs` is not modified.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw_nt(
    bw: c_int,
    coeffs: *mut FftwComplex,
    data: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_re: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guard("Inverse_SO3_Naive_fftw_nt", (), || {
        inverse_core(bw, coeffs, data, flag)
    })
}

// ----------------------------------------------------------------------------------------
// wrap_fftw.h
// ----------------------------------------------------------------------------------------

/// Forward transform that manages its own workspaces and weights (`wrap_fftw.h`).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw_W(
    bw: c_int,
    signal: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    flag: c_int,
) {
    guard("Forward_SO3_Naive_fftw_W", (), || {
        forward_core(bw, signal, coeffs, std::ptr::null(), flag)
    })
}

/// Inverse transform that manages its own workspaces (`wrap_fftw.h`).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw_W(
    bw: c_int,
    coeffs: *mut FftwComplex,
    signal: *mut FftwComplex,
    flag: c_int,
) {
    guard("Inverse_SO3_Naive_fftw_W", (), || {
        inverse_core(bw, coeffs, signal, flag)
    })
}

// ----------------------------------------------------------------------------------------
// utils_so3.h
// ----------------------------------------------------------------------------------------

/// Number of coefficients at bandwidth `bw`: `(4 bw^3 - bw) / 3` (-1 if `bw < 1` or the
/// value does not fit in an `int`).
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn totalCoeffs_so3(bw: c_int) -> c_int {
    guard("totalCoeffs_so3", -1, || {
        if bw < 1 {
            return Err(format!("invalid bandwidth {bw}"));
        }
        let b = bw as i128;
        to_int((4 * b * b * b - b) / 3)
    })
}

/// Number of coefficients of order `m1` (all `m2`, all degrees) at bandwidth `bw`:
/// `bw^2 - m1^2`. The two arguments may be given in either order (the larger absolute value
/// is taken as the bandwidth), so the value is right whichever order a client uses.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn numCoeffs_so3(bw: c_int, m1: c_int) -> c_int {
    guard("numCoeffs_so3", -1, || {
        let (x, y) = ((bw as i64).abs(), (m1 as i64).abs());
        let (b, m) = (x.max(y), x.min(y));
        to_int(b * b - m * m)
    })
}

/// Number of coefficients of the order pair `(m1, m2)`: `bw - max(|m1|, |m2|)`.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn howMany_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guard("howMany_so3", -1, || {
        to_int(bw as i64 - (m1 as i64).abs().max((m2 as i64).abs()))
    })
}

/// Start, in SOFT's internal FFT'd sample array (orders in FFT order `m mod 2B`, each order
/// pair holding its `2B` beta samples contiguously), of the data of the order pair
/// `(m1, m2)`: `2bw * (2bw * (m1 mod 2bw) + (m2 mod 2bw))`. Orders must satisfy
/// `-2bw < m < 2bw`; -1 otherwise.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn sampLoc_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guard("sampLoc_so3", -1, || {
        if bw < 1 {
            return Err(format!("invalid bandwidth {bw}"));
        }
        let n = 2 * bw as i128;
        let (m1, m2) = (m1 as i128, m2 as i128);
        if m1.abs() >= n || m2.abs() >= n {
            return Err(format!(
                "orders ({m1}, {m2}) out of range for bandwidth {bw}"
            ));
        }
        to_int(n * (n * m1.rem_euclid(n) + m2.rem_euclid(n)))
    })
}

/// Checked index of `fhat(l, m, mp)` at bandwidth `bw`, as an `i64`.
fn coef_loc(m: c_int, mp: c_int, l: c_int, bw: c_int) -> SoftResult<i64> {
    if bw < 1 || l < 0 {
        return Err(format!(
            "coefficient (m={m}, mp={mp}, l={l}) does not exist at bandwidth {bw}"
        ));
    }
    try_coef_index(bw as usize, l as usize, m as isize, mp as isize)
        .map(|i| i as i64)
        .map_err(|e| e.to_string())
}

/// Index of the first coefficient (degree `max(|m1|, |m2|)`) of the block `(m1, m2)`;
/// -1 if `max(|m1|,|m2|) >= bw`.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn coefLoc_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guard("coefLoc_so3", -1, || {
        let l = (m1 as i64).abs().max((m2 as i64).abs());
        let l = c_int::try_from(l).map_err(|_| format!("orders ({m1}, {m2}) out of range"))?;
        to_int(coef_loc(m1, m2, l, bw)?)
    })
}

/// Index of `fhat(l, m, mp)` (`m` pairs with alpha, `mp` with gamma) in the coefficient
/// array of bandwidth `bw` (SPEC.md section 3); -1 if the coefficient does not exist.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn so3CoefLoc(m: c_int, mp: c_int, l: c_int, bw: c_int) -> c_int {
    guard("so3CoefLoc", -1, || to_int(coef_loc(m, mp, l, bw)?))
}

// ----------------------------------------------------------------------------------------
// makeweights.h
// ----------------------------------------------------------------------------------------

/// Quadrature weights, `4 bw` doubles: `w[j] = w_B(j)` and `w[j + 2bw] = w_B(j) sin(beta_j)`
/// for `j < 2bw` (SPEC.md section 3).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn makeweights(bw: c_int, w: *mut c_double) {
    guard("makeweights", (), || {
        let b = check_bw(bw)?;
        check_ptr(w as *const c_double, "w")?;
        let std_w = crate::weights(b);
        // SAFETY: the caller passes 4 bw doubles (SOFT's contract).
        let out = std::slice::from_raw_parts_mut(w, 4 * b);
        for (j, wj) in std_w.iter().enumerate() {
            out[j] = *wj;
            out[j + 2 * b] = wj * crate::beta(b, j).sin();
        }
        Ok(())
    })
}

/// Quadrature weights, `2 bw` doubles: `w[j] = w_B(j)` (the `weights` argument of the
/// forward transforms).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn makeweights2(bw: c_int, w: *mut c_double) {
    guard("makeweights2", (), || {
        let b = check_bw(bw)?;
        check_ptr(w as *const c_double, "w")?;
        // SAFETY: the caller passes 2 bw doubles (SOFT's contract).
        std::slice::from_raw_parts_mut(w, 2 * b).copy_from_slice(&crate::weights(b));
        Ok(())
    })
}

// ----------------------------------------------------------------------------------------
// makeWigner.h
// ----------------------------------------------------------------------------------------

/// Number of doubles in a `genWigAll` / `genWigAllTrans` table: the normalised Wigner d
/// values `dt^l_{m1,m2}(beta_k)` for the order pairs of [`wig_blocks`],
/// `l = max(m1, m2)..bw-1`, `k < 2bw`: `bw^2 (bw+1) (bw+2) / 3` (the size SOFT's clients
/// allocate).
fn wig_table_len(b: usize) -> Option<usize> {
    b.checked_mul(b)?
        .checked_mul(b + 1)?
        .checked_mul(b + 2)
        .map(|v| v / 3)
}

/// The order pairs `(m1, m2)` of a `genWigAll` table's blocks, in SOFT's order: `(0, 0)`;
/// `(m, m)` for `m = 1..bw-1`; `(m, 0)` for `m = 1..bw-1`; `(m1, m2)` for `m1 = 1..bw-1`,
/// `m2 = m1+1..bw-1`. (Every pair `0 <= min <= max < bw` once; the symmetries of `d` give
/// the others.)
fn wig_blocks(b: usize) -> impl Iterator<Item = (usize, usize)> {
    std::iter::once((0, 0))
        .chain((1..b).map(|m| (m, m)))
        .chain((1..b).map(|m| (m, 0)))
        .chain((1..b).flat_map(move |m1| (m1 + 1..b).map(move |m2| (m1, m2))))
}

/// Shared body of the two table generators.
unsafe fn gen_wig(bw: c_int, table: *mut c_double, transposed: bool) -> SoftResult<()> {
    let b = check_bw(bw)?;
    check_ptr(table as *const c_double, "wigners")?;
    let len = wig_table_len(b).ok_or("table size overflows")?;
    // SAFETY: the caller allocates bw^2 (bw+1)(bw+2)/3 doubles (SOFT's table size).
    let out = std::slice::from_raw_parts_mut(table, len);
    let n = 2 * b;
    let mut pos = 0;
    for (m1, m2) in wig_blocks(b) {
        let d = crate::wigner::dt_on_grid(b, m1 as isize, m2 as isize);
        let rows = b - m1.max(m2);
        let blk = &mut out[pos..pos + rows * n];
        if transposed {
            for k in 0..n {
                for r in 0..rows {
                    blk[k * rows + r] = d[r * n + k];
                }
            }
        } else {
            blk.copy_from_slice(&d);
        }
        pos += rows * n;
    }
    debug_assert_eq!(pos, len);
    // Set-up time belongs here: build (and cache) the transform plan of this bandwidth.
    // A failure is reported by the transform that needs the plan.
    let _ = plan_for(b);
    Ok(())
}

/// Table for the `_pc` forward transform (`makeWigner.h`): writes exactly
/// `bw^2 (bw+1)(bw+2)/3` doubles, the normalised Wigner d values
/// `sqrt((2l+1)/2) d^l_{m1,m2}(beta_k)`, blocks in SOFT's order: `(0, 0)`, `(m, m)` for
/// `m = 1..bw-1`, `(m, 0)` for `m = 1..bw-1`, then `(m1, m2)` for `m1 = 1..bw-1`,
/// `m2 = m1+1..bw-1`; rows `l = max(m1, m2)..bw-1`, each of the `2bw` values `k`), and creates the
/// cached transform plan of `bw`. The `_pc` transforms accept but do not read the table.
/// `workspace` is not used.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn genWigAll(bw: c_int, wigners: *mut c_double, _workspace: *mut c_double) {
    guard("genWigAll", (), || gen_wig(bw, wigners, false))
}

/// Table for the `_pc` inverse transform (`makeWigner.h`): the same values and size as
/// [`genWigAll`], each block transposed (rows `k`, columns `l`).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn genWigAllTrans(
    bw: c_int,
    wigners: *mut c_double,
    _workspace: *mut c_double,
) {
    guard("genWigAllTrans", (), || gen_wig(bw, wigners, true))
}

// ----------------------------------------------------------------------------------------
// so3_correlate_fftw.h
// ----------------------------------------------------------------------------------------

/// Index of the spherical-harmonic coefficient of degree `l` and order `m` at bandwidth `b`
/// in SOFT's/S2kit's layout (SPEC.md section 4): `m >= 0`: `m b - m(m-1)/2 + (l-m)`;
/// `m < 0`: `L(L+3)/2 + 1 + (L+m)(L+m+1)/2 + (l-|m|)` with `L = b-1`.
fn sean_index(m: i64, l: i64, b: i64) -> i64 {
    if m >= 0 {
        m * b - m * (m - 1) / 2 + (l - m)
    } else {
        let big_l = b - 1;
        big_l * (big_l + 3) / 2 + 1 + (big_l + m) * (big_l + m + 1) / 2 + (l + m)
    }
}

/// Index of the S^2 coefficient `(l, m)` at bandwidth `bw` in S2kit's layout (see SPEC.md
/// section 4); -1 if `|m| > l` or `l >= bw`.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn seanindex(m: c_int, l: c_int, bw: c_int) -> c_int {
    guard("seanindex", -1, || {
        if l < 0 || l >= bw || (m as i64).abs() > l as i64 {
            return Err(format!(
                "coefficient (m={m}, l={l}) does not exist at bandwidth {bw}"
            ));
        }
        to_int(sean_index(m as i64, l as i64, bw as i64))
    })
}

/// Combine the S^2 coefficients of a signal (`sigCoefR/I`) and a pattern (`patCoefR/I`),
/// both of bandwidth `bwIn` in `seanindex` order, into the SO(3) coefficients of their
/// correlation at bandwidth `bwOut`:
/// `so3Coef[so3CoefLoc(m1,m2,l,bwOut)] = 2pi sqrt(2/(2l+1)) (-1)^(m1+m2) f(l,-m1) conj(h(l,-m2))`
/// for `l <= degLim`, 0 for all other coefficients (all `(4bwOut^3-bwOut)/3` are written).
/// Requires `degLim < min(bwIn, bwOut)` (a negative `degLim` gives all zeros).
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn so3CombineCoef_fftw(
    bwIn: c_int,
    bwOut: c_int,
    degLim: c_int,
    sigCoefR: *mut c_double,
    sigCoefI: *mut c_double,
    patCoefR: *mut c_double,
    patCoefI: *mut c_double,
    so3Coef: *mut FftwComplex,
) {
    guard("so3CombineCoef_fftw", (), || {
        let bin = check_bw(bwIn)?;
        let bout = check_bw(bwOut)?;
        if degLim >= bwIn || degLim >= bwOut {
            return Err(format!(
                "degLim {degLim} must be below both bandwidths ({bwIn}, {bwOut})"
            ));
        }
        check_ptr(so3Coef as *const Complex64, "so3Coef")?;
        let nin = bin * bin;
        let nout = num_coeffs(bout);
        let ins = [sigCoefR, sigCoefI, patCoefR, patCoefI];
        for (p, name) in ins
            .iter()
            .zip(["sigCoefR", "sigCoefI", "patCoefR", "patCoefI"])
        {
            if degLim >= 0 {
                check_ptr(*p as *const c_double, name)?;
                check_disjoint(
                    *p as *const c_double,
                    nin,
                    so3Coef as *const FftwComplex,
                    nout,
                )?;
            }
        }
        // SAFETY: SOFT's contract: so3Coef holds (4bwOut^3-bwOut)/3 values, each input
        // bwIn^2 doubles (only read when degLim >= 0); checked above.
        let out = std::slice::from_raw_parts_mut(so3Coef as *mut Complex64, nout);
        out.fill(Complex64::new(0.0, 0.0));
        if degLim < 0 {
            return Ok(());
        }
        let rd = |p: *mut c_double| std::slice::from_raw_parts(p as *const c_double, nin);
        let (fr, fi, hr, hi) = (rd(sigCoefR), rd(sigCoefI), rd(patCoefR), rd(patCoefI));
        let bi = bin as i64;
        for l in 0..=degLim as i64 {
            let norm = 2.0 * PI * (2.0 / (2 * l + 1) as f64).sqrt();
            for m1 in -l..=l {
                let fidx = sean_index(-m1, l, bi) as usize;
                let f = Complex64::new(fr[fidx], fi[fidx]);
                for m2 in -l..=l {
                    let hidx = sean_index(-m2, l, bi) as usize;
                    let h = Complex64::new(hr[hidx], hi[hidx]);
                    let s = norm * parity(m1 as isize, m2 as isize);
                    let o = crate::coef_index(bout, l as usize, m1 as isize, m2 as isize);
                    out[o] = f * h.conj() * s;
                }
            }
        }
        Ok(())
    })
}

// ----------------------------------------------------------------------------------------
// csecond.h
// ----------------------------------------------------------------------------------------

/// Wall-clock time in seconds (since the Unix epoch), for timing as SOFT's clients do.
/// (SOFT's `csecond` may return CPU time; with multithreaded transforms wall time is the
/// meaningful measure.)
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn csecond() -> c_double {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_pairs_partition_blocks() {
        for b in 1..7usize {
            let bi = b as isize;
            let mut seen = std::collections::BTreeSet::new();
            seen.insert((0, 0));
            for (m, mp) in real_primary_pairs(b) {
                assert!(seen.insert((m, mp)), "dup {m} {mp}");
                assert!(seen.insert((-m, -mp)), "dup partner {m} {mp}");
            }
            assert_eq!(seen.len(), ((2 * bi - 1) * (2 * bi - 1)) as usize);
        }
    }

    #[test]
    fn index_functions() {
        assert_eq!(so3CoefLoc(0, 0, 0, 256), 0);
        assert_eq!(so3CoefLoc(0, 0, 255, 256), 255);
        assert_eq!(so3CoefLoc(0, 1, 1, 256), 256);
        assert_eq!(so3CoefLoc(0, -1, 1, 256), 65281);
        assert_eq!(so3CoefLoc(1, 0, 1, 256), 65536);
        assert_eq!(so3CoefLoc(-1, 0, 1, 256), 22304001);
        assert_eq!(so3CoefLoc(-1, -1, 255, 256), 22369535);
        assert_eq!(totalCoeffs_so3(256), 22369536);
        assert_eq!(totalCoeffs_so3(2048), -1);
        assert_eq!(numCoeffs_so3(8, 3), 55);
        assert_eq!(numCoeffs_so3(3, 8), 55);
        assert_eq!(numCoeffs_so3(8, -3), 55);
        assert_eq!(howMany_so3(-2, 5, 8), 3);
        assert_eq!(sampLoc_so3(1, -1, 4), 8 * (8 + 7));
        for bw in 1..6 {
            let mut k = 0;
            for m in 0..bw {
                for l in m..bw {
                    assert_eq!(seanindex(m, l, bw), k);
                    k += 1;
                }
            }
            for m in (1..bw).rev() {
                for l in m..bw {
                    assert_eq!(seanindex(-m, l, bw), k);
                    k += 1;
                }
            }
            assert_eq!(k, bw * bw);
        }
    }

    #[test]
    fn wig_table_size() {
        for b in 1..12usize {
            let direct: usize = (0..b).map(|m2| (m2 + 1) * (b - m2) * 2 * b).sum();
            assert_eq!(wig_table_len(b), Some(direct));
        }
    }
}
