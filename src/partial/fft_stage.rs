//! The FFT stage of a partial plan: pruned 2-D DFTs of one beta slice over
//! `(alpha, gamma)`, as 1-D transforms of only the rows and columns that can be non-zero.
//!
//! Inverse: the `2 Mmax + 1` rows `M` of a slice's values (zero outside `|M'| <= N`) are
//! transformed over gamma in the worker's work buffer (`n_alpha x n_gamma`, other rows
//! zero), then every column over alpha into the caller's slice. Forward: every row of the
//! caller's slice over gamma into the work buffer, then only the `2N + 1` columns `M'`
//! over alpha. The real transforms use `r2c` rows of `n_gamma / 2 + 1` values and
//! transform only the columns `0 ..= N`.
//!
//! Plans on the caller's arrays exist twice: for arrays aligned as FFTW's SIMD code wants
//! and (`FFTW_UNALIGNED`) for the others; plans inside the page-aligned work buffers once.

use crate::error::Result;
use crate::fft::{plan_guarded, AlignedBuf, RawPlan, Rigor, SIGN_MINUS, SIGN_PLUS};
use fftw_sys as fftw;
use num_complex::Complex64;
use std::ffi::c_int;

/// A batch of 1-D DFTs: `howmany` transforms of `n` points, `stride` apart within one,
/// `dist` from one to the next (the same on both sides).
#[derive(Clone, Copy)]
struct DftBatch {
    n: usize,
    howmany: usize,
    stride: usize,
    dist: usize,
}

/// Which kind of DFT a [`DftBatch`] is planned as.
#[derive(Clone, Copy)]
enum Kind {
    Complex(i32),
    R2c,
    C2r,
}

/// Plans a batch from `inp` to `out` (the same pointer: in place).
///
/// # Safety
/// `inp` and `out` cover the batch's extent (complex values, or reals for the real side of
/// `R2c` / `C2r`, whose complex side has rows of `n/2 + 1` values `dist_c` apart).
unsafe fn plan_batch(
    b: DftBatch,
    kind: Kind,
    (inp, out): (*mut Complex64, *mut Complex64),
    dist_c: usize,
    flags: u32,
) -> Result<RawPlan> {
    let dims = [b.n as c_int];
    let (h, s, d, dc) = (
        b.howmany as c_int,
        b.stride as c_int,
        b.dist as c_int,
        dist_c as c_int,
    );
    plan_guarded(b.n * b.howmany, 1, || {
        // SAFETY: under the planner lock (plan_guarded); the arrays cover the batch
        // (caller's contract); FFTW keeps no pointer to `dims`.
        unsafe {
            match kind {
                Kind::Complex(sign) => fftw::fftw_plan_many_dft(
                    1,
                    dims.as_ptr(),
                    h,
                    inp,
                    std::ptr::null(),
                    s,
                    d,
                    out,
                    std::ptr::null(),
                    s,
                    d,
                    sign,
                    flags,
                ),
                Kind::R2c => fftw::fftw_plan_many_dft_r2c(
                    1,
                    dims.as_ptr(),
                    h,
                    inp.cast::<f64>(),
                    std::ptr::null(),
                    1,
                    d,
                    out,
                    std::ptr::null(),
                    1,
                    dc,
                    flags | fftw::FFTW_PRESERVE_INPUT,
                ),
                Kind::C2r => fftw::fftw_plan_many_dft_c2r(
                    1,
                    dims.as_ptr(),
                    h,
                    inp,
                    std::ptr::null(),
                    1,
                    dc,
                    out.cast::<f64>(),
                    std::ptr::null(),
                    1,
                    d,
                    flags,
                ),
            }
        }
    })
}

/// A plan touching a caller's array: aligned and unaligned variants.
struct TwoWay {
    aligned: RawPlan,
    unaligned: RawPlan,
}

impl TwoWay {
    /// # Safety
    /// As for [`plan_batch`].
    unsafe fn new(
        b: DftBatch,
        kind: Kind,
        arrays: (*mut Complex64, *mut Complex64),
        dist_c: usize,
        rigor: Rigor,
    ) -> Result<TwoWay> {
        // SAFETY: the caller's contract.
        unsafe {
            Ok(TwoWay {
                aligned: plan_batch(b, kind, arrays, dist_c, rigor.flags())?,
                unaligned: plan_batch(
                    b,
                    kind,
                    arrays,
                    dist_c,
                    fftw::FFTW_ESTIMATE | fftw::FFTW_UNALIGNED,
                )?,
            })
        }
    }

