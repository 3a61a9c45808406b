//! The FFTW calls the library makes, for both precisions: [`FftwApi`], implemented by `f64`
//! (FFTW's `fftw_*`, libfftw3) and `f32` (`fftwf_*`, libfftw3f). The two libraries are
//! separate FFTW instances: each has its own planner, wisdom and thread setting.
//!
//! The functions mirror FFTW's signatures one for one, so a call
//! `fftw::fftw_plan_many_dft(..)` becomes `T::plan_many_dft(..)` in code generic over the
//! element type. FFTW's rules apply: planner calls (plan creation and destruction, wisdom,
//! thread setting) only under the planner lock (`planner::planner_lock`), new-array executes
//! from any thread.

use crate::numeric::Elem;
use fftw_sys as fftw;
use num_complex::Complex;
use std::ffi::{c_char, c_int, c_uint, CStr};

/// FFTW of one precision (crate-private: a supertrait of the sealed [`Real`](crate::Real),
/// implemented by exactly `f64` and `f32`). Complex values are `Complex<Self>`, which is
/// layout-compatible with FFTW's `fftw_complex` / `fftwf_complex`.
///
/// Every function is FFTW's function of the same name with the library's prefix; the
/// safety contracts are FFTW's (arrays covering the planned extent, planner calls under the
/// planner lock).
pub trait FftwApi: Elem {
    /// FFTW's opaque plan structure (`fftw_plan_s` / `fftwf_plan_s`); a plan is a pointer to
    /// it.
    type PlanS;
    /// The name of `int fftw_planner_nthreads(void)` (FFTW 3.3.9 on, looked up at run time).
    const PLANNER_NTHREADS: &'static CStr;

    /// `fftw_plan_many_dft`.
    ///
    /// # Safety
    /// Under the planner lock; `input` and `output` cover the described extents (`n`,
    /// `inembed` and `onembed` valid for `rank` values each, or null embeds).
    #[allow(clippy::too_many_arguments)]
    unsafe fn plan_many_dft(
        rank: c_int,
        n: *const c_int,
        howmany: c_int,
        input: *mut Complex<Self>,
        inembed: *const c_int,
        istride: c_int,
        idist: c_int,
        output: *mut Complex<Self>,
        onembed: *const c_int,
        ostride: c_int,
        odist: c_int,
        sign: c_int,
        flags: c_uint,
    ) -> *mut Self::PlanS;

    /// `fftw_plan_many_dft_r2c`.
    ///
    /// # Safety
    /// As for [`FftwApi::plan_many_dft`], reals in and complex values out.
    #[allow(clippy::too_many_arguments)]
    unsafe fn plan_many_dft_r2c(
        rank: c_int,
        n: *const c_int,
        howmany: c_int,
        input: *mut Self,
        inembed: *const c_int,
        istride: c_int,
        idist: c_int,
        output: *mut Complex<Self>,
        onembed: *const c_int,
        ostride: c_int,
        odist: c_int,
        flags: c_uint,
    ) -> *mut Self::PlanS;

    /// `fftw_plan_many_dft_c2r`.
    ///
    /// # Safety
    /// As for [`FftwApi::plan_many_dft`], complex values in and reals out.
    #[allow(clippy::too_many_arguments)]
    unsafe fn plan_many_dft_c2r(
        rank: c_int,
        n: *const c_int,
        howmany: c_int,
        input: *mut Complex<Self>,
        inembed: *const c_int,
        istride: c_int,
        idist: c_int,
        output: *mut Self,
        onembed: *const c_int,
        ostride: c_int,
        odist: c_int,
        flags: c_uint,
    ) -> *mut Self::PlanS;

    /// `fftw_execute_dft`: the complex plan `p` on new arrays.
    ///
    /// # Safety
    /// `p` is a live complex plan; the arrays have the planned extent, layout, in-place-ness
    /// and alignment class (see [`FftwApi::alignment_of`]).
    unsafe fn execute_dft(
        p: *mut Self::PlanS,
        input: *mut Complex<Self>,
        output: *mut Complex<Self>,
    );

    /// `fftw_execute_dft_r2c`.
    ///
    /// # Safety
    /// As for [`FftwApi::execute_dft`], with an r2c plan.
    unsafe fn execute_dft_r2c(p: *mut Self::PlanS, input: *mut Self, output: *mut Complex<Self>);

