//! [`S2Plan`]: spherical-harmonic transforms of one bandwidth.

use super::layout::{order_start, s2_num_coeffs, s2_num_samples};
use super::legendre::{CoeffRows, Group, LegendreStage, Spectra};
use super::rings::RingFft;
use crate::error::{check_length, Error, Result};
use crate::fft::AlignedBuf;
use crate::options::Options;
use crate::real::Real;
use crate::simd::Isa;
use crate::system::check_headroom;
use crate::transform::StageTimes;
use crate::transform::{Scratch, Transform};
use crate::workers::{lock_free, SendConstPtr, SendPtr, WorkerPool, WORKER_STACK_BYTES};
use num_complex::{Complex, Complex64};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;
use std::time::Instant;

/// Largest bandwidth of the S^2 transforms.
pub const S2_MAX_BANDWIDTH: usize = 4096;

/// Which degrees and orders an [`S2Plan`] computes (default all).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct S2Limits {
    /// Degree limit `L <= B`: only degrees `l < L` are computed (forward: the others are
    /// written as 0; inverse: they are not read). `None`: `B`.
    pub degree_limit: Option<usize>,
    /// Order limit: only orders `|m| <= Mmax` are computed (as for the degree limit).
    /// `None`: all.
    pub order_limit: Option<usize>,
}

/// Spherical-harmonic transforms of bandwidth `B` on SOFT's grid
/// `theta_j = pi (2j+1)/(4B)`, `phi_k = pi k / B` (`j, k < 2B`, sample `j 2B + k`), with
/// orthonormal `Y_l^m` (Condon-Shortley phase) and coefficients in `seanindex` order (see
/// `docs/conventions-s2.md`):
///
/// - forward (analysis): `fhat(l, m) = (pi / B) sum_{j,k} w_B(j) f(theta_j, phi_k) conj(Y_l^m)`,
///   exact for band-limited samples;
/// - inverse (synthesis): `f(theta_j, phi_k) = sum_{l<B} sum_{|m|<=l} fhat(l, m) Y_l^m`.
///
/// Execution takes `&self`; one plan may run on different arrays from several threads.
pub struct S2Plan<T: Real = f64> {
    b: usize,
    threads: usize,
    workers: WorkerPool,
    rings: RingFft<T>,
    legendre: LegendreStage<T>,
    /// Start of each order's coefficient block, indexed by `m + B - 1`.
    starts: Vec<usize>,
    /// Orders `|m| <= order_limit` are computed.
    order_limit: usize,
    /// Ring spectra (`(2B)^2` values), taken by one execution at a time.
    scratch: Mutex<Option<AlignedBuf>>,
    /// A second ring scratch for the real transforms of two fields at once (made on first
    /// use).
    spare: Mutex<Option<AlignedBuf>>,
    /// Per-worker copies of a block of orders' columns (see [`S2Plan::run_orders`]).
    blocks: Vec<Mutex<Vec<Complex<T>>>>,
}

/// Orders per task of the Legendre stage: each ring's values of a block are read as whole
/// cache lines.
const ORDER_BLOCK: usize = 8;

impl<T: Real> S2Plan<T> {
    /// A plan for bandwidth `bandwidth` (`1 ..= S2_MAX_BANDWIDTH`), all degrees and
    /// orders. It reads the options' `threads`, `rigor` and `isa`.
    pub fn new(bandwidth: usize, options: &Options) -> Result<S2Plan<T>> {
        Self::new_on(bandwidth, S2Limits::default(), options, None)
    }

    /// [`S2Plan::new`] computing only the degrees and orders of `limits`.
    pub fn with_limits(bandwidth: usize, limits: S2Limits, options: &Options) -> Result<S2Plan<T>> {
        Self::new_on(bandwidth, limits, options, None)
    }

