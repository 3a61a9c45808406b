//! The matching pipeline's floor (`so3fft-bench match`, the second table): FFTW alone on
//! the grid's slices plus the DWT at its in-cache kernel rate, measured in the same run.
//!
//! - **FFT part**: the `2L` slices of `2L x 2L` of the grid, each a 2-D inverse FFT:
//!   complex, `c2c` in place on complex slices (FFTW's sign -1, as the inverse SO(3)
//!   transform's slices); real, `c2r` from a half spectrum of `2L x (L+1)` complex values
//!   to the real slice, out of place, the half spectra in their own buffer. One FFTW plan
//!   per kind and bandwidth, planned with the pipeline's rigour on an `fftw_malloc` array and
//!   executed with the new-array interface on every slice of `fftw_malloc` arrays (each
//!   slice as aligned as the planning array, checked); the slices split evenly over as many
//!   threads as the pipeline's (a rayon pool, one contiguous range of slices per thread).
//!   No copies, no padding of the slices: FFTW's own floor. The input is rewritten before
//!   every execution, outside the timing (the in-place `c2c` and the `c2r` destroy it).
//!   `match` times `--runs` executions right after the pipeline's runs of the same kind
//!   ([`SliceFloor`]); medians.
//! - **DWT part** (feature `internals`): the DWT stage's nominal flops
//!   (`workload::dwt_flops_exact`, or `dwt_flops_real` for real inputs) divided by the
//!   inverse kernel's rate on one cluster in cache, measured as `benches/kernel_speed.rs`
//!   does ("kernels over all clusters"): every cluster of bandwidth `L` through the inverse
//!   kernel of the selected instruction set, one thread, all `2L` betas (each half padded to whole vectors), ordinary stores
//!   into 64-byte aligned arrays, the kernel time summed over the clusters (each cluster's
//!   best of a few batches); divided by the thread count (the clusters split evenly).
//!
//! FFTW's planner is not thread-safe, and the library serialises its own planner calls
//! through a lock that the binary cannot reach (`pub(crate)` in `src/fft/planner.rs`). The
//! floor's plans are therefore made by [`plan_slices`] at the start of `match`, before any
//! library plan exists: on the main thread, with no other thread running FFTW (the library
//! plans only inside its constructors, called later from this thread), and with FFTW's
//! thread count for new plans at its default of 1 (the library changes it only during its
//! own planner calls, restoring it before they return). The library has also made FFTW's
//! planner thread-safe when it was loaded (`fftw_make_planner_thread_safe`). FFTW's
//! wisdom is forgotten after that planning, so the pipeline's plans are chosen exactly as
//! without the floor. The plans are destroyed by [`SlicePlans`]' `Drop`, again on the main
//! thread between library plans (none is being made or destroyed then).

use fftw_sys as fftw;
use so3fft::{Complex64, Error, Rigor};
use std::time::Instant;

/// An array from `fftw_malloc` (aligned as FFTW's SIMD code wants), freed on drop.
struct FftwBuf<T> {
    ptr: *mut T,
    len: usize,
}

impl<T: Copy> FftwBuf<T> {
    /// `len` values, written with `value(i)` (so the pages are touched here).
    fn new(len: usize, value: impl Fn(usize) -> T) -> so3fft::Result<FftwBuf<T>> {
        let bytes = len
            .checked_mul(std::mem::size_of::<T>())
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?;
        // SAFETY: fftw_malloc takes a size and returns memory of that size or NULL.
        let ptr = unsafe { fftw::fftw_malloc(bytes) }.cast::<T>();
        if ptr.is_null() {
            return Err(Error::OutOfMemory { bytes });
        }
        let mut buf = FftwBuf { ptr, len };
        buf.fill(value);
        Ok(buf)
    }

    /// Writes `value(i)` to every value `i`.
    fn fill(&mut self, value: impl Fn(usize) -> T) {
        for i in 0..self.len {
            // SAFETY: `i < len`, inside the allocation, which `&mut self` holds alone.
            unsafe { self.ptr.add(i).write(value(i)) };
        }
    }

    /// The start of the array (valid for `len` values while `self` lives).
    fn as_mut_ptr(&self) -> *mut T {
        self.ptr
    }
}

impl<T> Drop for FftwBuf<T> {
    fn drop(&mut self) {
        // SAFETY: the pointer came from fftw_malloc and is freed once; no FFTW execution
        // uses it after the timed loops that borrowed `self` have returned.
        unsafe { fftw::fftw_free(self.ptr.cast()) }
    }
}

/// A test value in [-1, 1) for index `i` (cheap, not constant, never subnormal).
fn pattern(i: usize) -> f64 {
    ((i.wrapping_mul(2_654_435_761) >> 7) % 1024) as f64 / 512.0 - 1.0
}

