//! The FFT layer in both precisions against independent truth: batches of 1-D DFTs planned
//! and executed through [`FftwApi`] (the calls generic code makes) compared with direct
//! summation of the DFT in f64; and the host's FFTW thread setting of each library kept.

use super::planner::{planner_lock, planner_nthreads};
use super::{plan_guarded, AlignedBuf, FftwApi, RawPlan, SIGN_MINUS, SIGN_PLUS};
use crate::error::Result;
use crate::real::Real;
use num_complex::{Complex, Complex64};
use std::ffi::c_int;

/// A batch of `howmany` 1-D DFTs of `n` points, `stride` apart within one and `dist` from
/// one to the next (on both sides).
#[derive(Clone, Copy, Debug)]
pub(super) struct Batch {
    pub n: usize,
    pub howmany: usize,
    pub stride: usize,
    pub dist: usize,
}

impl Batch {
    /// Values the batch spans.
    pub fn extent(&self) -> usize {
        (self.n - 1) * self.stride + (self.howmany - 1) * self.dist + 1
    }

    /// Index of point `j` of transform `t`.
    fn at(&self, t: usize, j: usize) -> usize {
        t * self.dist + j * self.stride
    }
}

/// Plans the complex batch `b` in place at `data` with `sign` and FFTW `flags`, through
/// the generic layer.
///
/// # Safety
/// `data` is valid for `b.extent()` values.
pub(super) unsafe fn plan_dft<T: Real>(
    b: Batch,
    data: *mut Complex<T>,
    sign: i32,
    flags: u32,
) -> Result<RawPlan<T>> {
    let dims = [b.n as c_int];
    plan_guarded(b.n * b.howmany, || {
        // SAFETY: under the planner lock (plan_guarded); the batch stays inside `data`
        // (caller's contract); FFTW keeps no pointer to `dims`.
        unsafe {
            T::plan_many_dft(
                1,
                dims.as_ptr(),
                b.howmany as c_int,
                data,
                std::ptr::null(),
                b.stride as c_int,
                b.dist as c_int,
                data,
                std::ptr::null(),
                b.stride as c_int,
                b.dist as c_int,
                sign,
                flags,
            )
        }
    })
}

/// Deterministic values in [-1, 1) (a small LCG).
fn values(seed: u64, len: usize) -> Vec<f64> {
    let mut x = seed;
    (0..len)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

/// `sum_j x_j e^{sign 2 pi i j k / n}`, in f64.
fn direct_dft(x: &[Complex64], sign: i32) -> Vec<Complex64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            x.iter()
                .enumerate()
                .map(|(j, &v)| {
                    let phase =
                        sign as f64 * std::f64::consts::TAU * ((j * k) % n) as f64 / n as f64;
                    v * Complex64::from_polar(1.0, phase)
                })
                .sum()
        })
        .collect()
}

/// `max |a - b| / max |b|`.
fn rel_err(a: &[Complex64], b: &[Complex64]) -> f64 {
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max);
    d / b.iter().map(|y| y.norm()).fold(0.0, f64::max)
}

/// The accuracy asked of a DFT of `n` points in `T`: a few units of roundoff per stage.
fn tolerance<T: Real>(n: usize) -> f64 {
    4.0 * T::EPSILON.to_f64() * (n as f64).log2().max(1.0)
}

/// A widened complex value.
fn wide<T: Real>(z: Complex<T>) -> Complex64 {
    Complex64::new(z.re.to_f64(), z.im.to_f64())
}

/// The batch `b` planned in `T` (in place), forward (sign -1) then backward (+1): each
/// step equals direct summation, in f64, of the values it was given.
fn complex_batch<T: Real>(b: Batch) {
    let mut buf = AlignedBuf::of::<Complex<T>>(b.extent()).unwrap();
    let data = buf.ptr::<Complex<T>>();
    // SAFETY: `buf` holds the batch's extent.
    let fwd = unsafe { plan_dft::<T>(b, data, SIGN_MINUS, fftw_sys::FFTW_ESTIMATE) }.unwrap();
    // SAFETY: as above.
    let bwd = unsafe { plan_dft::<T>(b, data, SIGN_PLUS, fftw_sys::FFTW_ESTIMATE) }.unwrap();
    let v = values(b.n as u64 * 31 + b.howmany as u64, 2 * b.n * b.howmany);
    let view = buf.view_mut::<Complex<T>>(b.extent());
    for t in 0..b.howmany {
        for j in 0..b.n {
            let k = 2 * (t * b.n + j);
            view[b.at(t, j)] = Complex::new(T::from_f64(v[k]), T::from_f64(v[k + 1]));
        }
    }
    let rows = |view: &[Complex<T>]| -> Vec<Vec<Complex64>> {
        (0..b.howmany)
            .map(|t| (0..b.n).map(|j| wide(view[b.at(t, j)])).collect())
            .collect()
    };
    let input = rows(view);
    for (plan, sign) in [(&fwd, SIGN_MINUS), (&bwd, SIGN_PLUS)] {
        let given = rows(buf.view_mut::<Complex<T>>(b.extent()));
        // SAFETY: the plan was made in place on this buffer, which holds its extent.
        unsafe { T::execute_dft(plan.0, data, data) };
        let got = rows(buf.view_mut::<Complex<T>>(b.extent()));
        for t in 0..b.howmany {
            let e = rel_err(&got[t], &direct_dft(&given[t], sign));
            assert!(
                e < tolerance::<T>(b.n),
                "{} {b:?} sign {sign} row {t}: {e:e}",
                T::NAME
            );
        }
    }
    // Forward then backward is `n` times the input.
    let back = rows(buf.view_mut::<Complex<T>>(b.extent()));
    for t in 0..b.howmany {
        let scaled: Vec<_> = input[t].iter().map(|z| z * b.n as f64).collect();
        let e = rel_err(&back[t], &scaled);
        assert!(
            e < 2.0 * tolerance::<T>(b.n),
            "{} {b:?} round trip row {t}: {e:e}",
            T::NAME
        );
    }
}