    /// [`S2Plan::with_limits`] on the workers of `shared` if given (with the plan's thread
    /// count).
    pub(crate) fn new_on(
        bandwidth: usize,
        limits: S2Limits,
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<S2Plan<T>> {
        let b = bandwidth;
        if b == 0 || b > S2_MAX_BANDWIDTH {
            return Err(Error::InvalidBandwidth {
                bandwidth: b,
                max: S2_MAX_BANDWIDTH,
            });
        }
        let threads = crate::workers::thread_count(options.threads)?;
        let isa = Isa::resolve(options.isa)?;
        let n = 2 * b;
        let bytes = Self::memory_needed(b, threads);
        check_headroom(
            bytes
                .saturating_add(threads * WORKER_STACK_BYTES)
                .saturating_add(crate::fft::planning_bytes(16 * n)),
        )?;
        let scratch = AlignedBuf::of::<Complex<T>>(scratch_len(b))?;
        let rings = RingFft::new(n, options.rigor)?;
        let lend = limits.degree_limit.unwrap_or(b);
        if lend == 0 || lend > b {
            return Err(Error::InvalidArgument(format!(
                "degree limit {lend} outside 1..={b} (degrees l < L are computed)"
            )));
        }
        let legendre = LegendreStage::new(b, lend, isa, threads);
        let starts = (-(b as isize - 1)..b as isize)
            .map(|m| order_start(b, m))
            .collect();
        let workers = WorkerPool::shared_or_new(shared, threads)?;
        Ok(S2Plan {
            b,
            threads,
            workers,
            rings,
            legendre,
            starts,
            order_limit: limits.order_limit.unwrap_or(b),
            scratch: Mutex::new(Some(scratch)),
            spare: Mutex::new(None),
            blocks: (0..threads).map(|_| Mutex::new(Vec::new())).collect(),
        })
    }

    /// Bytes a plan of bandwidth `b` on `threads` threads holds (ring scratch, tables,
    /// the Legendre stage's buffers).
    /// Calls on two fields at once (`*_many` with `howmany > 1`, `*_pair`) add a second
    /// ring scratch of the same size, made on their first use and kept with the plan.
    pub fn memory_needed(b: usize, threads: usize) -> usize {
        // The block buffers: two fields' columns of a block of orders per worker.
        let blocks = threads * 2 * (2 * b) * (2 * ORDER_BLOCK) * 2 * T::BYTES;
        2 * T::BYTES * scratch_len(b) + LegendreStage::<T>::bytes(b, threads) + 8 * 2 * b + blocks
    }

    /// The plan's worker threads (for tests).
    #[cfg(test)]
    pub(crate) fn workers(&self) -> &WorkerPool {
        &self.workers
    }

    /// Runs `f` on the plan's worker threads (rayon parallel iterators in `f` use them).
    pub(crate) fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.workers.pool().install(f)
    }

    /// The bandwidth `B`.
    pub fn bandwidth(&self) -> usize {
        self.b
    }

    /// Worker threads.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Number of samples `(2B)^2`.
    pub fn num_samples(&self) -> usize {
        s2_num_samples(self.b)
    }

    /// Number of coefficients `B^2`.
    pub fn num_coeffs(&self) -> usize {
        s2_num_coeffs(self.b)
    }

    /// An error unless the arrays hold `howmany` fields of samples and coefficients.
    fn check(&self, samples: usize, coeffs: usize, howmany: usize) -> Result<()> {
        self.workers.check_process()?;
        if howmany == 0 {
            return Err(Error::InvalidArgument("howmany is 0".into()));
        }
        for (what, each, got) in [
            ("samples", self.num_samples(), samples),
            ("coefficients", self.num_coeffs(), coeffs),
        ] {
            check_length(what, each.saturating_mul(howmany), got)?;
        }
        Ok(())
    }

    /// Runs `f` with the caller's `scratch` if given (checked to hold the ring scratch),
    /// else the plan's ring scratch (and, with `two`, its second one, made on first use),
    /// or with new ones when they are in use.
    fn with_scratch<R>(
        &self,
        (two, scratch): (bool, Option<&Scratch>),
        f: impl FnOnce(&AlignedBuf, Option<&AlignedBuf>) -> Result<R>,
    ) -> Result<R> {
        let len = scratch_len(self.b);
        if let Some(s) = scratch {
            let a = s.holding(2 * T::BYTES * len)?;
            if !two {
                return f(a, None);
            }
        }
        let mut first = try_take(&self.scratch);
        let own = match first.as_mut() {
            Some(g) => g.as_ref(),
            None => None,
        };
        let tmp;
        let a = match own {
            Some(buf) => buf,
            None => {
                tmp = AlignedBuf::of::<Complex<T>>(len)?;
                &tmp
            }
        };
        if !two {
            return f(a, None);
        }
        let mut second = try_take(&self.spare);
        let tmp2;
        let bbuf = match second.as_mut() {
            Some(g) => {
                if g.is_none() {
                    **g = Some(AlignedBuf::of::<Complex<T>>(len)?);
                }
                g.as_ref().expect("just made")
            }
            None => {
                tmp2 = AlignedBuf::of::<Complex<T>>(len)?;
                &tmp2
            }
        };
        f(a, Some(bbuf))
    }

