//! The FFT stage of a partial plan: pruned 2-D DFTs of one beta slice over
//! `(alpha, gamma)`, as 1-D transforms of only the rows and columns that can be non-zero.
//!
//! Inverse: the values of a slice sit in the columns `|M'| <= N` of the worker's work
//! buffer (`n_alpha` rows, the other columns zero); those columns are transformed over
//! alpha in place, then every row over gamma into the caller's slice (rows written
//! whole). Forward: every row of the caller's slice over gamma into the work buffer, then
//! only the `2N + 1` columns `M'` over alpha. The real transforms use rows of
//! `n_gamma / 2 + 1` values (`r2c`, `c2r`) and transform only the columns `0 ..= N`.
//! The work buffers' rows are padded by a cache line so that a walk down a column does
//! not stay in one cache set.
//!
//! Plans on the caller's arrays exist twice: for arrays aligned as FFTW's SIMD code wants
//! and (`FFTW_UNALIGNED`) for the others; plans inside the page-aligned work buffers once.

use crate::error::Result;
use crate::fft::{
    copy_rows, plan_guarded, AlignedBuf, Plain, RawPlan, Rigor, SIGN_MINUS, SIGN_PLUS,
};
use crate::Real;
use fftw_sys as fftw;
use num_complex::Complex;
use std::ffi::c_int;

/// Complex values of padding after each row of a work buffer.
pub(crate) const ROW_PAD: usize = 4;

/// One output slice of an inverse, handed to a [`SliceWatch`] right after it is
/// computed (while in the cache): the real slice as written, or a complex slice in a work
/// buffer or the output, `row` values per row and rows `stride` values apart.
pub(crate) enum SliceRef<'a, T = f64> {
    /// The `n_alpha n_gamma` reals of the slice.
    Real(&'a [T]),
    /// The `n_alpha` rows of the slice.
    Complex {
        values: &'a [Complex<T>],
        row: usize,
        stride: usize,
    },
}

/// What an inverse calls with the slice index and the values of each output slice, once
/// per slice, from whichever worker computed it (for scans fused into the transform, such
/// as a grid's argmax).
pub(crate) type SliceWatch<'a, T = f64> = &'a (dyn Fn(usize, SliceRef<T>) + Sync);

/// A [`SliceWatch`] bound to one slice, for the FFT stage.
pub(crate) type Seen<'a, T> = Option<&'a dyn Fn(SliceRef<T>)>;

/// A batch of 1-D DFTs: `howmany` transforms of `n` points, `stride` apart within one,
/// `dist` from one to the next, on the input and the output side.
#[derive(Clone, Copy)]
struct DftBatch {
    n: usize,
    howmany: usize,
    stride: usize,
    idist: usize,
    odist: usize,
}

/// Which kind of DFT a [`DftBatch`] is planned as (the real kinds have stride 1).
#[derive(Clone, Copy)]
enum Kind {
    Complex(i32),
    R2c,
    C2r,
}

/// Plans a batch from `inp` to `out` (the same pointer: in place).
///
/// # Safety
/// `inp` and `out` cover the batch's extent (complex values, or reals on the real side of
/// `R2c` / `C2r`).
unsafe fn plan_batch<T: Real>(
    b: DftBatch,
    kind: Kind,
    (inp, out): (*mut Complex<T>, *mut Complex<T>),
    flags: u32,
) -> Result<RawPlan<T>> {
    let dims = [b.n as c_int];
    let (h, s, id, od) = (
        b.howmany as c_int,
        b.stride as c_int,
        b.idist as c_int,
        b.odist as c_int,
    );
    plan_guarded(b.n * b.howmany, || {
        // SAFETY: under the planner lock (plan_guarded); the arrays cover the batch
        // (caller's contract); FFTW keeps no pointer to `dims`.
        unsafe {
            match kind {
                Kind::Complex(sign) => T::plan_many_dft(
                    1,
                    dims.as_ptr(),
                    h,
                    inp,
                    std::ptr::null(),
                    s,
                    id,
                    out,
                    std::ptr::null(),
                    s,
                    od,
                    sign,
                    flags,
                ),
                Kind::R2c => T::plan_many_dft_r2c(
                    1,
                    dims.as_ptr(),
                    h,
                    inp.cast::<T>(),
                    std::ptr::null(),
                    1,
                    id,
                    out,
                    std::ptr::null(),
                    1,
                    od,
                    flags | fftw::FFTW_PRESERVE_INPUT,
                ),
                Kind::C2r => T::plan_many_dft_c2r(
                    1,
                    dims.as_ptr(),
                    h,
                    inp,
                    std::ptr::null(),
                    1,
                    id,
                    out.cast::<T>(),
                    std::ptr::null(),
                    1,
                    od,
                    flags,
                ),
            }
        }
    })
}

