//! The FFT stage of the S^2 transforms: 1-D DFTs over `phi` of the `2B` rings of the grid,
//! a few rings per FFTW call so that the workers can share the rings.

use crate::error::{Error, Result};
use crate::fft::{plan_guarded, RawPlan, Rigor};
use crate::real::Real;
use num_complex::Complex;
use std::ffi::c_int;

/// Ring DFTs of one bandwidth: complex (in place, rows of `2B` values) in both directions,
/// real `r2c` (rows of `2B` reals into rows of `B + 1` values) and `c2r`, each planned for
/// [`RingFft::per_call`] consecutive rings.
pub(super) struct RingFft<T: Real = f64> {
    n: usize,
    per_call: usize,
    /// Sign -1: `F_m = sum_k f_k e^{-i m phi_k}`.
    analysis: RawPlan<T>,
    /// Sign +1.
    synthesis: RawPlan<T>,
    r2c: RawPlan<T>,
    c2r: RawPlan<T>,
}

impl<T: Real> RingFft<T> {
    /// The DFTs of `n = 2B` points, planned with `rigor` on scratch memory.
    pub(super) fn new(n: usize, rigor: Rigor) -> Result<RingFft<T>> {
        // Rings per call: the largest power of two up to 16 that divides the ring count.
        let per_call = 1usize << n.trailing_zeros().min(4);
        let flags = rigor.flags();
        let len = per_call * n;
        let scratch = crate::fft::AlignedBuf::of::<Complex<T>>(len)?;
        let real_in = crate::fft::AlignedBuf::of::<Complex<T>>(len)?;
        let dims = [n as c_int];
        let (howmany, dist, half) = (per_call as c_int, n as c_int, (n / 2 + 1) as c_int);
        let data = scratch.ptr::<Complex<T>>();
        let complex = |sign: i32| {
            plan_guarded(len, || {
                // SAFETY: under the planner lock (plan_guarded); `per_call` rows of `n` values
                // in `scratch` (which outlives the call); FFTW keeps no pointer to `dims`.
                unsafe {
                    T::plan_many_dft(
                        1,
                        dims.as_ptr(),
                        howmany,
                        data,
                        std::ptr::null(),
                        1,
                        dist,
                        data,
                        std::ptr::null(),
                        1,
                        dist,
                        sign,
                        flags,
                    )
                }
            })
        };
        let reals = real_in.ptr::<T>();
        let r2c = plan_guarded(len, || {
            // SAFETY: as above: `per_call` rows of `n` reals in `real_in` into rows of
            // `n/2 + 1` values in `scratch` (both hold `per_call * n` complex values).
            unsafe {
                T::plan_many_dft_r2c(
                    1,
                    dims.as_ptr(),
                    howmany,
                    reals,
                    std::ptr::null(),
                    1,
                    dist,
                    data,
                    std::ptr::null(),
                    1,
                    half,
                    flags | fftw_sys::FFTW_PRESERVE_INPUT,
                )
            }
        })?;
        let c2r = plan_guarded(len, || {
            // SAFETY: as for `r2c`, in the other direction.
            unsafe {
                T::plan_many_dft_c2r(
                    1,
                    dims.as_ptr(),
                    howmany,
                    data,
                    std::ptr::null(),
                    1,
                    half,
                    reals,
                    std::ptr::null(),
                    1,
                    dist,
                    flags,
                )
            }
        })?;
        Ok(RingFft {
            n,
            per_call,
            analysis: complex(crate::fft::SIGN_MINUS)?,
            synthesis: complex(crate::fft::SIGN_PLUS)?,
            r2c,
            c2r,
        })
    }

    /// Rings per call.
    pub(super) fn per_call(&self) -> usize {
        self.per_call
    }

    /// Whether FFTW's plans may run on data at `p` (aligned as the planned arrays: 16 bytes).
    pub(super) fn aligned(p: *const T) -> bool {
        // SAFETY: fftw_alignment_of only inspects the address.
        unsafe { T::alignment_of(p.cast_mut()) == 0 }
    }

    /// An error unless `p` is aligned as FFTW's plans were made for (see [`RingFft::aligned`]).
    fn check_alignment(p: *const T) -> Result<()> {
        if !Self::aligned(p) {
            return Err(Error::Fftw("ring data not aligned for FFTW".into()));
        }
        Ok(())
    }

    /// Complex DFTs (sign -1 with `analysis`, else +1) of the `per_call` rings at `rows`, in
    /// place.
    ///
    /// # Safety
    /// `rows` is valid for reads and writes of `per_call * 2B` values, used by no one else.
    pub(super) unsafe fn complex(&self, rows: *mut Complex<T>, analysis: bool) -> Result<()> {
        Self::check_alignment(rows.cast())?;
        let plan = if analysis {
            &self.analysis
        } else {
            &self.synthesis
        };
        // SAFETY: the plan's extent and layout (caller's contract); new-array execute is
        // thread-safe.
        unsafe { T::execute_dft(plan.0, rows, rows) };
        Ok(())
    }

    /// `r2c` of `per_call` real rings at `input` (`2B` reals each) into rows of `B + 1`
    /// values at `out`.
    ///
    /// # Safety
    /// `input` is valid for reading `per_call * 2B` reals, `out` for writing
    /// `per_call * (B + 1)` values, not overlapping, `out` used by no one else.
    pub(super) unsafe fn r2c(&self, input: *const T, out: *mut Complex<T>) -> Result<()> {
        Self::check_alignment(input)?;
        Self::check_alignment(out.cast())?;
        // SAFETY: as above; FFTW_PRESERVE_INPUT: `input` is only read.
        unsafe { T::execute_dft_r2c(self.r2c.0, input.cast_mut(), out) };
        Ok(())
    }

    /// `c2r` of `per_call` rows of `B + 1` values at `input` (destroyed) into real rings.
    ///
    /// # Safety
    /// `input` is valid for reads and writes of `per_call * (B + 1)` values, `out` for
    /// writing `per_call * 2B` reals, not overlapping, neither used by anyone else.
    pub(super) unsafe fn c2r(&self, input: *mut Complex<T>, out: *mut T) -> Result<()> {
        Self::check_alignment(input.cast())?;
        Self::check_alignment(out)?;
        // SAFETY: as above.
        unsafe { T::execute_dft_c2r(self.c2r.0, input, out) };
        Ok(())
    }

    /// Points per ring.
    pub(super) fn len(&self) -> usize {
        self.n
    }
}
