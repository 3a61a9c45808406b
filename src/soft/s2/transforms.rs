//! `FST_semi_memo`, `InvFST_semi_memo`, `FST_semi_fly`, `InvFST_semi_fly`: SOFT's split-array
//! spherical-harmonic transforms on one cached [`S2Plan`] per bandwidth.

use super::super::cache::{cached, layer_workers, s2_options, Cache};
use super::super::real::try_zeroed;
use super::super::{guarded, SoftResult};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::CallError;
use crate::options::Options;
use crate::s2::{s2_coef_index, S2Limits, S2Plan};
use crate::Complex64;
use std::ffi::{c_double, c_int, c_void};
use std::sync::{Arc, Mutex, TryLockError};

/// Conversion buffers larger than this many bytes are made per call instead of being kept
/// with the cached plan.
const KEEP_BUFFERS_BYTES: usize = 128 << 20;

/// Arrays shorter than this are converted on the calling thread only: a copy of 16 MiB
/// takes about as long as starting threads on a busy machine.
const PARALLEL_MIN_LEN: usize = 1 << 20;

/// Coefficient arrays between the caller's split arrays and the plan: the transforms of
/// split data run as pairs of real transforms, one array each.
struct Buffers {
    /// `B^2` coefficients.
    coeffs: Vec<Complex64>,
    /// `B^2` coefficients of the second field of a pair.
    second: Vec<Complex64>,
}

impl Buffers {
    fn new(b: usize) -> SoftResult<Buffers> {
        Ok(Buffers {
            coeffs: try_zeroed(b * b)?,
            second: try_zeroed(b * b)?,
        })
    }
}

/// The S^2 plans of the layer, one per bandwidth.
static S2_PLANS: Cache<S2Entry> = Cache::new();

/// The cached S^2 plan (and buffers) of bandwidth `b`, created on first use.
pub(in crate::soft) fn s2_plan_for(b: usize) -> SoftResult<Arc<S2Entry>> {
    cached(&S2_PLANS, b, || S2Entry::new(b, &s2_options()))
}

/// A cached S^2 plan of the SOFT layer with its conversion buffers.
pub(in crate::soft) struct S2Entry {
    plan: S2Plan,
    /// Kept buffers (small bandwidths), taken by one call at a time.
    buffers: Mutex<Option<Buffers>>,
}

impl S2Entry {
    /// The plan.
    pub(in crate::soft) fn plan(&self) -> &S2Plan {
        &self.plan
    }

    /// The plan of bandwidth `b` with `options`.
    fn new(b: usize, options: &Options) -> crate::Result<S2Entry> {
        Ok(S2Entry {
            plan: S2Plan::new_on(b, S2Limits::default(), options, Some(&layer_workers()?))?,
            buffers: Mutex::new(None),
        })
    }

    /// Runs `f` with the kept buffers, or new ones when they are in use or too large to
    /// keep.
    fn with_buffers<R>(&self, f: impl FnOnce(&mut Buffers) -> SoftResult<R>) -> SoftResult<R> {
        let b = self.plan.bandwidth();
        let keep = 16 * 2 * b * b <= KEEP_BUFFERS_BYTES;
        let guard = match self.buffers.try_lock() {
            Ok(g) => Some(g),
            Err(TryLockError::Poisoned(e)) => Some(e.into_inner()),
            Err(TryLockError::WouldBlock) => None,
        };
        match guard {
            Some(mut g) if keep => {
                if g.is_none() {
                    *g = Some(Buffers::new(b)?);
                }
                match g.as_mut() {
                    Some(buf) => f(buf),
                    None => f(&mut Buffers::new(b)?),
                }
            }
            _ => f(&mut Buffers::new(b)?),
        }
    }

    /// Forward transform of `re + i im` into `(out_re, out_im)`; `real_format`: SOFT's
    /// `dataformat = 1` (negative orders rebuilt from the non-negative ones).
    fn forward(
        &self,
        input: (&[f64], &[f64]),
        output: (&mut [f64], &mut [f64]),
        real_format: bool,
    ) -> SoftResult<()> {
        let (re, im) = input;
        let threads = self.plan.threads();
        self.with_buffers(|buf| {
            // Zero imaginary parts (real data): the real-sample path, no conversion.
            if im.iter().all(|&v| v == 0.0) {
                self.plan.forward_real(re, &mut buf.coeffs)?;
                if real_format {
                    hermitian_from_nonnegative(self.plan.bandwidth(), &mut buf.coeffs);
                }
                deinterleave(&buf.coeffs, output.0, output.1, threads);
                return Ok(());
            }
            // The transform of re + i im is A(re) + i A(im), both real analyses read straight
            // from the caller's arrays.
            self.plan
                .forward_real_pair([re, im], [&mut buf.coeffs, &mut buf.second])?;
            let (a, b) = (&mut buf.coeffs, &buf.second);
            for (x, y) in a.iter_mut().zip(b) {
                *x += Complex64::i() * y;
            }
            if real_format {
                hermitian_from_nonnegative(self.plan.bandwidth(), a);
            }
            deinterleave(a, output.0, output.1, threads);
            Ok(())
        })
    }