/// A plan touching a caller's array: aligned and unaligned variants.
struct TwoWay<T: Real> {
    aligned: RawPlan<T>,
    unaligned: RawPlan<T>,
}

impl<T: Real> TwoWay<T> {
    /// # Safety
    /// As for [`plan_batch`].
    unsafe fn new(
        b: DftBatch,
        kind: Kind,
        arrays: (*mut Complex<T>, *mut Complex<T>),
        rigor: Rigor,
    ) -> Result<TwoWay<T>> {
        // SAFETY: the caller's contract.
        unsafe {
            Ok(TwoWay {
                aligned: plan_batch(b, kind, arrays, rigor.flags())?,
                unaligned: plan_batch(b, kind, arrays, fftw::FFTW_ESTIMATE | fftw::FFTW_UNALIGNED)?,
            })
        }
    }

    /// The variant for these arrays.
    fn pick(&self, a: *const Complex<T>, b: *const Complex<T>) -> *mut T::PlanS {
        // SAFETY: fftw_alignment_of only inspects the addresses.
        let ok = unsafe {
            T::alignment_of(a.cast::<T>().cast_mut()) == 0
                && T::alignment_of(b.cast::<T>().cast_mut()) == 0
        };
        if ok {
            self.aligned.0
        } else {
            self.unaligned.0
        }
    }
}

/// The work buffers of a slice and its mirror.
pub(crate) type BufPair<'a, T> = (&'a mut [Complex<T>], &'a mut [Complex<T>]);

/// `len` values of two buffers, made on first use.
fn buf_pair<'a, T: Real>(
    (a, b): (&'a mut Option<AlignedBuf>, &'a mut Option<AlignedBuf>),
    len: usize,
) -> Result<BufPair<'a, T>> {
    Ok((view(a, len)?, view(b, len)?))
}

/// `len` values of `U` of a buffer, made on first use.
fn view<U: Plain>(buf: &mut Option<AlignedBuf>, len: usize) -> Result<&mut [U]> {
    if buf.is_none() {
        *buf = Some(AlignedBuf::of::<U>(len)?);
    }
    Ok(buf.as_mut().expect("just made").view_mut::<U>(len))
}

/// A worker's buffers, each made on first use (a plan makes them, `Engine::reserve`):
/// two complex work buffers (a slice and its mirror in one task) that the forward and the
/// inverse share, two half-spectrum buffers of the real transforms, and a slice of reals.
#[derive(Default)]
pub(crate) struct Work {
    pub inv: Option<AlignedBuf>,
    pub inv2: Option<AlignedBuf>,
    pub half: Option<AlignedBuf>,
    pub half2: Option<AlignedBuf>,
    /// Reals of a slice (the real forward of the real parts of complex samples).
    pub reals: Option<AlignedBuf>,
    /// A forward has written the complex buffers: the inverse, which relies on the values
    /// no slot fills staying zero, clears them first.
    pub dirty: bool,
}

