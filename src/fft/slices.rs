//! The slice transforms: an in-place complex `n x n` DFT of a padded slice, and the
//! real-data `r2c` / `c2r` pair.

use super::buf::{slice_stride, AlignedBuf};
use super::planner::{plan_slice, RawPlan};
use super::Rigor;
use crate::error::Result;
use fftw_sys as fftw;
use num_complex::Complex64;

/// Plan one in-place `n x n` DFT of a slice with rows [`slice_stride`]`(n)` apart; with
/// `nthreads > 1` the plan runs on FFTW's own threads (see [`plan_slice`] for what that
/// does to FFTW's process-wide setting).
fn plan_complex(n: usize, sign: i32, flags: u32, nthreads: usize) -> Result<RawPlan> {
    // Planning may write to the array (FFTW_MEASURE): plan on scratch memory.
    let rs = slice_stride(n);
    let scratch = AlignedBuf::new(n * rs)?;
    let dims = [
        fftw::fftw_iodim {
            n: n as i32,
            is: rs as i32,
            os: rs as i32,
        },
        fftw::fftw_iodim {
            n: n as i32,
            is: 1,
            os: 1,
        },
    ];
    let data = scratch.as_mut_ptr();
    plan_slice(n, nthreads, || {
        // SAFETY: under the planner lock (plan_slice); `dims` describes `n` rows of `n`
        // values `rs` apart, all inside the `n * rs` values of `scratch`, which outlives the
        // call; FFTW keeps no pointer to `dims` or the array after planning.
        unsafe {
            fftw::fftw_plan_guru_dft(
                2,
                dims.as_ptr(),
                0,
                std::ptr::null(),
                data,
                data,
                sign,
                flags,
            )
        }
    })
}

/// In-place `n x n` complex DFT of one beta slice in the FFT scratch, rows
/// [`slice_stride`]`(n)` apart.
pub(crate) struct SliceFft {
    aligned: RawPlan,
    /// Plan for arrays not aligned as FFTW's SIMD code wants (FFTW_UNALIGNED, planned
    /// with FFTW_ESTIMATE, on as many threads). The scratch slices always are aligned;
    /// this is a safety net.
    unaligned: RawPlan,
}

impl SliceFft {
    /// A plan for one slice; `nthreads > 1` makes it run on FFTW's own threads.
    pub fn new(n: usize, sign: i32, rigor: Rigor, nthreads: usize) -> Result<SliceFft> {
        Ok(SliceFft {
            aligned: plan_complex(n, sign, rigor.flags(), nthreads)?,
            unaligned: plan_complex(
                n,
                sign,
                fftw::FFTW_ESTIMATE | fftw::FFTW_UNALIGNED,
                nthreads,
            )?,
        })
    }

    /// Transform the slice at `data` in place.
    ///
    /// # Safety
    /// `data` is valid for reads and writes of `n * slice_stride(n)` values, not accessed by
    /// anyone else during the call.
    pub unsafe fn in_place(&self, data: *mut Complex64) {
        // SAFETY: fftw_alignment_of only inspects the address.
        let plan = if unsafe { fftw::fftw_alignment_of(data.cast::<f64>()) } == 0 {
            &self.aligned
        } else {
            &self.unaligned
        };
        // SAFETY: the plan was made for this layout (`n` rows `slice_stride(n)` apart, in
        // place) and for `data`'s alignment class; `data` covers the extent (this
        // function's contract); new-array execute is thread-safe.
        unsafe { fftw::fftw_execute_dft(plan.0, data, data) };
    }
}