    /// Inverse transform of `re + i im` into `(out_re, out_im)`; `real_format`: SOFT's
    /// `dataformat = 1` (only orders `m >= 0` read, `Im fhat(l, 0)` kept).
    fn inverse(
        &self,
        input: (&[f64], &[f64]),
        output: (&mut [f64], &mut [f64]),
        real_format: bool,
    ) -> SoftResult<()> {
        let (re, im) = input;
        let (out_re, out_im) = output;
        let b = self.plan.bandwidth();
        let threads = self.plan.threads();
        self.with_buffers(|buf| {
            if !real_format {
                // rdata and idata are the real syntheses of the two Hermitian parts of the
                // coefficients, written straight into the caller's arrays.
                let (h1, h2) = (&mut buf.coeffs, &mut buf.second);
                hermitian_parts(b, (re, im), h1, h2);
                self.plan.inverse_real_pair([h1, h2], [out_re, out_im])?;
                return Ok(());
            }
            // The synthesis of the Hermitian extension of the orders m >= 0 is
            // S(Re part) + i S_0(Im fhat(l, 0)): the real inverse of the non-negative orders
            // (which ignores Im fhat(l, 0)) gives rdata; the m = 0 imaginary parts alone,
            // as the coefficients of a real function, give idata.
            let split = b * (b + 1) / 2;
            for (c, (r, i)) in buf.coeffs[..split].iter_mut().zip(re.iter().zip(im)) {
                *c = Complex64::new(*r, *i);
            }
            buf.coeffs[split..].fill(Complex64::default());
            // fhat(l, 0) sits at index l.
            if im[..b].iter().all(|&v| v == 0.0) {
                self.plan.inverse_real(&buf.coeffs, out_re)?;
                fill_zero(out_im, threads);
            } else {
                let second = &mut buf.second;
                second[..split].fill(Complex64::default());
                for (c, v) in second[..b].iter_mut().zip(&im[..b]) {
                    *c = Complex64::new(*v, 0.0);
                }
                self.plan
                    .inverse_real_pair([&buf.coeffs, second], [out_re, out_im])?;
            }
            Ok(())
        })
    }
}

/// The Hermitian parts `h1 = (f + g) / 2` and `h2 = (f - g) / 2i` of the coefficients
/// `f = re + i im`, `g(l, m) = (-1)^m conj(f(l, -m))`, for the orders `m >= 0` (the first
/// `B (B + 1) / 2` entries; the real synthesis reads no others): `f = h1 + i h2`, and both
/// parts satisfy `h(l, -m) = (-1)^m conj(h(l, m))`, so each synthesises a real function:
/// the real and the imaginary part of the synthesis of `f`.
fn hermitian_parts(
    b: usize,
    (re, im): (&[f64], &[f64]),
    h1: &mut [Complex64],
    h2: &mut [Complex64],
) {
    for m in 0..b {
        let sign = if m % 2 == 0 { 0.5 } else { -0.5 };
        let pos = s2_coef_index(b, m, m as isize);
        let neg = s2_coef_index(b, m, -(m as isize));
        for k in 0..b - m {
            let f = Complex64::new(re[pos + k], im[pos + k]) * 0.5;
            let g = Complex64::new(re[neg + k], -im[neg + k]) * sign;
            h1[pos + k] = f + g;
            // (f - g) / i = -i (f - g)
            let d = f - g;
            h2[pos + k] = Complex64::new(d.im, -d.re);
        }
    }
}

/// Overwrites the negative orders: `fhat(l, -m) = (-1)^m conj(fhat(l, m))`, `m = 1..B-1`.
fn hermitian_from_nonnegative(b: usize, coeffs: &mut [Complex64]) {
    for m in 1..b {
        let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
        let pos = s2_coef_index(b, m, m as isize);
        let neg = s2_coef_index(b, m, -(m as isize));
        for k in 0..b - m {
            coeffs[neg + k] = coeffs[pos + k].conj() * sign;
        }
    }
}

/// Length of the pieces `len` values are cut into for `threads` threads.
fn piece_len(len: usize, threads: usize) -> usize {
    if len < PARALLEL_MIN_LEN {
        len.max(1)
    } else {
        len.div_ceil(threads.max(1)).max(1)
    }
}