/// The slice DFTs of one shape, in `T`.
pub(crate) struct FftStage<T: Real = f64> {
    na: usize,
    ng: usize,
    n: usize,
    /// Row strides of the complex and the half-spectrum work buffers.
    rs: usize,
    hs: usize,
    /// Columns `0..=N` and `-N..-1` over alpha, in place: sign -1 (inverse), +1 (forward).
    inv_cols: [Option<RawPlan<T>>; 2],
    fwd_cols: [Option<RawPlan<T>>; 2],
    inv_rows: InverseRows<T>,
    /// The forward's rows in place in the work buffer, after a copy of the caller's slice
    /// there (a sequential read the prefetchers follow).
    fwd_rows_in_place: RawPlan<T>,
    real: Option<RealFfts<T>>,
}

/// The inverse's rows over gamma.
enum InverseRows<T: Real> {
    /// In place in the work buffer, then streamed to the caller's slice: where most
    /// columns are in the band (`2N + 1 >= n_gamma / 2`), so the rows are transformed
    /// whole anyway and FFTW's own stores into the caller's slice would first read each of
    /// its lines from memory.
    InPlace(RawPlan<T>),
    /// Straight into the caller's slice (the columns outside the band stay zero in the
    /// work buffer).
    IntoSlice(TwoWay<T>),
}

struct RealFfts<T: Real> {
    r2c: TwoWay<T>,
    c2r: TwoWay<T>,
    /// Columns `0..=N` of the half spectrum, sign -1 (forward) and +1 (inverse).
    cols_minus: RawPlan<T>,
    cols_plus: RawPlan<T>,
}

impl<T: Real> FftStage<T> {
    /// Plans for slices of `na x ng` values with orders `|M'| <= n`.
    pub fn new(
        (na, ng): (usize, usize),
        n: usize,
        real: bool,
        rigor: Rigor,
    ) -> Result<FftStage<T>> {
        let (rs, hs) = (ng + ROW_PAD, ng / 2 + 1 + ROW_PAD);
        let a = AlignedBuf::of::<Complex<T>>(na * rs)?;
        let b = AlignedBuf::of::<Complex<T>>(na * rs)?;
        let (pa, pb) = (a.ptr::<Complex<T>>(), b.ptr::<Complex<T>>());
        let flags = rigor.flags();
        let cols = |howmany: usize, stride: usize| DftBatch {
            n: na,
            howmany,
            stride,
            idist: 1,
            odist: 1,
        };
        let rows = |idist: usize, odist: usize| DftBatch {
            n: ng,
            howmany: na,
            stride: 1,
            idist,
            odist,
        };
        // SAFETY (all plans below): `a` and `b` hold `na` rows of `rs >= ng` values (or,
        // as reals, `na` rows of `ng`); each batch stays inside them: columns `c..c+howmany`
        // (`c + howmany <= ng`, or `<= hs` of the half spectrum) of `na` values, or the
        // `na` rows.
        let col_plan =
            |howmany: usize, at: usize, stride: usize, sign: i32| -> Result<Option<RawPlan<T>>> {
                if howmany == 0 {
                    return Ok(None);
                }
                let p = pa.wrapping_add(at);
                // SAFETY: see above.
                unsafe { plan_batch(cols(howmany, stride), Kind::Complex(sign), (p, p), flags) }
                    .map(Some)
            };
        let inv_cols = [
            col_plan(n + 1, 0, rs, SIGN_MINUS)?,
            col_plan(n, ng - n, rs, SIGN_MINUS)?,
        ];
        let fwd_cols = [
            col_plan(n + 1, 0, rs, SIGN_PLUS)?,
            col_plan(n, ng - n, rs, SIGN_PLUS)?,
        ];
        let inv_rows = if 2 * n + 1 >= ng / 2 {
            // SAFETY: as above, in place in `a`.
            InverseRows::InPlace(unsafe {
                plan_batch(rows(rs, rs), Kind::Complex(SIGN_MINUS), (pa, pa), flags)?
            })
        } else {
            // SAFETY: as above, from `a` into `b`.
            InverseRows::IntoSlice(unsafe {
                TwoWay::new(rows(rs, ng), Kind::Complex(SIGN_MINUS), (pa, pb), rigor)?
            })
        };
        // SAFETY: as above, in place in `a`.
        let fwd_rows_in_place =
            unsafe { plan_batch(rows(rs, rs), Kind::Complex(SIGN_PLUS), (pa, pa), flags)? };
        let real = if real {
            let half_cols =
                |sign| col_plan(n + 1, 0, hs, sign).map(|p| p.expect("N + 1 > 0 columns"));
            Some(RealFfts {
                // SAFETY: `na` rows of `ng` reals in `b`, rows of `hs` values in `a`.
                r2c: unsafe { TwoWay::new(rows(ng, hs), Kind::R2c, (pb, pa), rigor)? },
                // SAFETY: as for r2c, the other way.
                c2r: unsafe { TwoWay::new(rows(hs, ng), Kind::C2r, (pa, pb), rigor)? },
                cols_minus: half_cols(SIGN_MINUS)?,
                cols_plus: half_cols(SIGN_PLUS)?,
            })
        } else {
            None
        };
        Ok(FftStage {
            na,
            ng,
            n,
            rs,
            hs,
            inv_cols,
            fwd_cols,
            inv_rows,
            fwd_rows_in_place,
            real,
        })
    }