    /// The variant for these arrays.
    fn pick(&self, a: *const Complex64, b: *const Complex64) -> fftw::fftw_plan {
        // SAFETY: fftw_alignment_of only inspects the addresses.
        let ok = unsafe {
            fftw::fftw_alignment_of(a.cast::<f64>().cast_mut()) == 0
                && fftw::fftw_alignment_of(b.cast::<f64>().cast_mut()) == 0
        };
        if ok {
            self.aligned.0
        } else {
            self.unaligned.0
        }
    }
}

/// A worker's buffers: a complex slice and (real plans) a half-spectrum slice.
pub(super) struct Work {
    pub full: AlignedBuf,
    pub half: Option<AlignedBuf>,
}

/// The slice DFTs of one shape.
pub(super) struct FftStage {
    na: usize,
    ng: usize,
    mmax: usize,
    n: usize,
    inv_rows: [Option<RawPlan>; 2],
    inv_cols: TwoWay,
    fwd_rows: TwoWay,
    fwd_cols: [Option<RawPlan>; 2],
    real: Option<RealFfts>,
}

struct RealFfts {
    r2c: TwoWay,
    c2r: TwoWay,
    /// Columns `0..=N` of the half spectrum, sign -1 (forward) and +1 (inverse).
    cols_minus: RawPlan,
    cols_plus: RawPlan,
}

impl FftStage {
    /// Plans for slices of `na x ng` values with orders `|M| <= mmax`, `|M'| <= n`.
    pub fn new(
        (na, ng): (usize, usize),
        (mmax, n): (usize, usize),
        real: bool,
        rigor: Rigor,
    ) -> Result<FftStage> {
        let len = na * ng;
        let a = AlignedBuf::new(len)?;
        let b = AlignedBuf::new(len)?;
        let (pa, pb) = (a.as_mut_ptr(), b.as_mut_ptr());
        let flags = rigor.flags();
        let rows = |howmany: usize| DftBatch {
            n: ng,
            howmany,
            stride: 1,
            dist: ng,
        };
        let cols = |howmany: usize| DftBatch {
            n: na,
            howmany,
            stride: ng,
            dist: 1,
        };
        // SAFETY (all plans below): `a` and `b` hold `na ng` values; each batch stays
        // inside them (rows `r..r+howmany` of `ng` values, or columns `c..c+howmany` of
        // `na` values `ng` apart), as does the real side (`na` rows of `ng` reals).
        let opt = |howmany: usize,
                   at: usize,
                   batch: &dyn Fn(usize) -> DftBatch,
                   sign: i32|
         -> Result<Option<RawPlan>> {
            if howmany == 0 {
                return Ok(None);
            }
            let p = pa.wrapping_add(at);
            // SAFETY: see above: the batch lies inside `a` from offset `at`.
            unsafe { plan_batch(batch(howmany), Kind::Complex(sign), (p, p), 0, flags) }.map(Some)
        };
        let inv_rows = [
            opt(mmax + 1, 0, &rows, SIGN_MINUS)?,
            opt(mmax, (na - mmax) * ng, &rows, SIGN_MINUS)?,
        ];
        let fwd_cols = [
            opt(n + 1, 0, &cols, SIGN_PLUS)?,
            opt(n, ng - n, &cols, SIGN_PLUS)?,
        ];
        // SAFETY: as above.
        let inv_cols =
            unsafe { TwoWay::new(cols(ng), Kind::Complex(SIGN_MINUS), (pa, pb), 0, rigor)? };
        // SAFETY: as above.
        let fwd_rows =
            unsafe { TwoWay::new(rows(na), Kind::Complex(SIGN_PLUS), (pb, pa), 0, rigor)? };
        let real = if real {
            let h = ng / 2 + 1;
            let half_cols = |sign| {
                let batch = DftBatch {
                    n: na,
                    howmany: n + 1,
                    stride: h,
                    dist: 1,
                };
                // SAFETY: columns 0..=N of `na` rows of `h <= ng` values, inside `a`.
                unsafe { plan_batch(batch, Kind::Complex(sign), (pa, pa), 0, flags) }
            };
            Some(RealFfts {
                // SAFETY: `na` rows of `ng` reals in `b`, `h` complex values each in `a`.
                r2c: unsafe { TwoWay::new(rows(na), Kind::R2c, (pb, pa), h, rigor)? },
                // SAFETY: as for r2c, the other way.
                c2r: unsafe { TwoWay::new(rows(na), Kind::C2r, (pa, pb), h, rigor)? },
                cols_minus: half_cols(SIGN_MINUS)?,
                cols_plus: half_cols(SIGN_PLUS)?,
            })
        } else {
            None
        };
        Ok(FftStage {
            na,
            ng,
            mmax,
            n,
            inv_rows,
            inv_cols,
            fwd_rows,
            fwd_cols,
            real,
        })
    }