    fn coeff_rows(&self, base: *mut Complex<T>) -> CoeffRows<T> {
        CoeffRows {
            base,
            starts: self.starts.as_ptr(),
            b: self.b,
        }
    }

    /// Ring DFTs of all rings in parallel: complex in place at `data` (`analysis`: sign
    /// -1), each task copying its rings in from or out to another array (`copy`) while
    /// they are in its cache.
    fn rings_complex(
        &self,
        data: *mut Complex<T>,
        analysis: bool,
        copy: RingCopy<T>,
    ) -> Result<()> {
        let (n, per) = (self.rings.len(), self.rings.per_call());
        let base = SendPtr(data);
        (0..n / per).into_par_iter().try_for_each(|c| {
            let (at, len) = (c * per * n, per * n);
            // SAFETY: rings c*per .. (c+1)*per of the (2B)^2 values at `data` and of the
            // copy's array (as long, not overlapping `data`): this task's alone.
            unsafe {
                if let RingCopy::From(src) = copy {
                    std::ptr::copy_nonoverlapping(src.get().add(at), base.get().add(at), len);
                }
                self.rings.complex(base.get().add(at), analysis)?;
                if let RingCopy::To(dst) = copy {
                    std::ptr::copy_nonoverlapping(base.get().add(at), dst.get().add(at), len);
                }
            }
            Ok(())
        })
    }

    /// The Legendre analysis of order `m`, or zeros beyond the degree and order limits.
    ///
    /// # Safety
    /// As for `LegendreStage::analyse`.
    unsafe fn analyse(&self, m: usize, groups: &[Group<T>], factor: f64) {
        // SAFETY: the caller's contract is the stage's.
        unsafe {
            if m <= self.order_limit && self.legendre.computes(m) {
                self.legendre.analyse(m, groups, factor)
            } else {
                self.legendre.zero_order(m, groups, true)
            }
        }
    }

    /// The Legendre synthesis of order `m`, or zero spectra beyond the limits.
    ///
    /// # Safety
    /// As for `LegendreStage::synthesise`.
    unsafe fn synthesise(&self, m: usize, groups: &[Group<T>], factor: f64) {
        // SAFETY: the caller's contract is the stage's.
        unsafe {
            if m <= self.order_limit && self.legendre.computes(m) {
                self.legendre.synthesise(m, groups, factor)
            } else {
                self.legendre.zero_order(m, groups, false)
            }
        }
    }

    /// The column groups of order `m` of a complex field: `m` and, for `m > 0`, `-m`.
    fn complex_groups(m: usize, spectra: Spectra<T>, coef: CoeffRows<T>) -> ([Group<T>; 2], usize) {
        let g = |order: isize| Group {
            spectra,
            coef,
            order,
            partner: false,
        };
        ([g(m as isize), g(-(m as isize))], if m > 0 { 2 } else { 1 })
    }

    /// Forward transform of complex samples (`(2B)^2`, ring-major) into `B^2` coefficients;
    /// the time of each stage (`fft`: the ring DFTs, `dwt`: the Legendre stage).
    pub fn forward(&self, samples: &[Complex<T>], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        self.forward_in((samples, coeffs, 1), None)
    }

    /// [`S2Plan::forward`] of `howmany` fields stored one after another (`howmany (2B)^2`
    /// samples, `howmany B^2` coefficients).
    pub fn forward_many(
        &self,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
        howmany: usize,
    ) -> Result<StageTimes> {
        self.forward_in((samples, coeffs, howmany), None)
    }

