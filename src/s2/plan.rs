//! [`S2Plan`]: spherical-harmonic transforms of one bandwidth.

use super::layout::{order_start, s2_num_coeffs, s2_num_samples};
use super::legendre::{CoeffRows, LegendreStage, Spectra};
use super::rings::RingFft;
use crate::error::{Error, Result};
use crate::fft::{AlignedBuf, Rigor};
use crate::simd::Isa;
use crate::system::check_headroom;
use crate::workers::{WorkerPool, WORKER_STACK_BYTES};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;

/// Largest bandwidth of the S^2 transforms.
pub const S2_MAX_BANDWIDTH: usize = 4096;

/// Options of an [`S2Plan`].
#[derive(Clone, Debug, Default)]
pub struct S2Options {
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// FFTW planner rigour of the ring DFTs.
    pub rigor: Rigor,
    /// Instruction set of the kernels (`None`: the best this CPU has).
    pub isa: Option<Isa>,
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
pub struct S2Plan {
    b: usize,
    threads: usize,
    workers: WorkerPool,
    rings: RingFft,
    legendre: LegendreStage,
    /// Start of each order's coefficient block, indexed by `m + B - 1`.
    starts: Vec<usize>,
    /// Ring spectra (`(2B)^2` values), taken by one execution at a time.
    scratch: Mutex<Option<AlignedBuf>>,
}

impl S2Plan {
    /// A plan for bandwidth `bandwidth` (`1 ..= S2_MAX_BANDWIDTH`).
    pub fn new(bandwidth: usize, options: &S2Options) -> Result<S2Plan> {
        let b = bandwidth;
        if b == 0 || b > S2_MAX_BANDWIDTH {
            return Err(Error::InvalidBandwidth {
                bandwidth: b,
                max: S2_MAX_BANDWIDTH,
            });
        }
        let threads = match options.threads {
            0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
            t if t > 1024 => {
                return Err(Error::InvalidArgument(format!(
                    "{t} threads requested (at most 1024)"
                )))
            }
            t => t,
        };
        let isa = options.isa.unwrap_or_else(Isa::detect);
        if !isa.is_supported() {
            return Err(Error::InvalidArgument(format!(
                "instruction set {isa:?} not supported by this CPU"
            )));
        }
        let n = 2 * b;
        let bytes = S2Plan::memory_needed(b, threads);
        check_headroom(
            bytes
                .saturating_add(threads * WORKER_STACK_BYTES)
                .saturating_add(crate::fft::planning_bytes(16 * n, 1)),
        )?;
        let scratch = AlignedBuf::new(scratch_len(b))?;
        let rings = RingFft::new(n, options.rigor)?;
        let legendre = LegendreStage::new(b, isa, threads);
        let starts = (-(b as isize - 1)..b as isize)
            .map(|m| order_start(b, m))
            .collect();
        let workers = WorkerPool::new(threads, "so3fft-s2")?;
        Ok(S2Plan {
            b,
            threads,
            workers,
            rings,
            legendre,
            starts,
            scratch: Mutex::new(Some(scratch)),
        })
    }