/// Rows (stride 1, padded rows as in the FFT stage's work buffers) and columns (stride of
/// a padded row, consecutive columns) of a few sizes, in both precisions.
#[test]
fn complex_batches_match_direct_sums() {
    let batches = [
        Batch {
            n: 16,
            howmany: 3,
            stride: 1,
            dist: 16 + 4,
        },
        Batch {
            n: 12,
            howmany: 5,
            stride: 1,
            dist: 12,
        },
        Batch {
            n: 10,
            howmany: 4,
            stride: 10 + 4,
            dist: 1,
        },
        Batch {
            n: 32,
            howmany: 2,
            stride: 1,
            dist: 40,
        },
    ];
    for b in batches {
        complex_batch::<f32>(b);
        complex_batch::<f64>(b);
    }
}

/// `howmany` real rows of `n` reals (`n + pad` apart) r2c into rows of `n / 2 + 1` values
/// (`n / 2 + 1 + pad` apart), then c2r back, in `T`: the half spectrum equals the direct
/// sums (sign -1) of the reals, and the way back gives `n` times the reals.
fn real_batch<T: Real>(n: usize, howmany: usize, pad: usize) {
    let (rd, hd) = (n + pad, n / 2 + 1 + pad);
    let mut reals = AlignedBuf::of::<T>(howmany * rd).unwrap();
    let mut half = AlignedBuf::of::<Complex<T>>(howmany * hd).unwrap();
    let (pr, ph) = (reals.ptr::<T>(), half.ptr::<Complex<T>>());
    let dims = [n as c_int];
    let (h, rd_c, hd_c) = (howmany as c_int, rd as c_int, hd as c_int);
    let flags = fftw_sys::FFTW_ESTIMATE;
    let r2c = plan_guarded::<T>(n * howmany, || {
        // SAFETY: under the planner lock; `howmany` rows of `n` reals `rd` apart in
        // `reals`, and of `n / 2 + 1` values `hd` apart in `half`.
        unsafe {
            T::plan_many_dft_r2c(
                1,
                dims.as_ptr(),
                h,
                pr,
                std::ptr::null(),
                1,
                rd_c,
                ph,
                std::ptr::null(),
                1,
                hd_c,
                flags | fftw_sys::FFTW_PRESERVE_INPUT,
            )
        }
    })
    .unwrap();
    let c2r = plan_guarded::<T>(n * howmany, || {
        // SAFETY: as for r2c, the other way.
        unsafe {
            T::plan_many_dft_c2r(
                1,
                dims.as_ptr(),
                h,
                ph,
                std::ptr::null(),
                1,
                hd_c,
                pr,
                std::ptr::null(),
                1,
                rd_c,
                flags,
            )
        }
    })
    .unwrap();
    let v = values(n as u64 * 7 + 3, n * howmany);
    let r = reals.view_mut::<T>(howmany * rd);
    for t in 0..howmany {
        for j in 0..n {
            r[t * rd + j] = T::from_f64(v[t * n + j]);
        }
    }
    let input: Vec<Vec<f64>> = (0..howmany)
        .map(|t| r[t * rd..t * rd + n].iter().map(|x| x.to_f64()).collect())
        .collect();
    // SAFETY: the plans' extents in the buffers they were made on (same pointers).
    unsafe { T::execute_dft_r2c(r2c.0, pr, ph) };
    let hv = half.view_mut::<Complex<T>>(howmany * hd);
    for t in 0..howmany {
        let got: Vec<_> = hv[t * hd..t * hd + n / 2 + 1]
            .iter()
            .map(|&z| wide(z))
            .collect();
        let x: Vec<_> = input[t].iter().map(|&x| Complex64::new(x, 0.0)).collect();
        let want = &direct_dft(&x, SIGN_MINUS)[..n / 2 + 1];
        let e = rel_err(&got, want);
        assert!(
            e < tolerance::<T>(n),
            "{} r2c n {n} row {t}: {e:e}",
            T::NAME
        );
    }
    // SAFETY: as above.
    unsafe { T::execute_dft_c2r(c2r.0, ph, pr) };
    let r = reals.view_mut::<T>(howmany * rd);
    for t in 0..howmany {
        let got: Vec<_> = r[t * rd..t * rd + n]
            .iter()
            .map(|x| Complex64::new(x.to_f64(), 0.0))
            .collect();
        let want: Vec<_> = input[t]
            .iter()
            .map(|&x| Complex64::new(x * n as f64, 0.0))
            .collect();
        let e = rel_err(&got, &want);
        assert!(
            e < 2.0 * tolerance::<T>(n),
            "{} c2r n {n} row {t}: {e:e}",
            T::NAME
        );
    }
}