    /// `(n_alpha, n_gamma)`.
    pub fn dims(&self) -> (usize, usize) {
        (self.na, self.ng)
    }

    /// Values of a slice, `n_alpha n_gamma`.
    pub fn slice_len(&self) -> usize {
        self.na * self.ng
    }

    /// A worker's buffers for these plans.
    pub fn work(&self) -> Result<Work> {
        Ok(Work {
            full: AlignedBuf::new(self.na * self.ng)?,
            half: match self.real {
                Some(_) => Some(AlignedBuf::new(self.na * (self.ng / 2 + 1))?),
                None => None,
            },
        })
    }

    /// Inverse of a slice: the order rows of `work.full` (values at `(M mod na) ng + M' mod ng`,
    /// everything else zero) over gamma in place, then all columns over alpha into `out`.
    ///
    /// # Safety
    /// `out` is valid for writes of `na ng` values, nobody else's meanwhile.
    pub unsafe fn inverse(&self, work: &mut Work, out: *mut Complex64) {
        let w = work.full.as_mut_ptr();
        let (na, ng, mmax) = (self.na, self.ng, self.mmax);
        for (plan, at) in self.inv_rows.iter().zip([0, (na - mmax) * ng]) {
            if let Some(p) = plan {
                // SAFETY: the plan was made at this offset of a page-aligned buffer of
                // the same size (same alignment); the work buffer is this worker's.
                unsafe { fftw::fftw_execute_dft(p.0, w.add(at), w.add(at)) };
            }
        }
        // SAFETY: `out` holds the slice (caller's contract); the variant matches the
        // arrays' alignment.
        unsafe { fftw::fftw_execute_dft(self.inv_cols.pick(w, out), w, out) };
    }

    /// Forward of the slice at `inp`: its rows over gamma into `work.full`, then the
    /// columns `|M'| <= N` over alpha, in place.
    ///
    /// # Safety
    /// `inp` is valid for reads of `na ng` values.
    pub unsafe fn forward(&self, work: &mut Work, inp: *const Complex64) {
        let w = work.full.as_mut_ptr();
        let inp = inp.cast_mut();
        // SAFETY: `inp` holds the slice and is only read (FFTW preserves the input of an
        // out-of-place complex DFT); the variant matches the arrays' alignment.
        unsafe { fftw::fftw_execute_dft(self.fwd_rows.pick(inp, w), inp, w) };
        for (plan, at) in self.fwd_cols.iter().zip([0, self.ng - self.n]) {
            if let Some(p) = plan {
                // SAFETY: as in `inverse`: same offset in a same-size page-aligned buffer.
                unsafe { fftw::fftw_execute_dft(p.0, w.add(at), w.add(at)) };
            }
        }
    }

    /// Real inverse: `work.half` holds `conj(G[M][M'])` at `(M mod na) h + M'` for
    /// `0 <= M' <= N` (everything else zero); its columns over alpha (sign +1), then the
    /// rows `c2r` into `out` (`na ng` reals). The half buffer is destroyed.
    ///
    /// # Safety
    /// `out` valid for writes of `na ng` doubles, nobody else's; the plan is real.
    pub unsafe fn inverse_real(&self, work: &mut Work, out: *mut f64) {
        let r = self.real.as_ref().expect("real plans");
        let w = work.half.as_mut().expect("real work buffer").as_mut_ptr();
        // SAFETY: plan made on a same-size page-aligned buffer; the buffer is this worker's.
        unsafe { fftw::fftw_execute_dft(r.cols_plus.0, w, w) };
        let o = out.cast::<Complex64>();
        // SAFETY: `out` holds the slice's reals (caller's contract); variant by alignment.
        unsafe { fftw::fftw_execute_dft_c2r(r.c2r.pick(w, o), w, out) };
    }

    /// Real forward of the `na ng` reals at `inp`: rows `r2c` into `work.half`, then its
    /// columns `0..=N` over alpha with sign -1 (`C` of the module documentation).
    ///
    /// # Safety
    /// `inp` valid for reads of `na ng` doubles; the plan is real.
    pub unsafe fn forward_real(&self, work: &mut Work, inp: *const f64) {
        let r = self.real.as_ref().expect("real plans");
        let w = work.half.as_mut().expect("real work buffer").as_mut_ptr();
        let i = inp.cast_mut();
        // SAFETY: `inp` holds the slice and is only read (FFTW_PRESERVE_INPUT); variant
        // by alignment.
        unsafe { fftw::fftw_execute_dft_r2c(r.r2c.pick(i.cast(), w), i, w) };
        // SAFETY: as in `inverse_real`.
        unsafe { fftw::fftw_execute_dft(r.cols_minus.0, w, w) };
    }
}