    /// Bytes a plan of bandwidth `b` on `threads` threads holds (ring scratch, tables).
    pub fn memory_needed(b: usize, threads: usize) -> usize {
        16 * scratch_len(b) + LegendreStage::bytes(b, threads) + 8 * 2 * b
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

    fn check(&self, samples: usize, coeffs: usize) -> Result<()> {
        if !self.workers.in_own_process() {
            return Err(Error::InvalidArgument(
                "S^2 plan made in another process (before fork()): make a new plan here".into(),
            ));
        }
        for (what, expected, got) in [
            ("samples", self.num_samples(), samples),
            ("coefficients", self.num_coeffs(), coeffs),
        ] {
            if got != expected {
                return Err(Error::LengthMismatch {
                    what,
                    expected,
                    got,
                });
            }
        }
        Ok(())
    }

    /// Runs `f` with the plan's ring scratch, or a new one when it is in use.
    fn with_scratch<R>(&self, f: impl FnOnce(&AlignedBuf) -> Result<R>) -> Result<R> {
        let guard = match self.scratch.try_lock() {
            Ok(g) => Some(g),
            Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
            Err(std::sync::TryLockError::WouldBlock) => None,
        };
        match guard.as_ref().and_then(|g| g.as_ref()) {
            Some(buf) => f(buf),
            None => f(&AlignedBuf::new(scratch_len(self.b))?),
        }
    }

    fn coeff_rows(&self, base: *mut Complex64) -> CoeffRows {
        CoeffRows {
            base,
            starts: self.starts.as_ptr(),
            b: self.b,
        }
    }

    /// Ring DFTs of all rings in parallel: complex in place (`analysis`: sign -1).
    fn rings_complex(&self, buf: &AlignedBuf, analysis: bool) -> Result<()> {
        let (n, per) = (self.rings.len(), self.rings.per_call());
        let base = SendMut(buf.as_mut_ptr());
        (0..n / per).into_par_iter().try_for_each(|c| {
            // SAFETY: rings c*per .. (c+1)*per of the (2B)^2 scratch: this task's alone.
            unsafe { self.rings.complex(base.get().add(c * per * n), analysis) }
        })
    }

    /// Forward transform of complex samples (`(2B)^2`, ring-major) into `B^2` coefficients.
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<()> {
        self.check(samples.len(), coeffs.len())?;
        let (b, n) = (self.b, 2 * self.b);
        let factor = (2.0 * PI).sqrt() / n as f64;
        self.with_scratch(|buf| {
            // SAFETY: the scratch holds n*n values; nothing else uses it during the call.
            unsafe { std::ptr::copy_nonoverlapping(samples.as_ptr(), buf.as_mut_ptr(), n * n) };
            let spectra = Spectra {
                base: buf.as_mut_ptr(),
                row: n,
                real: false,
            };
            let coef = self.coeff_rows(coeffs.as_mut_ptr());
            self.workers.pool().install(|| {
                self.rings_complex(buf, true)?;
                (0..b).into_par_iter().for_each(|m| {
                    // SAFETY: each task handles orders +-m only; the spectra and the
                    // coefficient array are whole (lengths checked).
                    unsafe { self.legendre.analyse(m, spectra, coef, factor) }
                });
                Ok(())
            })
        })
    }

    /// Inverse transform of `B^2` coefficients into complex samples.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<()> {
        self.check(samples.len(), coeffs.len())?;
        let (b, n) = (self.b, 2 * self.b);
        let factor = 1.0 / (2.0 * PI).sqrt();
        self.with_scratch(|buf| {
            let spectra = Spectra {
                base: buf.as_mut_ptr(),
                row: n,
                real: false,
            };
            let coef = self.coeff_rows(coeffs.as_ptr().cast_mut());
            self.workers.pool().install(|| {
                (0..b).into_par_iter().for_each(|m| {
                    // SAFETY: each task writes the columns of orders +-m only and reads
                    // their coefficient blocks (never written).
                    unsafe { self.legendre.synthesise(m, coef, spectra, factor) }
                });
                // The frequency B is never used.
                for k in 0..n {
                    // SAFETY: column B of ring k, inside the scratch.
                    unsafe { *buf.as_mut_ptr().add(k * n + b) = Complex64::default() };
                }
                self.rings_complex(buf, false)
            })?;
            // SAFETY: the scratch holds n*n values; `samples` as many (checked).
            unsafe { std::ptr::copy_nonoverlapping(buf.as_mut_ptr(), samples.as_mut_ptr(), n * n) };
            Ok(())
        })
    }