/// Runs `work` on every item: a single item on the calling thread, several on scoped
/// threads (the first on the calling thread).
fn run_pieces<T: Send>(items: impl Iterator<Item = T>, work: impl Fn(T) + Sync) {
    let mut items = items.peekable();
    let Some(first) = items.next() else {
        return;
    };
    if items.peek().is_none() {
        work(first);
        return;
    }
    let work = &work;
    std::thread::scope(|scope| {
        for item in items {
            scope.spawn(move || work(item));
        }
        work(first);
    });
}

/// `re[i] + i im[i] = values[i]` on `threads` threads.
fn deinterleave(values: &[Complex64], re: &mut [f64], im: &mut [f64], threads: usize) {
    let piece = piece_len(values.len(), threads);
    let items = values
        .chunks(piece)
        .zip(re.chunks_mut(piece).zip(im.chunks_mut(piece)));
    run_pieces(items, |(v, (r, i))| {
        for (v, (r, i)) in v.iter().zip(r.iter_mut().zip(i.iter_mut())) {
            *r = v.re;
            *i = v.im;
        }
    });
}

/// Zeroes `out` on `threads` threads.
fn fill_zero(out: &mut [f64], threads: usize) {
    let piece = piece_len(out.len(), threads);
    run_pieces(out.chunks_mut(piece), |o| o.fill(0.0));
}

/// The caller's split arrays of one call.
struct SplitArrays {
    /// Real and imaginary parts of the input.
    input: (*const f64, *const f64),
    /// Real and imaginary parts of the output.
    output: (*mut f64, *mut f64),
}

impl SplitArrays {
    /// The input `(re, im)` and output `(re, im)` arrays of a call.
    fn new(input: (*mut f64, *mut f64), output: (*mut f64, *mut f64)) -> SplitArrays {
        SplitArrays {
            input: (input.0.cast_const(), input.1.cast_const()),
            output,
        }
    }
}

/// Names of the split arrays of the forward and the inverse (input, then output).
const FORWARD_NAMES: [&str; 4] = ["rdata", "idata", "rcoeffs", "icoeffs"];
const INVERSE_NAMES: [&str; 4] = ["rcoeffs", "icoeffs", "rdata", "idata"];

/// Shared body of the four entry points: checks the arguments (nothing is written on
/// failure) and runs the transform.
///
/// # Safety
/// The arrays are NULL or hold `(2B)^2` (samples) and `B^2` (coefficients) doubles, valid
/// for the call; the outputs are not used by anyone else during the call.
unsafe fn transform(
    bw: c_int,
    arrays: SplitArrays,
    dataformat: c_int,
    cutoff: c_int,
    forward: bool,
) -> SoftResult<()> {
    let b = checks::bandwidth(bw)?;
    if dataformat != 0 && dataformat != 1 {
        return Err(CallError::invalid(format!(
            "dataformat {dataformat} is neither 0 (complex) nor 1 (real)"
        )));
    }
    if cutoff < 0 || cutoff as usize > b {
        return Err(CallError::invalid(format!(
            "cutoff {cutoff} outside 0..={bw}"
        )));
    }
    let (samples, coeffs) = (4 * b * b, b * b);
    let (in_len, out_len, names) = if forward {
        (samples, coeffs, FORWARD_NAMES)
    } else {
        (coeffs, samples, INVERSE_NAMES)
    };
    let ins = [
        Array::new(arrays.input.0, in_len, names[0]),
        Array::new(arrays.input.1, in_len, names[1]),
    ];
    let outs = [
        Array::new(arrays.output.0.cast_const(), out_len, names[2]),
        Array::new(arrays.output.1.cast_const(), out_len, names[3]),
    ];
    for input in &ins {
        for output in &outs {
            input_output(input, output)?;
        }
    }
    input_output(&outs[0], &outs[1])?;
    let entry = s2_plan_for(b)?;
    // SAFETY: non-NULL, aligned, the outputs disjoint from the inputs and from each other
    // (checked); the lengths and exclusive use of the outputs by this function's contract.
    // The two inputs may be the same array (both are only read).
    let (in_re, in_im, out_re, out_im) = unsafe {
        (
            std::slice::from_raw_parts(arrays.input.0, in_len),
            std::slice::from_raw_parts(arrays.input.1, in_len),
            std::slice::from_raw_parts_mut(arrays.output.0, out_len),
            std::slice::from_raw_parts_mut(arrays.output.1, out_len),
        )
    };
    let real_format = dataformat == 1;
    if forward {
        entry.forward((in_re, in_im), (out_re, out_im), real_format)
    } else {
        entry.inverse((in_re, in_im), (out_re, out_im), real_format)
    }
}

// s2_semi_memo.h