#[test]
fn real_batches_match_direct_sums() {
    for (n, howmany, pad) in [(16, 3, 4), (12, 2, 0), (24, 5, 4)] {
        real_batch::<f32>(n, howmany, pad);
        real_batch::<f64>(n, howmany, pad);
    }
}

/// FFTW's alignment classes through the generic layer: page-aligned data is class 0 in both
/// precisions; one value further on is not (4 or 8 bytes off a 16-byte boundary).
#[test]
fn alignment_of_both_precisions() {
    let buf = AlignedBuf::with_bytes(4096).unwrap();
    // SAFETY: fftw_alignment_of only inspects the addresses (all inside `buf`).
    unsafe {
        assert_eq!(f64::alignment_of(buf.ptr::<f64>()), 0);
        assert_eq!(f32::alignment_of(buf.ptr::<f32>()), 0);
        assert_ne!(f64::alignment_of(buf.ptr::<f64>().add(1)), 0);
        assert_ne!(f32::alignment_of(buf.ptr::<f32>().add(1)), 0);
    }
}

/// A host that runs single-precision FFTW on its threads keeps its thread count for new
/// plans: the library plans with 1 (read inside the planner call) and restores the host's
/// count (read after), where FFTW can report it (3.3.9 on). Double precision's setting is
/// a separate one and stays as it was.
#[test]
fn host_fftwf_thread_count_is_kept() {
    let f64_before = {
        let _lock = planner_lock();
        // SAFETY: single-precision FFTW's thread initialisation and setting, under the
        // planner lock as the library's own planner calls.
        unsafe {
            assert_ne!(fftw_sys::fftwf_init_threads(), 0);
            fftw_sys::fftwf_plan_with_nthreads(3);
        }
        planner_nthreads::<f64>()
    };
    // SAFETY: dlsym with a NUL-terminated name in the loaded objects.
    let readable =
        !unsafe { libc::dlsym(libc::RTLD_DEFAULT, c"fftwf_planner_nthreads".as_ptr()) }.is_null();
    let b = Batch {
        n: 20,
        howmany: 3,
        stride: 1,
        dist: 20,
    };
    let mut buf = AlignedBuf::of::<Complex<f32>>(b.extent()).unwrap();
    let data = buf.ptr::<Complex<f32>>();
    let dims = [b.n as c_int];
    let mut inside = 0;
    let plan = plan_guarded::<f32>(b.n * b.howmany, || {
        inside = planner_nthreads::<f32>();
        // SAFETY: under the planner lock; the batch fills `buf`.
        unsafe {
            f32::plan_many_dft(
                1,
                dims.as_ptr(),
                b.howmany as c_int,
                data,
                std::ptr::null(),
                1,
                b.n as c_int,
                data,
                std::ptr::null(),
                1,
                b.n as c_int,
                SIGN_MINUS,
                fftw_sys::FFTW_ESTIMATE,
            )
        }
    })
    .unwrap();
    let after = {
        let _lock = planner_lock();
        planner_nthreads::<f32>()
    };
    if readable {
        assert_eq!(inside, 1, "planned single-threaded");
        assert_eq!(after, 3, "host setting restored");
    } else {
        assert_eq!(
            (inside, after),
            (1, 1),
            "fftwf_planner_nthreads absent: taken as 1"
        );
    }
    assert_eq!(
        planner_nthreads::<f64>(),
        f64_before,
        "double precision untouched"
    );
    // The plan made while the host asked for 3 threads runs (single-threaded) and is right.
    buf.view_mut::<Complex<f32>>(b.extent())[1] = Complex::new(1.0, 0.0);
    // SAFETY: the plan's extent in the buffer it was made on.
    unsafe { f32::execute_dft(plan.0, data, data) };
    let out = buf.view_mut::<Complex<f32>>(b.extent());
    let mut impulse = vec![Complex64::new(0.0, 0.0); b.n];
    impulse[1] = Complex64::new(1.0, 0.0);
    let want = direct_dft(&impulse, SIGN_MINUS);
    let got: Vec<_> = out[..b.n].iter().map(|&z| wide(z)).collect();
    assert!(rel_err(&got, &want) < tolerance::<f32>(b.n));
    drop(plan);
    let _lock = planner_lock();
    // SAFETY: under the planner lock; back to FFTW's default for the other tests.
    unsafe { fftw_sys::fftwf_plan_with_nthreads(1) };
}