    /// Forward transform of real samples: all `B^2` coefficients, with
    /// `fhat(l, -m) = (-1)^m conj(fhat(l, m))`.
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<()> {
        self.check(samples.len(), coeffs.len())?;
        let (b, n) = (self.b, 2 * self.b);
        let per = self.rings.per_call();
        let factor = (2.0 * PI).sqrt() / n as f64;
        let half = b + 1;
        self.with_scratch(|buf| {
            // Real rings in the first n*n/2 values of the scratch, their spectra after them.
            let reals = SendMut(buf.as_mut_ptr().cast::<f64>());
            let spec = SendMut(buf.as_mut_ptr().wrapping_add(n * n / 2));
            // SAFETY: n*n reals fit in the first n*n/2 complex values of the scratch.
            unsafe { std::ptr::copy_nonoverlapping(samples.as_ptr(), reals.get(), n * n) };
            let spectra = Spectra {
                base: spec.get(),
                row: half,
                real: true,
            };
            let coef = self.coeff_rows(coeffs.as_mut_ptr());
            self.workers.pool().install(|| {
                (0..n / per).into_par_iter().try_for_each(|c| {
                    // SAFETY: rings c*per.. of the reals (read) and of the spectra (n rows
                    // of B+1 values after n*n/2, within the n*n + n scratch): this task's.
                    unsafe {
                        self.rings
                            .r2c(reals.get().add(c * per * n), spec.get().add(c * per * half))
                    }
                })?;
                (0..b).into_par_iter().for_each(|m| {
                    // SAFETY: as in `forward`.
                    unsafe { self.legendre.analyse(m, spectra, coef, factor) }
                });
                Ok(())
            })
        })
    }

    /// Inverse transform into real samples: reads the orders `m >= 0` and takes
    /// `fhat(l, -m) = (-1)^m conj(fhat(l, m))` (imaginary parts of `fhat(l, 0)` are
    /// ignored).
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<()> {
        self.check(samples.len(), coeffs.len())?;
        let (b, n) = (self.b, 2 * self.b);
        let per = self.rings.per_call();
        let factor = 1.0 / (2.0 * PI).sqrt();
        let half = b + 1;
        self.with_scratch(|buf| {
            let reals = SendMut(buf.as_mut_ptr().cast::<f64>());
            let spec = SendMut(buf.as_mut_ptr().wrapping_add(n * n / 2));
            let spectra = Spectra {
                base: spec.get(),
                row: half,
                real: true,
            };
            let coef = self.coeff_rows(coeffs.as_ptr().cast_mut());
            self.workers.pool().install(|| {
                (0..b).into_par_iter().for_each(|m| {
                    // SAFETY: as in `inverse`.
                    unsafe { self.legendre.synthesise(m, coef, spectra, factor) }
                });
                for k in 0..n {
                    // SAFETY: column B of spectrum row k, inside the scratch.
                    unsafe { *spec.get().add(k * half + b) = Complex64::default() };
                }
                (0..n / per).into_par_iter().try_for_each(|c| {
                    // SAFETY: as in `forward_real`, the other way.
                    unsafe {
                        self.rings
                            .c2r(spec.get().add(c * per * half), reals.get().add(c * per * n))
                    }
                })
            })?;
            // SAFETY: n*n reals in the scratch; `samples` has as many (checked).
            unsafe { std::ptr::copy_nonoverlapping(reals.get(), samples.as_mut_ptr(), n * n) };
            Ok(())
        })
    }
}

/// Values of the ring scratch: `(2B)^2` complex spectra, or for real samples `(2B)^2`
/// reals (half as many values) followed by `2B` rows of `B + 1` spectra.
fn scratch_len(b: usize) -> usize {
    let n = 2 * b;
    n * n + n
}

/// A pointer the tasks of one execution use at disjoint places.
#[derive(Clone, Copy)]
struct SendMut<T>(*mut T);

// SAFETY: an address only; every dereference says why the tasks' accesses are disjoint.
unsafe impl<T> Send for SendMut<T> {}
// SAFETY: as for Send.
unsafe impl<T> Sync for SendMut<T> {}

impl<T> SendMut<T> {
    fn get(self) -> *mut T {
        self.0
    }
}