/// Plan one `n x n` real-to-complex (`r2c`) or complex-to-real (`c2r`) DFT, single-threaded.
fn plan_real(n: usize, r2c: bool, flags: u32) -> Result<RawPlan> {
    // Scratch for planning (FFTW_MEASURE writes): room for n^2 reals or n(n/2+1) complex.
    let input = AlignedBuf::new(n * n)?;
    let output = AlignedBuf::new(n * n)?;
    plan_slice(n, 1, || {
        // SAFETY: under the planner lock (plan_slice); both scratch buffers hold `n * n` complex values,
        // more than either layout needs, and outlive the call.
        unsafe {
            if r2c {
                fftw::fftw_plan_dft_r2c_2d(
                    n as i32,
                    n as i32,
                    input.as_mut_ptr().cast::<f64>(),
                    output.as_mut_ptr(),
                    flags | fftw::FFTW_PRESERVE_INPUT,
                )
            } else {
                // A multi-dimensional c2r cannot preserve its input; ours is scratch.
                fftw::fftw_plan_dft_c2r_2d(
                    n as i32,
                    n as i32,
                    input.as_mut_ptr(),
                    output.as_mut_ptr().cast::<f64>(),
                    flags,
                )
            }
        }
    })
}

/// Real-data slice transforms: `r2c` (FFTW sign -1, output `n x (n/2+1)`) and its
/// inverse-direction `c2r` (sign +1), each with an aligned and an unaligned variant.
pub(crate) struct SliceFftReal {
    r2c: RawPlan,
    r2c_unaligned: RawPlan,
    c2r: RawPlan,
    c2r_unaligned: RawPlan,
}

impl SliceFftReal {
    /// The four plans of an `n x n` slice (single-threaded).
    pub fn new(n: usize, rigor: Rigor) -> Result<SliceFftReal> {
        let unaligned = fftw::FFTW_ESTIMATE | fftw::FFTW_UNALIGNED;
        Ok(SliceFftReal {
            r2c: plan_real(n, true, rigor.flags())?,
            r2c_unaligned: plan_real(n, true, unaligned)?,
            c2r: plan_real(n, false, rigor.flags())?,
            c2r_unaligned: plan_real(n, false, unaligned)?,
        })
    }

    /// `n*n` reals at `inp` to `n*(n/2+1)` complex values at `out`.
    ///
    /// # Safety
    /// `inp` is valid for reading `n*n` reals and `out` for writing `n*(n/2+1)` complex
    /// values; they do not overlap, and `out` is not accessed by anyone else during the call.
    pub unsafe fn r2c(&self, inp: *const f64, out: *mut Complex64) {
        // SAFETY: fftw_alignment_of only inspects the addresses.
        let aligned = unsafe {
            fftw::fftw_alignment_of(inp.cast_mut()) == 0
                && fftw::fftw_alignment_of(out.cast::<f64>()) == 0
        };
        let plan = if aligned {
            &self.r2c
        } else {
            &self.r2c_unaligned
        };
        // SAFETY: the plan was made for these extents and this alignment class; the
        // pointers cover them (this function's contract); FFTW_PRESERVE_INPUT: `inp` is
        // only read.
        unsafe { fftw::fftw_execute_dft_r2c(plan.0, inp.cast_mut(), out) };
    }

    /// `n*(n/2+1)` complex values at `inp` (destroyed) to `n*n` reals at `out`.
    ///
    /// # Safety
    /// `inp` is valid for reading and writing `n*(n/2+1)` complex values and `out` for
    /// writing `n*n` reals; they do not overlap and neither is accessed by anyone else during
    /// the call.
    pub unsafe fn c2r(&self, inp: *mut Complex64, out: *mut f64) {
        // SAFETY: fftw_alignment_of only inspects the addresses.
        let aligned = unsafe {
            fftw::fftw_alignment_of(inp.cast::<f64>()) == 0 && fftw::fftw_alignment_of(out) == 0
        };
        let plan = if aligned {
            &self.c2r
        } else {
            &self.c2r_unaligned
        };
        // SAFETY: the plan was made for these extents and this alignment class; the
        // pointers cover them (this function's contract).
        unsafe { fftw::fftw_execute_dft_c2r(plan.0, inp, out) };
    }
}