    /// `fftw_execute_dft_c2r`.
    ///
    /// # Safety
    /// As for [`FftwApi::execute_dft`], with a c2r plan.
    unsafe fn execute_dft_c2r(p: *mut Self::PlanS, input: *mut Complex<Self>, output: *mut Self);

    /// `fftw_alignment_of`: 0 where `p` is aligned as FFTW's SIMD code wants.
    ///
    /// # Safety
    /// None beyond FFTW's: it only inspects the address.
    unsafe fn alignment_of(p: *mut Self) -> c_int;

    /// `fftw_destroy_plan`.
    ///
    /// # Safety
    /// Under the planner lock; `p` is a live plan of this library, destroyed once, with no
    /// execution running.
    unsafe fn destroy_plan(p: *mut Self::PlanS);

    /// `fftw_plan_with_nthreads`.
    ///
    /// # Safety
    /// Under the planner lock; the library's threads were initialised (by the host, for a
    /// count above 1).
    unsafe fn plan_with_nthreads(nthreads: c_int);

    /// `fftw_make_planner_thread_safe` (in the threads library).
    ///
    /// # Safety
    /// Not while a planner call of this library runs unlocked on another thread.
    unsafe fn make_planner_thread_safe();

    /// `fftw_export_wisdom_to_string`: a string from malloc (released with free), or null.
    ///
    /// # Safety
    /// Under the planner lock.
    unsafe fn export_wisdom_to_string() -> *mut c_char;

    /// `fftw_import_wisdom_from_string`: non-zero on success.
    ///
    /// # Safety
    /// Under the planner lock; `wisdom` is NUL-terminated.
    unsafe fn import_wisdom_from_string(wisdom: *const c_char) -> c_int;

    /// `fftw_forget_wisdom`.
    ///
    /// # Safety
    /// Under the planner lock.
    unsafe fn forget_wisdom();
}

/// Implements [`FftwApi`] for the element type `$t` with the plan structure `$plan_s` and
/// the `planner_nthreads` name `$nthreads`: each method calls the fftw-sys function named
/// next to it (written out in full, so that a grep
/// for an FFTW name finds its use).
macro_rules! fftw_api {
    ($t:ty, $plan_s:ty, $nthreads:literal, {
        plan_many_dft: $plan_many_dft:path,
        plan_many_dft_r2c: $plan_many_dft_r2c:path,
        plan_many_dft_c2r: $plan_many_dft_c2r:path,
        execute_dft: $execute_dft:path,
        execute_dft_r2c: $execute_dft_r2c:path,
        execute_dft_c2r: $execute_dft_c2r:path,
        alignment_of: $alignment_of:path,
        destroy_plan: $destroy_plan:path,
        plan_with_nthreads: $plan_with_nthreads:path,
        make_planner_thread_safe: $make_planner_thread_safe:path,
        export_wisdom_to_string: $export_wisdom_to_string:path,
        import_wisdom_from_string: $import_wisdom_from_string:path,
        forget_wisdom: $forget_wisdom:path,
    }) => {
        impl FftwApi for $t {
            type PlanS = $plan_s;
            const PLANNER_NTHREADS: &'static CStr = $nthreads;

            #[inline]
            unsafe fn plan_many_dft(
                rank: c_int,
                n: *const c_int,
                howmany: c_int,
                input: *mut Complex<$t>,
                inembed: *const c_int,
                istride: c_int,
                idist: c_int,
                output: *mut Complex<$t>,
                onembed: *const c_int,
                ostride: c_int,
                odist: c_int,
                sign: c_int,
                flags: c_uint,
            ) -> *mut $plan_s {
                // SAFETY: the caller's contract is FFTW's.
                unsafe {
                    $plan_many_dft(
                        rank, n, howmany, input, inembed, istride, idist, output, onembed, ostride,
                        odist, sign, flags,
                    )
                }
            }

            #[inline]
            unsafe fn plan_many_dft_r2c(
                rank: c_int,
                n: *const c_int,
                howmany: c_int,
                input: *mut $t,
                inembed: *const c_int,
                istride: c_int,
                idist: c_int,
                output: *mut Complex<$t>,
                onembed: *const c_int,
                ostride: c_int,
                odist: c_int,
                flags: c_uint,
            ) -> *mut $plan_s {
                // SAFETY: the caller's contract is FFTW's.
                unsafe {
                    $plan_many_dft_r2c(
                        rank, n, howmany, input, inembed, istride, idist, output, onembed, ostride,
                        odist, flags,
                    )
                }
            }

            #[inline]
            unsafe fn plan_many_dft_c2r(
                rank: c_int,
                n: *const c_int,
                howmany: c_int,
                input: *mut Complex<$t>,
                inembed: *const c_int,
                istride: c_int,
                idist: c_int,
                output: *mut $t,
                onembed: *const c_int,
                ostride: c_int,
                odist: c_int,
                flags: c_uint,
            ) -> *mut $plan_s {
                // SAFETY: the caller's contract is FFTW's.
                unsafe {
                    $plan_many_dft_c2r(
                        rank, n, howmany, input, inembed, istride, idist, output, onembed, ostride,
                        odist, flags,
                    )
                }
            }

            #[inline]
            unsafe fn execute_dft(
                p: *mut $plan_s,
                input: *mut Complex<$t>,
                output: *mut Complex<$t>,
            ) {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $execute_dft(p, input, output) }
            }

            #[inline]
            unsafe fn execute_dft_r2c(p: *mut $plan_s, input: *mut $t, output: *mut Complex<$t>) {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $execute_dft_r2c(p, input, output) }
            }

            #[inline]
            unsafe fn execute_dft_c2r(p: *mut $plan_s, input: *mut Complex<$t>, output: *mut $t) {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $execute_dft_c2r(p, input, output) }
            }

            #[inline]
            unsafe fn alignment_of(p: *mut $t) -> c_int {
                // SAFETY: FFTW only inspects the address.
                unsafe { $alignment_of(p) }
            }

            unsafe fn destroy_plan(p: *mut $plan_s) {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $destroy_plan(p) }
            }

            unsafe fn plan_with_nthreads(nthreads: c_int) {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $plan_with_nthreads(nthreads) }
            }

            unsafe fn make_planner_thread_safe() {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $make_planner_thread_safe() }
            }

            unsafe fn export_wisdom_to_string() -> *mut c_char {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $export_wisdom_to_string() }
            }

            unsafe fn import_wisdom_from_string(wisdom: *const c_char) -> c_int {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $import_wisdom_from_string(wisdom) }
            }

            unsafe fn forget_wisdom() {
                // SAFETY: the caller's contract is FFTW's.
                unsafe { $forget_wisdom() }
            }
        }
    };
}