    /// [`S2Plan::forward_many`] in the caller's `scratch` if given.
    fn forward_in(
        &self,
        (samples, coeffs, howmany): (&[Complex<T>], &mut [Complex<T>], usize),
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        self.check(samples.len(), coeffs.len(), howmany)?;
        let start = Instant::now();
        let mut times = StageTimes::default();
        let (n, nc) = (2 * self.b, self.num_coeffs());
        let factor = (2.0 * PI).sqrt() / n as f64;
        self.with_scratch((false, scratch), |buf, _| {
            for (field, out) in samples.chunks_exact(n * n).zip(coeffs.chunks_exact_mut(nc)) {
                let spectra = Spectra {
                    base: buf.ptr::<Complex<T>>(),
                    row: n,
                    real: false,
                    block: None,
                };
                let coef = self.coeff_rows(out.as_mut_ptr());
                self.workers.pool().install(|| {
                    let t0 = Instant::now();
                    let src = SendConstPtr(field.as_ptr());
                    self.rings_complex(buf.ptr::<Complex<T>>(), true, RingCopy::From(src))?;
                    let t1 = Instant::now();
                    // SAFETY: each task handles its orders +-m only; the spectra and the
                    // coefficient array are whole (lengths checked).
                    unsafe {
                        self.run_orders((true, factor), &|m| Self::complex_groups(m, spectra, coef))
                    };
                    times.fft += (t1 - t0).as_secs_f64();
                    times.dwt += t1.elapsed().as_secs_f64();
                    Ok::<(), Error>(())
                })?;
            }
            Ok(())
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// Inverse transform of `B^2` coefficients into complex samples; the time of each
    /// stage.
    pub fn inverse(&self, coeffs: &[Complex<T>], samples: &mut [Complex<T>]) -> Result<StageTimes> {
        self.inverse_in((coeffs, samples, 1), None)
    }

    /// [`S2Plan::inverse`] of `howmany` fields stored one after another.
    pub fn inverse_many(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
        howmany: usize,
    ) -> Result<StageTimes> {
        self.inverse_in((coeffs, samples, howmany), None)
    }

    /// [`S2Plan::inverse_many`] in the caller's `scratch` if given.
    fn inverse_in(
        &self,
        (coeffs, samples, howmany): (&[Complex<T>], &mut [Complex<T>], usize),
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        self.check(samples.len(), coeffs.len(), howmany)?;
        let start = Instant::now();
        let mut times = StageTimes::default();
        let (b, n, nc) = (self.b, 2 * self.b, self.num_coeffs());
        let factor = 1.0 / (2.0 * PI).sqrt();
        self.with_scratch((false, scratch), |buf, _| {
            for (field, out) in coeffs.chunks_exact(nc).zip(samples.chunks_exact_mut(n * n)) {
                // Straight into the output where FFTW may run on it, else through the scratch.
                let direct = RingFft::<T>::aligned(out.as_ptr().cast::<T>());
                let (data, copy) = if direct {
                    (out.as_mut_ptr(), RingCopy::None)
                } else {
                    (
                        buf.ptr::<Complex<T>>(),
                        RingCopy::To(SendPtr(out.as_mut_ptr())),
                    )
                };
                let spectra = Spectra {
                    base: data,
                    row: n,
                    real: false,
                    block: None,
                };
                let data = SendPtr(data);
                let coef = self.coeff_rows(field.as_ptr().cast_mut());
                self.workers.pool().install(|| {
                    let t0 = Instant::now();
                    // SAFETY: each task writes the columns of its orders +-m only and reads
                    // their coefficient blocks (never written).
                    unsafe {
                        self.run_orders((false, factor), &|m| {
                            Self::complex_groups(m, spectra, coef)
                        })
                    };
                    let t1 = Instant::now();
                    // The frequency B is never used.
                    for k in 0..n {
                        // SAFETY: column B of ring k, inside the n*n values at `data`.
                        unsafe { *data.get().add(k * n + b) = Complex::new(T::ZERO, T::ZERO) };
                    }
                    self.rings_complex(data.get(), false, copy)?;
                    times.dwt += (t1 - t0).as_secs_f64();
                    times.fft += t1.elapsed().as_secs_f64();
                    Ok::<(), Error>(())
                })?;
            }
            Ok(())
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// Forward transform of real samples: all `B^2` coefficients, with
    /// `fhat(l, -m) = (-1)^m conj(fhat(l, m))`.
    pub fn forward_real(&self, samples: &[T], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        self.forward_real_in((samples, coeffs, 1), None)
    }

    /// [`S2Plan::forward_real`] of `howmany` fields stored one after another. Two fields
    /// share each kernel call (the recurrence is run once for both).
    pub fn forward_real_many(
        &self,
        samples: &[T],
        coeffs: &mut [Complex<T>],
        howmany: usize,
    ) -> Result<StageTimes> {
        self.forward_real_in((samples, coeffs, howmany), None)
    }

    /// [`S2Plan::forward_real_many`] in the caller's `scratch` if given (one field).
    fn forward_real_in(
        &self,
        (samples, coeffs, howmany): (&[T], &mut [Complex<T>], usize),
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        self.check(samples.len(), coeffs.len(), howmany)?;
        let start = Instant::now();
        let mut times = StageTimes::default();
        let (n, nc) = (2 * self.b, self.num_coeffs());
        self.with_scratch((howmany > 1, scratch), |first, second| {
            for (fields, outs) in samples.chunks(2 * n * n).zip(coeffs.chunks_mut(2 * nc)) {
                let (mut ins, mut outs2) = ([&[][..]; 2], [&mut [][..], &mut [][..]]);
                let mut count = 0;
                for (field, out) in fields.chunks_exact(n * n).zip(outs.chunks_exact_mut(nc)) {
                    (ins[count], outs2[count]) = (field, out);
                    count += 1;
                }
                times +=
                    self.real_analysis([Some(first), second], &ins[..count], &mut outs2[..count])?;
            }
            Ok(())
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// [`S2Plan::forward_real`] of two fields held in two separate arrays, sharing the
    /// kernel calls (as [`S2Plan::forward_real_many`]).
    pub fn forward_real_pair(
        &self,
        samples: [&[T]; 2],
        coeffs: [&mut [Complex<T>]; 2],
    ) -> Result<StageTimes> {
        for (s, c) in samples.iter().zip(&coeffs) {
            self.check(s.len(), c.len(), 1)?;
        }
        let start = Instant::now();
        let [a, b] = coeffs;
        let mut times = self.with_scratch((true, None), |first, second| {
            self.real_analysis([Some(first), second], &samples, &mut [a, b])
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// The real analysis of one or two fields (`fields[i]` into `outs[i]`, checked
    /// lengths) with the ring scratches `bufs` (the second one for a second field).
    fn real_analysis(
        &self,
        bufs: [Option<&AlignedBuf>; 2],
        fields: &[&[T]],
        outs: &mut [&mut [Complex<T>]],
    ) -> Result<StageTimes> {
        let factor = (2.0 * PI).sqrt() / (2 * self.b) as f64;
        let t0 = Instant::now();
        let mut groups = [None; 2];
        for (i, (field, out)) in fields.iter().zip(outs.iter_mut()).enumerate().take(2) {
            let buf = bufs[i].expect("a second scratch for two fields");
            groups[i] = Some(self.real_rings_forward(buf, field, out)?);
        }
        let t1 = Instant::now();
        // SAFETY: as in `forward_many`; each field has its own spectra and coefficients.
        unsafe { self.real_orders(groups, factor, true) };
        Ok(StageTimes {
            fft: (t1 - t0).as_secs_f64(),
            dwt: t1.elapsed().as_secs_f64(),
            ..StageTimes::default()
        })
    }

    /// The Legendre stage of every order for one or two real fields (`groups[1]` `None` for
    /// one), analysis or synthesis: two fields share each kernel call.
    ///
    /// # Safety
    /// As for `LegendreStage::analyse` / `synthesise`, for each field.
    unsafe fn real_orders(&self, groups: [Option<Group<T>>; 2], factor: f64, analyse: bool) {
        let used = groups.iter().flatten().count();
        let first = groups[0].expect("at least one field");
        let groups = groups.map(|g| g.unwrap_or(first));
        self.workers.pool().install(|| {
            let of = |m: usize| {
                let g = groups.map(|src| Group {
                    order: m as isize,
                    ..src
                });
                (g, used)
            };
            // SAFETY: each task handles its orders of each field only (caller's contract).
            unsafe { self.run_orders((analyse, factor), &of) }
        });
    }

    /// The Legendre analysis (`analyse`) or synthesis of every order, the groups of order
    /// `m` given by `groups_of(m)` (those of all orders on the same spectra), in tasks of
    /// [`ORDER_BLOCK`] orders: each task copies its orders' columns of every ring into a
    /// block of its own before the analysis, or from it after the synthesis, so that the
    /// rings' values are read and written as whole cache lines.
    ///
    /// # Safety
    /// As for `LegendreStage::analyse` / `synthesise`, for every order's groups.
    unsafe fn run_orders(
        &self,
        (analyse, factor): (bool, f64),
        groups_of: &(dyn Fn(usize) -> ([Group<T>; 2], usize) + Sync),
    ) {
        let (b, rings) = (self.b, 2 * self.b);
        let width = ORDER_BLOCK;
        (0..b.div_ceil(width)).into_par_iter().for_each(|blk| {
            let (first, len) = (blk * width, width.min(b - blk * width));
            // The distinct spectra of the groups (one per field).
            let (g0, count) = groups_of(first);
            let mut fields: Vec<Spectra<T>> = Vec::with_capacity(2);
            for g in &g0[..count] {
                if !fields.iter().any(|f| f.base == g.spectra.base) {
                    fields.push(g.spectra);
                }
            }
            let each = rings * 2 * width;
            self.with_block(fields.len() * each, |buf| {
                let views: Vec<Spectra<T>> = fields
                    .iter()
                    .enumerate()
                    .map(|(i, f)| f.block_view((first, width), buf[i * each..].as_mut_ptr()))
                    .collect();
                // SAFETY: the block's orders of each field: this task's (caller's contract);
                // each view covers `each` values of `buf`.
                unsafe {
                    if analyse {
                        for (f, v) in fields.iter().zip(&views) {
                            f.copy_block(v, rings, len, true);
                        }
                    }
                    for m in first..first + len {
                        let (mut g, count) = groups_of(m);
                        for gi in g[..count].iter_mut() {
                            let i = fields.iter().position(|f| f.base == gi.spectra.base);
                            gi.spectra = views[i.expect("a field of the block")];
                        }
                        if analyse {
                            self.analyse(m, &g[..count], factor)
                        } else {
                            self.synthesise(m, &g[..count], factor)
                        }
                    }
                    if !analyse {
                        for (f, v) in fields.iter().zip(&views) {
                            f.copy_block(v, rings, len, false);
                        }
                    }
                }
            });
        });
    }

    /// Runs `f` with a worker's block buffer of at least `len` values (another's if its
    /// own is in use, else a new one).
    fn with_block(&self, len: usize, f: impl FnOnce(&mut [Complex<T>])) {
        let zero = Complex::new(T::ZERO, T::ZERO);
        match lock_free(&self.blocks) {
            Some(mut g) => {
                if g.len() < len {
                    g.resize(len, zero);
                }
                f(&mut g[..len])
            }
            None => f(&mut vec![zero; len]),
        }
    }

    /// The `r2c` of one real field's rings (copied into `buf` first); the field's column
    /// group (order set per call).
    fn real_rings_forward(
        &self,
        buf: &AlignedBuf,
        field: &[T],
        out: &mut [Complex<T>],
    ) -> Result<Group<T>> {
        let n = 2 * self.b;
        let per = self.rings.per_call();
        let half = self.b + 1;
        // Real rings in the first n*n/2 values of the scratch (unless FFTW may read the
        // field itself), their spectra after them.
        let direct = RingFft::aligned(field.as_ptr());
        let reals = SendPtr(buf.ptr::<T>());
        let src = SendConstPtr(field.as_ptr());
        let spec = SendPtr(buf.ptr::<Complex<T>>().wrapping_add(n * n / 2));
        self.workers.pool().install(|| {
            (0..n / per).into_par_iter().try_for_each(|c| {
                let at = c * per * n;
                // SAFETY: rings c*per.. of the field (n*n reals, read only: the r2c plan
                // preserves its input), of the reals (n*n reals in the first n*n/2 values
                // of the scratch) and of the spectra (n rows of B+1 values after n*n/2,
                // within the n*n + n scratch): this task's.
                unsafe {
                    let input = if direct {
                        src.get().add(at)
                    } else {
                        std::ptr::copy_nonoverlapping(
                            src.get().add(at),
                            reals.get().add(at),
                            per * n,
                        );
                        reals.get().add(at)
                    };
                    self.rings.r2c(input, spec.get().add(c * per * half))
                }
            })
        })?;
        Ok(Group {
            spectra: Spectra {
                base: spec.get(),
                row: half,
                real: true,
                block: None,
            },
            coef: self.coeff_rows(out.as_mut_ptr()),
            order: 0,
            partner: true,
        })
    }

    /// Inverse transform into real samples: reads the orders `m >= 0` and takes
    /// `fhat(l, -m) = (-1)^m conj(fhat(l, m))` (imaginary parts of `fhat(l, 0)` are
    /// ignored).
    pub fn inverse_real(&self, coeffs: &[Complex<T>], samples: &mut [T]) -> Result<StageTimes> {
        self.inverse_real_in((coeffs, samples, 1), None)
    }

    /// [`S2Plan::inverse_real`] of `howmany` fields stored one after another, two fields
    /// per kernel call.
    pub fn inverse_real_many(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [T],
        howmany: usize,
    ) -> Result<StageTimes> {
        self.inverse_real_in((coeffs, samples, howmany), None)
    }

    /// [`S2Plan::inverse_real_many`] in the caller's `scratch` if given (one field).
    fn inverse_real_in(
        &self,
        (coeffs, samples, howmany): (&[Complex<T>], &mut [T], usize),
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        self.check(samples.len(), coeffs.len(), howmany)?;
        let start = Instant::now();
        let mut times = StageTimes::default();
        let (n, nc) = (2 * self.b, self.num_coeffs());
        self.with_scratch((howmany > 1, scratch), |first, second| {
            for (fields, outs) in coeffs.chunks(2 * nc).zip(samples.chunks_mut(2 * n * n)) {
                let (mut ins, mut outs2) = ([&[][..]; 2], [&mut [][..], &mut [][..]]);
                let mut count = 0;
                for (field, out) in fields.chunks_exact(nc).zip(outs.chunks_exact_mut(n * n)) {
                    (ins[count], outs2[count]) = (field, out);
                    count += 1;
                }
                times +=
                    self.real_synthesis([Some(first), second], &ins[..count], &mut outs2[..count])?;
            }
            Ok(())
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// [`S2Plan::inverse_real`] of two fields into two separate arrays, sharing the kernel
    /// calls (as [`S2Plan::inverse_real_many`]).
    pub fn inverse_real_pair(
        &self,
        coeffs: [&[Complex<T>]; 2],
        samples: [&mut [T]; 2],
    ) -> Result<StageTimes> {
        for (c, s) in coeffs.iter().zip(&samples) {
            self.check(s.len(), c.len(), 1)?;
        }
        let start = Instant::now();
        let [a, b] = samples;
        let mut times = self.with_scratch((true, None), |first, second| {
            self.real_synthesis([Some(first), second], &coeffs, &mut [a, b])
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// The real synthesis of one or two fields (`fields[i]` into `outs[i]`, checked
    /// lengths) with the ring scratches `bufs` (the second one for a second field).
    fn real_synthesis(
        &self,
        bufs: [Option<&AlignedBuf>; 2],
        fields: &[&[Complex<T>]],
        outs: &mut [&mut [T]],
    ) -> Result<StageTimes> {
        let t0 = Instant::now();
        let (b, n) = (self.b, 2 * self.b);
        let factor = 1.0 / (2.0 * PI).sqrt();
        let half = b + 1;
        let mut groups = [None; 2];
        for (i, field) in fields.iter().enumerate().take(2) {
            let buf = bufs[i].expect("a second scratch for two fields");
            groups[i] = Some(Group {
                spectra: Spectra {
                    base: buf.ptr::<Complex<T>>().wrapping_add(n * n / 2),
                    row: half,
                    real: true,
                    block: None,
                },
                coef: self.coeff_rows(field.as_ptr().cast_mut()),
                order: 0,
                partner: false,
            });
        }
        // SAFETY: as in `inverse_many`; each field has its own spectra; the coefficient
        // arrays hold B^2 values (checked by the callers) and are only read.
        unsafe { self.real_orders(groups, factor, false) };
        let t1 = Instant::now();
        for (i, out) in outs.iter_mut().enumerate().take(fields.len().min(2)) {
            let buf = bufs[i].expect("a second scratch for two fields");
            self.real_rings_inverse(buf, out)?;
        }
        Ok(StageTimes {
            fft: t1.elapsed().as_secs_f64(),
            dwt: (t1 - t0).as_secs_f64(),
            ..StageTimes::default()
        })
    }

    /// The `c2r` of one field's spectra in `buf` into `out`.
    fn real_rings_inverse(&self, buf: &AlignedBuf, out: &mut [T]) -> Result<()> {
        let (b, n) = (self.b, 2 * self.b);
        let per = self.rings.per_call();
        let half = b + 1;
        let reals = SendPtr(buf.ptr::<T>());
        let spec = SendPtr(buf.ptr::<Complex<T>>().wrapping_add(n * n / 2));
        self.workers.pool().install(|| {
            for k in 0..n {
                // SAFETY: column B of spectrum row k, inside the scratch.
                unsafe { *spec.get().add(k * half + b) = Complex::new(T::ZERO, T::ZERO) };
            }
            let direct = RingFft::aligned(out.as_ptr());
            let dst = SendPtr(out.as_mut_ptr());
            (0..n / per).into_par_iter().try_for_each(|c| {
                let at = c * per * n;
                // SAFETY: as in `real_rings_forward`, the other way; rings c*per.. of `out`
                // (n*n reals): this task's.
                unsafe {
                    let spectra = spec.get().add(c * per * half);
                    if direct {
                        self.rings.c2r(spectra, dst.get().add(at))
                    } else {
                        self.rings.c2r(spectra, reals.get().add(at))?;
                        std::ptr::copy_nonoverlapping(
                            reals.get().add(at),
                            dst.get().add(at),
                            per * n,
                        );
                        Ok(())
                    }
                }
            })
        })
    }
}

/// Copies made by the ring DFT tasks around their DFTs (see `S2Plan::rings_complex`).
enum RingCopy<T> {
    None,
    /// Copy the rings in from this array first.
    From(SendConstPtr<Complex<T>>),
    /// Copy the transformed rings out to this array.
    To(SendPtr<Complex<T>>),
}

impl<T: Copy> Clone for RingCopy<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T: Copy> Copy for RingCopy<T> {}

/// The scratch behind `m` if no other execution holds it.
fn try_take(
    m: &Mutex<Option<AlignedBuf>>,
) -> Option<std::sync::MutexGuard<'_, Option<AlignedBuf>>> {
    match m.try_lock() {
        Ok(g) => Some(g),
        Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => None,
    }
}

/// Values of the ring scratch: `(2B)^2` complex spectra, or for real samples `(2B)^2`
/// reals (half as many values) followed by `2B` rows of `B + 1` spectra.
fn scratch_len(b: usize) -> usize {
    let n = 2 * b;
    n * n + n
}

impl Transform for S2Plan<f64> {
    fn num_samples(&self) -> usize {
        S2Plan::num_samples(self)
    }

    fn num_coeffs(&self) -> usize {
        S2Plan::num_coeffs(self)
    }

    /// The ring scratch.
    fn scratch_bytes(&self) -> usize {
        16 * scratch_len(self.b)
    }

    fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        S2Plan::forward(self, samples, coeffs)
    }

    fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        S2Plan::inverse(self, coeffs, samples)
    }

    fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        S2Plan::forward_real(self, samples, coeffs)
    }

    fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        S2Plan::inverse_real(self, coeffs, samples)
    }

    fn forward_with_scratch(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.forward_in((samples, coeffs, 1), Some(scratch))
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.inverse_in((coeffs, samples, 1), Some(scratch))
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[f64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.forward_real_in((samples, coeffs, 1), Some(scratch))
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.inverse_real_in((coeffs, samples, 1), Some(scratch))
    }
}