/// Complex test value `i`.
fn complex_value(i: usize) -> Complex64 {
    Complex64::new(pattern(2 * i), pattern(2 * i + 1))
}

/// FFTW's planner flag of a rigour.
fn rigor_flags(rigor: Rigor) -> u32 {
    match rigor {
        Rigor::Estimate => fftw::FFTW_ESTIMATE,
        Rigor::Measure => fftw::FFTW_MEASURE,
        Rigor::Patient => fftw::FFTW_PATIENT,
        Rigor::Exhaustive => fftw::FFTW_EXHAUSTIVE,
    }
}

/// An FFTW plan of the floor, destroyed on drop (see the module documentation for when).
struct FftwPlan(fftw::fftw_plan);

// SAFETY: executing a plan on new arrays is thread-safe in FFTW, from any thread; creation
// and destruction happen on the main thread only (module documentation).
unsafe impl Send for FftwPlan {}
// SAFETY: as for Send: shared references only execute the plan (new-array interface).
unsafe impl Sync for FftwPlan {}

impl FftwPlan {
    fn new(made: fftw::fftw_plan, what: &str) -> so3fft::Result<FftwPlan> {
        if made.is_null() {
            return Err(Error::Fftw(format!("could not plan {what}")));
        }
        Ok(FftwPlan(made))
    }
}

impl Drop for FftwPlan {
    fn drop(&mut self) {
        // SAFETY: the plan was made by FFTW and is owned by this value, destroyed once on
        // the main thread while no FFTW planner call runs (module documentation); no
        // execution runs (the timed loops have returned).
        unsafe { fftw::fftw_destroy_plan(self.0) }
    }
}

/// The floor's FFTW plans of one bandwidth `l`: `2l x 2l` slices.
pub struct SlicePlans {
    l: usize,
    /// In-place complex DFT, sign -1.
    c2c: FftwPlan,
    /// `c2r` from `2l x (l+1)` complex values to `2l x 2l` reals, out of place.
    c2r: FftwPlan,
    /// Whether `c2r` was planned for SIMD-aligned arrays only (not `FFTW_UNALIGNED`).
    c2r_aligned: bool,
}

/// Plans the slice transforms of every bandwidth in `bandwidths`, then forgets FFTW's
/// wisdom. Call before any library plan exists (module documentation).
pub fn plan_slices(bandwidths: &[usize], rigor: Rigor) -> so3fft::Result<Vec<SlicePlans>> {
    let flags = rigor_flags(rigor);
    let mut plans = Vec::new();
    for &l in bandwidths {
        let n = 2 * l;
        let ni = i32::try_from(n).map_err(|_| Error::Fftw(format!("{n} x {n} slices")))?;
        // Planning may overwrite the arrays (FFTW_MEASURE and up): scratch of one slice.
        let slice = FftwBuf::new(n * n, |_| Complex64::default())?;
        let half = FftwBuf::new(n * (l + 1), |_| Complex64::default())?;
        let real = FftwBuf::new(n * n, |_| 0.0f64)?;
        // SAFETY: main thread, no other FFTW planner call can run (module documentation);
        // `slice` holds the n x n values of the in-place transform and outlives the call;
        // FFTW keeps no pointer to the array after planning.
        let c2c = unsafe {
            fftw::fftw_plan_dft_2d(
                ni,
                ni,
                slice.as_mut_ptr(),
                slice.as_mut_ptr(),
                fftw::FFTW_FORWARD,
                flags,
            )
        };
        let c2c = FftwPlan::new(c2c, &format!("an in-place {n} x {n} DFT"))?;
        // Complex slices (64 l^2 bytes) and half spectra (32 l (l+1) bytes) are whole
        // multiples of 64 bytes apart, real slices (32 l^2 bytes) only for even l: for odd
        // l the c2r plan must accept any alignment.
        let c2r_aligned = l % 2 == 0;
        let c2r_flags = flags | if c2r_aligned { 0 } else { fftw::FFTW_UNALIGNED };
        // SAFETY: as above; `half` holds the n (n/2 + 1) complex inputs and `real` the n x n
        // real outputs, distinct arrays.
        let c2r = unsafe {
            fftw::fftw_plan_dft_c2r_2d(ni, ni, half.as_mut_ptr(), real.as_mut_ptr(), c2r_flags)
        };
        let c2r = FftwPlan::new(c2r, &format!("an {n} x {n} c2r DFT"))?;
        // SAFETY: the addresses are only inspected.
        let aligned = unsafe {
            [
                fftw::fftw_alignment_of(slice.as_mut_ptr().cast()),
                fftw::fftw_alignment_of(half.as_mut_ptr().cast()),
                fftw::fftw_alignment_of(real.as_mut_ptr()),
            ]
        };
        assert_eq!(aligned, [0; 3], "fftw_malloc arrays are SIMD-aligned");
        plans.push(SlicePlans {
            l,
            c2c,
            c2r,
            c2r_aligned,
        });
    }
    // The library's call, under its planner lock; existing plans stay valid.
    so3fft::wisdom::forget();
    Ok(plans)
}