/// Forward spherical-harmonic transform (`s2_semi_memo.h`): samples `rdata + i idata`
/// (`(2bw)^2` each, `theta_j = pi(2j+1)/(4bw)` slowest, `phi_k = pi k/bw` fastest) to the
/// coefficients `rcoeffs + i icoeffs` (`bw^2` each, `seanindex` order),
/// `fhat(l, m) = (pi/bw) sum_{j,k} w_B(j) f_jk conj(Y_l^m(theta_j, phi_k))`.
///
/// `dataformat = 1`: the orders `m >= 0` as for complex data, then
/// `fhat(l, -m) = (-1)^m conj(fhat(l, m))` for `m > 0` (`Im fhat(l, 0)` kept).
/// `cutoff` (`0..=bw`) does not change the result. The table, `workspace`, the plans and
/// `weights` (those of `makeweights`) are accepted and not read; the inputs are not modified.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_FST_semi_memo"]
pub unsafe extern "C" fn FST_semi_memo(
    rdata: *mut c_double,
    idata: *mut c_double,
    rcoeffs: *mut c_double,
    icoeffs: *mut c_double,
    bw: c_int,
    _seminaive_naive_table: *mut *mut c_double,
    _workspace: *mut c_double,
    dataformat: c_int,
    cutoff: c_int,
    _dct_plan: *mut c_void,
    _fft_plan: *mut c_void,
    _weights: *mut c_double,
) {
    guarded("FST_semi_memo", (), || {
        let arrays = SplitArrays::new((rdata, idata), (rcoeffs, icoeffs));
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { transform(bw, arrays, dataformat, cutoff, true) }
    })
}

/// Inverse spherical-harmonic transform (`s2_semi_memo.h`): coefficients
/// `rcoeffs + i icoeffs` (`seanindex` order) to the samples `rdata + i idata`,
/// `f_jk = sum_{l<bw} sum_{|m|<=l} fhat(l, m) Y_l^m(theta_j, phi_k)`.
///
/// `dataformat = 1`: only the orders `m >= 0` are read, the others taken as
/// `(-1)^m conj(fhat(l, m))`; `Im fhat(l, 0)` is not dropped, so `idata` is
/// `(1/sqrt(2pi)) sum_l Im fhat(l, 0) Pt_l^0(cos theta_j)` (exactly 0 when those parts
/// are 0); both outputs are always written. `cutoff` (`0..=bw`) does not change the
/// result; the table, `workspace` and the plans are accepted and not read.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_InvFST_semi_memo"]
pub unsafe extern "C" fn InvFST_semi_memo(
    rcoeffs: *mut c_double,
    icoeffs: *mut c_double,
    rdata: *mut c_double,
    idata: *mut c_double,
    bw: c_int,
    _transpose_seminaive_naive_table: *mut *mut c_double,
    _workspace: *mut c_double,
    dataformat: c_int,
    cutoff: c_int,
    _idct_plan: *mut c_void,
    _ifft_plan: *mut c_void,
) {
    guarded("InvFST_semi_memo", (), || {
        let arrays = SplitArrays::new((rcoeffs, icoeffs), (rdata, idata));
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { transform(bw, arrays, dataformat, cutoff, false) }
    })
}

// s2_semi_fly.h

/// Forward transform with the Legendre functions made on the fly (`s2_semi_fly.h`): the
/// same as [`FST_semi_memo`] without a table.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_FST_semi_fly"]
pub unsafe extern "C" fn FST_semi_fly(
    rdata: *mut c_double,
    idata: *mut c_double,
    rcoeffs: *mut c_double,
    icoeffs: *mut c_double,
    bw: c_int,
    _workspace: *mut c_double,
    dataformat: c_int,
    cutoff: c_int,
    _dct_plan: *mut c_void,
    _fft_plan: *mut c_void,
    _weights: *mut c_double,
) {
    guarded("FST_semi_fly", (), || {
        let arrays = SplitArrays::new((rdata, idata), (rcoeffs, icoeffs));
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { transform(bw, arrays, dataformat, cutoff, true) }
    })
}

/// Inverse transform with the Legendre functions made on the fly (`s2_semi_fly.h`): the
/// same as [`InvFST_semi_memo`] without a table.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_InvFST_semi_fly"]
pub unsafe extern "C" fn InvFST_semi_fly(
    rcoeffs: *mut c_double,
    icoeffs: *mut c_double,
    rdata: *mut c_double,
    idata: *mut c_double,
    bw: c_int,
    _workspace: *mut c_double,
    dataformat: c_int,
    cutoff: c_int,
    _idct_plan: *mut c_void,
    _ifft_plan: *mut c_void,
) {
    guarded("InvFST_semi_fly", (), || {
        let arrays = SplitArrays::new((rcoeffs, icoeffs), (rdata, idata));
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { transform(bw, arrays, dataformat, cutoff, false) }
    })
}