fftw_api!(f64, fftw::fftw_plan_s, c"fftw_planner_nthreads", {
    plan_many_dft: fftw::fftw_plan_many_dft,
    plan_many_dft_r2c: fftw::fftw_plan_many_dft_r2c,
    plan_many_dft_c2r: fftw::fftw_plan_many_dft_c2r,
    execute_dft: fftw::fftw_execute_dft,
    execute_dft_r2c: fftw::fftw_execute_dft_r2c,
    execute_dft_c2r: fftw::fftw_execute_dft_c2r,
    alignment_of: fftw::fftw_alignment_of,
    destroy_plan: fftw::fftw_destroy_plan,
    plan_with_nthreads: fftw::fftw_plan_with_nthreads,
    make_planner_thread_safe: fftw::fftw_make_planner_thread_safe,
    export_wisdom_to_string: fftw::fftw_export_wisdom_to_string,
    import_wisdom_from_string: fftw::fftw_import_wisdom_from_string,
    forget_wisdom: fftw::fftw_forget_wisdom,
});

fftw_api!(f32, fftw::fftwf_plan_s, c"fftwf_planner_nthreads", {
    plan_many_dft: fftw::fftwf_plan_many_dft,
    plan_many_dft_r2c: fftw::fftwf_plan_many_dft_r2c,
    plan_many_dft_c2r: fftw::fftwf_plan_many_dft_c2r,
    execute_dft: fftw::fftwf_execute_dft,
    execute_dft_r2c: fftw::fftwf_execute_dft_r2c,
    execute_dft_c2r: fftw::fftwf_execute_dft_c2r,
    alignment_of: fftw::fftwf_alignment_of,
    destroy_plan: fftw::fftwf_destroy_plan,
    plan_with_nthreads: fftw::fftwf_plan_with_nthreads,
    make_planner_thread_safe: fftw::fftwf_make_planner_thread_safe,
    export_wisdom_to_string: fftw::fftwf_export_wisdom_to_string,
    import_wisdom_from_string: fftw::fftwf_import_wisdom_from_string,
    forget_wisdom: fftw::fftwf_forget_wisdom,
});