/// The plans of bandwidth `l` among `plans`.
pub fn plans_for(plans: &[SlicePlans], l: usize) -> &SlicePlans {
    plans
        .iter()
        .find(|p| p.l == l)
        .expect("a plan for every bandwidth")
}

/// Addresses shared by the threads of one execution; every thread writes only its own
/// slices.
#[derive(Clone, Copy)]
struct Arrays {
    input: *mut Complex64,
    real_out: *mut f64,
}

// SAFETY: the threads of `time_slices` touch disjoint slices of the arrays, which
// outlive the broadcast that uses them.
unsafe impl Send for Arrays {}
// SAFETY: as for Send.
unsafe impl Sync for Arrays {}

/// The FFT part of the floor at one bandwidth and thread count: its arrays, its threads,
/// and one timed execution at a time.
pub struct SliceFloor<'a> {
    plans: &'a SlicePlans,
    pool: rayon::ThreadPool,
    /// The complex slices (`c2c` in place).
    grid: FftwBuf<Complex64>,
    /// The half spectra (`c2r` input).
    spectra: FftwBuf<Complex64>,
    /// The real slices (`c2r` output).
    rgrid: FftwBuf<f64>,
}

impl<'a> SliceFloor<'a> {
    /// The arrays of bandwidth `plans.l` and a pool of `threads` threads (0 = all cores);
    /// one untimed execution of each kind.
    pub fn new(plans: &'a SlicePlans, threads: usize) -> so3fft::Result<SliceFloor<'a>> {
        let threads = if threads == 0 {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        } else {
            threads
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| Error::Resources(format!("cannot start {threads} threads: {e}")))?;
        let (l, n) = (plans.l, 2 * plans.l);
        let (slice, half) = (n * n, n * (l + 1));
        let mut floor = SliceFloor {
            plans,
            pool,
            grid: FftwBuf::new(n * slice, complex_value)?,
            spectra: FftwBuf::new(n * half, complex_value)?,
            rgrid: FftwBuf::new(n * slice, |_| 0.0f64)?,
        };
        // Every slice as aligned as the planning arrays, as the plans were made for (the
        // real slices only where `c2r_aligned`, see `plan_slices`).
        for s in 0..n {
            // SAFETY: slice `s` starts inside each array; the addresses are only inspected.
            let aligned = unsafe {
                [
                    fftw::fftw_alignment_of(floor.grid.as_mut_ptr().add(s * slice).cast()),
                    fftw::fftw_alignment_of(floor.spectra.as_mut_ptr().add(s * half).cast()),
                    if plans.c2r_aligned {
                        fftw::fftw_alignment_of(floor.rgrid.as_mut_ptr().add(s * slice))
                    } else {
                        0
                    },
                ]
            };
            assert_eq!(aligned, [0; 3], "slice {s} aligned as planned");
        }
        floor.complex();
        floor.real();
        Ok(floor)
    }

    /// Seconds of one execution of the complex slices' in-place `c2c` (the input rewritten
    /// before, untimed).
    pub fn complex(&mut self) -> f64 {
        let (n, plan) = (2 * self.plans.l, &self.plans.c2c);
        let slice = n * n;
        let arrays = Arrays {
            input: self.grid.as_mut_ptr(),
            real_out: std::ptr::null_mut(),
        };
        time_slices(&self.pool, n, &mut self.grid, arrays, |a, s| {
            // SAFETY: the plan is an in-place n x n DFT planned on an array of this
            // alignment class (checked in `new`); slice `s` (n * n values) lies inside the
            // grid and only this thread touches it during the execution; new-array execute
            // is thread-safe.
            unsafe {
                let p = a.input.add(s * slice);
                fftw::fftw_execute_dft(plan.0, p, p)
            }
        })
    }

    /// Seconds of one execution of the `c2r` of every half spectrum into its real slice
    /// (the half spectra rewritten before, untimed).
    pub fn real(&mut self) -> f64 {
        let (l, plan) = (self.plans.l, &self.plans.c2r);
        let (slice, half) = (4 * l * l, 2 * l * (l + 1));
        let arrays = Arrays {
            input: self.spectra.as_mut_ptr(),
            real_out: self.rgrid.as_mut_ptr(),
        };
        time_slices(&self.pool, 2 * l, &mut self.spectra, arrays, |a, s| {
            // SAFETY: the plan is a 2l x 2l c2r from 2l (l+1) complex values to 4 l^2
            // reals, planned on arrays of these alignment classes (checked in `new`) or
            // for any (odd l); half spectrum `s` and real slice `s` lie inside their arrays,
            // do not overlap, and only this thread touches them during the execution;
            // new-array execute is thread-safe.
            unsafe {
                fftw::fftw_execute_dft_c2r(plan.0, a.input.add(s * half), a.real_out.add(s * slice))
            }
        })
    }
}

/// Seconds of one execution of the `n` slices on `pool`: thread `i` of `k` runs
/// `exec(arrays, s)` for its slices `s` in `i n / k .. (i+1) n / k`. `input` is rewritten
/// first, outside the timing.
fn time_slices(
    pool: &rayon::ThreadPool,
    n: usize,
    input: &mut FftwBuf<Complex64>,
    arrays: Arrays,
    exec: impl Fn(Arrays, usize) + Sync,
) -> f64 {
    input.fill(complex_value);
    let t = Instant::now();
    pool.broadcast(|ctx| {
        let (i, k) = (ctx.index(), ctx.num_threads());
        for s in i * n / k..(i + 1) * n / k {
            exec(arrays, s);
        }
    });
    t.elapsed().as_secs_f64()
}

/// Calls of the kernel per timed batch at bandwidth `l` (a batch of at least about 10 us
/// at small `l`, where one call takes well under a microsecond).
#[cfg(feature = "internals")]
fn calls_per_batch(l: usize) -> usize {
    ((1usize << 14) / (l * l)).max(1)
}

/// Timed batches per cluster; the best one counts.
#[cfg(feature = "internals")]
const BATCHES: usize = 3;

/// The DWT part's measurement at bandwidth `l`: the inverse kernel's time summed over every
/// cluster of `l` (all `2l` betas, each half padded to whole vectors, one thread, each cluster's inputs in cache; per cluster
/// the best of [`BATCHES`] batches of [`calls_per_batch`] calls, per call), as
/// `benches/kernel_speed.rs`'s "kernels over all clusters". The in-cache kernel rate is
/// `dwt_flops_exact(l)` over it. `None` without the feature `internals`.
#[cfg(feature = "internals")]
pub fn dwt_kernel_seconds(l: usize) -> so3fft::Result<Option<f64>> {
    use so3fft::internals::{
        cluster_pairs, grid_lanes, inverse, ClusterInputs, ClusterTables, Rec,
    };
    let isa = so3fft::Isa::selected()?;
    // The betas of each half padded to whole vectors, as in the plans' chunks (all `2l`
    // betas when the vector width divides `l`).
    let half = l.next_multiple_of(isa.lanes());
    let nbs = 2 * half;
    let tables = ClusterTables::new(l);
    let calls = calls_per_batch(l);
    // Input rows and output from a 64-byte boundary, as the plan's chunk buffers (with a
    // Vec's own alignment the kernel's time varies from run to run, up to 2.5x at L = 16).
    let (mut fbuf, mut ybuf) = (vec![0.0; (l + 8) * 16 + 8], vec![0.0; nbs * 16 + 8]);
    let f = aligned_mut(&mut fbuf);
    let y = aligned_mut(&mut ybuf);
    let mut total = 0.0;
    for (m, mp) in cluster_pairs(l) {
        let (m, mp) = (m as usize, mp as usize);
        let n = l - m;
        let ClusterInputs {
            coeffs: rc,
            tau: x,
            p,
            sc,
        } = tables.setup(m, mp, nbs);
        let rec = Rec::new(&rc, n);
        let mut lanes = grid_lanes(&x, &p, &sc, half);
        // Ordinary stores: the output stays in cache (non-temporal stores, the fixtures'
        // default, cost 2.5x at L = 16 and 5% at L = 128 here).
        lanes.stream = false;
        let pw = if m == mp || mp == 0 { 8 } else { 16 };
        let mut best = f64::INFINITY;
        for _ in 0..BATCHES {
            let t = Instant::now();
            for _ in 0..calls {
                inverse(
                    isa,
                    pw,
                    &rec,
                    &lanes,
                    &mut f[..n * pw],
                    &mut |_, _, _| {},
                    &mut y[..nbs * pw],
                );
            }
            best = best.min(t.elapsed().as_secs_f64() / calls as f64);
        }
        total += best;
    }
    std::hint::black_box(y);
    Ok(Some(total))
}

/// `buf` from its first 64-byte boundary (`buf` has 8 values to spare).
#[cfg(feature = "internals")]
fn aligned_mut(buf: &mut [f64]) -> &mut [f64] {
    let skip = buf.as_ptr().align_offset(64);
    let len = buf.len() - 8;
    &mut buf[skip..][..len]
}

/// Without the feature `internals` the kernels cannot be reached: no DWT part.
#[cfg(not(feature = "internals"))]
pub fn dwt_kernel_seconds(_l: usize) -> so3fft::Result<Option<f64>> {
    Ok(None)
}