    /// Values of a slice, `n_alpha n_gamma`.
    pub fn slice_len(&self) -> usize {
        self.na * self.ng
    }

    /// Row strides of the complex and the half-spectrum work buffers.
    pub fn strides(&self) -> (usize, usize) {
        (self.rs, self.hs)
    }

    /// The inverse's work buffer, zero where no value is ever placed.
    pub fn inv_buf<'a>(&self, work: &'a mut Work) -> Result<&'a mut [Complex<T>]> {
        self.inv_pair(work).map(|(a, _)| a)
    }

    /// Two inverse work buffers (a slice and its mirror), zero where no value is ever
    /// placed (cleared whole after a forward used them).
    pub fn inv_pair<'a>(&self, work: &'a mut Work) -> Result<BufPair<'a, T>> {
        let clear = std::mem::take(&mut work.dirty);
        let (a, b) = buf_pair((&mut work.inv, &mut work.inv2), self.na * self.rs)?;
        if clear {
            a.fill(Complex::new(T::ZERO, T::ZERO));
            b.fill(Complex::new(T::ZERO, T::ZERO));
        }
        Ok((a, b))
    }

    /// Two forward work buffers (a slice and its mirror): the inverse's, marked as written.
    pub fn fwd_pair<'a>(&self, work: &'a mut Work) -> Result<BufPair<'a, T>> {
        work.dirty = true;
        buf_pair((&mut work.inv, &mut work.inv2), self.na * self.rs)
    }

    /// Two half buffers (the real transforms of a slice and its mirror).
    pub fn half_pair<'a>(&self, work: &'a mut Work) -> Result<BufPair<'a, T>> {
        buf_pair((&mut work.half, &mut work.half2), self.na * self.hs)
    }

    /// Two half buffers and the reals of a slice (the real forward of real parts).
    pub fn half_pair_reals<'a>(&self, work: &'a mut Work) -> Result<(BufPair<'a, T>, &'a mut [T])> {
        let reals = view::<T>(&mut work.reals, self.slice_len())?;
        let pair = buf_pair((&mut work.half, &mut work.half2), self.na * self.hs)?;
        Ok((pair, reals))
    }

    /// The real transforms' half-spectrum buffer.
    pub fn half_buf<'a>(&self, work: &'a mut Work) -> Result<&'a mut [Complex<T>]> {
        view::<Complex<T>>(&mut work.half, self.na * self.hs)
    }

    /// Inverse of a slice: `w` (the inverse's work buffer) holds the values at
    /// `(M mod na) rs + (M' mod ng)`, zero elsewhere; its columns `|M'| <= N` over alpha in
    /// place, then its rows over gamma into `out`.
    ///
    /// # Safety
    /// `w` is [`FftStage::inv_buf`]'s; `out` is valid for writes of `na ng` values, nobody
    /// else's meanwhile.
    pub unsafe fn inverse(&self, w: &mut [Complex<T>], out: *mut Complex<T>, seen: Seen<T>) {
        let w = w.as_mut_ptr();
        for (plan, at) in self.inv_cols.iter().zip([0, self.ng - self.n]) {
            if let Some(p) = plan {
                // SAFETY: the plan was made at this offset of a page-aligned buffer of
                // the same size (same alignment); the work buffer is this worker's.
                unsafe { T::execute_dft(p.0, w.add(at), w.add(at)) };
            }
        }
        match &self.inv_rows {
            // SAFETY: as for the columns; then `out` holds the slice's `na` rows of `ng`
            // values (caller's contract), apart from the work buffer.
            InverseRows::InPlace(p) => unsafe {
                T::execute_dft(p.0, w, w);
                if let Some(seen) = seen {
                    let len = (self.na - 1) * self.rs + self.ng;
                    seen(SliceRef::Complex {
                        values: std::slice::from_raw_parts(w, len),
                        row: self.ng,
                        stride: self.rs,
                    });
                }
                copy_rows(
                    w.cast::<T>(),
                    2 * self.rs,
                    out.cast::<T>(),
                    2 * self.ng,
                    self.na,
                    2 * self.ng,
                    true,
                );
            },
            // SAFETY: `out` holds the slice (caller's contract); the variant matches the
            // arrays' alignment; the input rows are only read (out of place).
            InverseRows::IntoSlice(two) => unsafe {
                T::execute_dft(two.pick(w, out), w, out);
                if let Some(seen) = seen {
                    seen(SliceRef::Complex {
                        values: std::slice::from_raw_parts(out, self.na * self.ng),
                        row: self.ng,
                        stride: self.ng,
                    });
                }
            },
        }
    }

    /// Columns of the inverse's work buffer to clear before each slice is placed: `|M'| <=
    /// N` (the others stay zero), or every one where the rows run in place.
    pub fn inverse_clears(&self) -> [std::ops::Range<usize>; 2] {
        if matches!(self.inv_rows, InverseRows::InPlace(_)) {
            [0..self.ng, 0..0]
        } else {
            [0..self.n + 1, self.ng - self.n..self.ng]
        }
    }

    /// Forward of the slice at `inp`: its rows over gamma into `w` (the forward's work
    /// buffer), then the columns `|M'| <= N` over alpha, in place.
    ///
    /// # Safety
    /// `inp` is valid for reads of `na ng` values; `w` is one of [`FftStage::fwd_pair`]'s buffers.
    pub unsafe fn forward(&self, w: &mut [Complex<T>], inp: *const Complex<T>) {
        let w = w.as_mut_ptr();
        // SAFETY: `inp` holds the slice's `na` rows of `ng` values and is only read; the
        // work buffer (`na` rows of `rs`) is this worker's; the plan was made in place on a
        // same-size page-aligned buffer.
        unsafe {
            copy_rows(
                inp.cast::<T>(),
                2 * self.ng,
                w.cast::<T>(),
                2 * self.rs,
                self.na,
                2 * self.ng,
                false,
            );
            T::execute_dft(self.fwd_rows_in_place.0, w, w);
        }
        for (plan, at) in self.fwd_cols.iter().zip([0, self.ng - self.n]) {
            if let Some(p) = plan {
                // SAFETY: as in `inverse`: same offset in a same-size page-aligned buffer.
                unsafe { T::execute_dft(p.0, w.add(at), w.add(at)) };
            }
        }
    }

    /// Real inverse: `w` (the half buffer) holds `conj(G[M][M'])` at `(M mod na) hs + M'`
    /// for `0 <= M' <= N`, zero elsewhere; its columns over alpha (sign +1), then the rows
    /// `c2r` into `out` (`na ng` reals). `w` is destroyed.
    ///
    /// # Safety
    /// `out` valid for writes of `na ng` doubles, nobody else's; the plan is real; `w` is
    /// [`FftStage::half_buf`]'s.
    pub unsafe fn inverse_real(&self, w: &mut [Complex<T>], out: *mut T, seen: Seen<T>) {
        let r = self.real.as_ref().expect("real plans");
        let w = w.as_mut_ptr();
        // SAFETY: plan made on a same-size page-aligned buffer; the buffer is this worker's.
        unsafe { T::execute_dft(r.cols_plus.0, w, w) };
        let o = out.cast::<Complex<T>>();
        // SAFETY: `out` holds the slice's reals (caller's contract); variant by alignment.
        unsafe { T::execute_dft_c2r(r.c2r.pick(w, o), w, out) };
        if let Some(seen) = seen {
            // SAFETY: the reals just written, this caller's alone.
            seen(SliceRef::Real(unsafe {
                std::slice::from_raw_parts(out, self.slice_len())
            }));
        }
    }

    /// [`FftStage::inverse_real`] into the real parts of the complex slice at `out`, whose
    /// imaginary parts are set to 0: the reals go into the slice's first half, then move
    /// out to their places from the last one down (each lands at or after where it was
    /// read, in the cache).
    ///
    /// # Safety
    /// As for [`FftStage::inverse_real`], with `out` valid for writes of `na ng` complex
    /// values.
    pub unsafe fn inverse_real_parts(
        &self,
        w: &mut [Complex<T>],
        out: *mut Complex<T>,
        seen: Seen<T>,
    ) {
        let reals = out.cast::<T>();
        // SAFETY: the first `na ng` doubles of the caller's slice (caller's contract).
        unsafe { self.inverse_real(w, reals, seen) };
        for i in (0..self.slice_len()).rev() {
            // SAFETY: `i` and `2 i + 1 < 2 na ng` inside the slice; value `i` is read
            // before anything at or below `2 i` (written only for larger `i`) changes it.
            unsafe {
                let x = *reals.add(i);
                *reals.add(2 * i + 1) = T::ZERO;
                *reals.add(2 * i) = x;
            }
        }
    }

    /// [`FftStage::forward_real`] of the real parts of the `na ng` complex values at `inp`
    /// (the imaginary parts are not read), through `reals` (`na ng` doubles, page-aligned).
    ///
    /// # Safety
    /// `inp` valid for reads of `na ng` complex values; the plan is real; `w` is
    /// [`FftStage::half_buf`]'s; `reals` this caller's.
    pub unsafe fn forward_real_parts(
        &self,
        (w, reals): (&mut [Complex<T>], &mut [T]),
        inp: *const Complex<T>,
    ) {
        for (i, x) in reals[..self.slice_len()].iter_mut().enumerate() {
            // SAFETY: `i < na ng` (caller's contract).
            *x = unsafe { (*inp.add(i)).re };
        }
        // SAFETY: `reals` holds the slice's reals (just written), page-aligned.
        unsafe { self.forward_real(w, reals.as_ptr()) };
    }

    /// Real forward of the `na ng` reals at `inp`: rows `r2c` into `w` (the half buffer),
    /// then its columns `0..=N` over alpha with sign -1.
    ///
    /// # Safety
    /// `inp` valid for reads of `na ng` doubles; the plan is real; `w` is
    /// [`FftStage::half_buf`]'s.
    pub unsafe fn forward_real(&self, w: &mut [Complex<T>], inp: *const T) {
        let r = self.real.as_ref().expect("real plans");
        let w = w.as_mut_ptr();
        let i = inp.cast_mut();
        // SAFETY: `inp` holds the slice and is only read (FFTW_PRESERVE_INPUT); variant
        // by alignment.
        unsafe { T::execute_dft_r2c(r.r2c.pick(i.cast(), w), i, w) };
        // SAFETY: as in `inverse_real`.
        unsafe { T::execute_dft(r.cols_minus.0, w, w) };
    }
}
