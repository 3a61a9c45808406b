//! [`PartialPlan`]: the public face of the engine: construction, the argument checks and
//! the transforms, single and batched.

use crate::batch::Batch;
use crate::engine::{Data, Engine, Footprint, LanePairs, SliceWatch};
use crate::error::{Error, Result};
use crate::options::{Betas, Direction, Options};
use crate::shape::Shape;
use crate::simd::Isa;
use crate::system::{mem_available, mem_total};
use crate::transform::{Scratch, StageTimes, Transform};
use crate::workers::{SendConstPtr, SendPtr, WorkerPool};
use crate::Real;
use num_complex::Complex;

/// A transform on SO(3) that computes only what a [`Shape`] holds: band-limited,
/// order-limited, oversampled or undersampled in alpha and gamma, restricted to some
/// betas, several at once ([`Batch`]), complex or real.
///
/// Every shape runs on one engine: the DWT kernels per cluster of order pairs over
/// chunks of beta pairs, and pruned slice DFTs ([`Plan`](crate::Plan) is its full shape).
/// Execution takes `&self`; one plan may run on different arrays from several threads.
///
/// `T` is the precision of the arrays and of the computation: `f64`, or `f32` for about
/// half the time and memory at a relative error near `1e-6` (see `docs/precision.md`).
pub struct PartialPlan<T: Real = f64> {
    shape: Shape,
    direction: Direction,
    real: bool,
    threads: usize,
    n_slices: usize,
    isa: Isa,
    engine: Box<Engine<T>>,
}

/// What [`PartialPlan::new`] checks and resolves before it builds anything.
struct Checked {
    direction: Direction,
    threads: usize,
    isa: Isa,
    skip: (u32, bool),
    pairs: LanePairs,
}

impl<T: Real> PartialPlan<T> {
    /// A plan for `shape` with `options`.
    pub fn new(shape: &Shape, options: &Options) -> Result<PartialPlan<T>> {
        Self::new_on(shape, options, None)
    }

    /// [`PartialPlan::new`] on the workers of `shared` if given (with the plan's thread
    /// count).
    pub(crate) fn new_on(
        shape: &Shape,
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<PartialPlan<T>> {
        let c = Self::validate(shape, options)?;
        let n_slices = c.pairs.n_slices;
        // Fail cleanly instead of meeting the OOM killer: the plan must fit in the available
        // memory, and plan plus the caller's arrays in the machine. Checked on the estimate
        // before the tables are built (they take minutes at the largest bandwidths), and on
        // the plan's own count before its large buffers are made.
        let arrays =
            (n_slices * shape.slice_len() + shape.num_coeffs()).saturating_mul(2 * T::BYTES);
        let estimate = Footprint::new::<T>(shape, &c.pairs, (c.isa, c.threads), options).total();
        if !fits_in_memory(estimate, arrays) {
            return Err(Error::OutOfMemory { bytes: estimate });
        }
        let engine = Box::new(Engine::new(
            shape,
            c.pairs,
            (c.isa, c.skip, c.threads),
            options,
            shared,
        )?);
        let need = engine.memory_bytes();
        if !fits_in_memory(need, arrays) {
            return Err(Error::OutOfMemory { bytes: need });
        }
        engine.reserve()?;
        Ok(PartialPlan {
            shape: *shape,
            direction: c.direction,
            real: options.real,
            threads: c.threads,
            n_slices,
            isa: c.isa,
            engine,
        })
    }

    /// Bytes of memory a plan made now with these arguments would hold
    /// ([`PartialPlan::memory_bytes`]), without making it: the same checks as
    /// [`PartialPlan::new`] and the same formulas, nothing large allocated. The default
    /// workspace depends on the memory available at the time of the call (at most half of
    /// it is used), so a plan made later may differ if that has changed.
    pub fn memory_needed(shape: &Shape, options: &Options) -> Result<usize> {
        let c = Self::validate(shape, options)?;
        Ok(Footprint::new::<T>(shape, &c.pairs, (c.isa, c.threads), options).total())
    }

    /// The checks of [`PartialPlan::new`].
    fn validate(shape: &Shape, options: &Options) -> Result<Checked> {
        shape.validate()?;
        let restricted = options.betas != Betas::All;
        let direction = if restricted {
            match options.direction {
                Direction::Forward => {
                    return Err(Error::InvalidArgument(
                        "a forward transform needs every beta of the grid".into(),
                    ))
                }
                _ => Direction::Inverse,
            }
        } else {
            options.direction
        };
        if direction != Direction::Inverse {
            shape.check_forward()?;
        }
        let threads = crate::workers::thread_count(options.threads)?;
        let isa = Isa::resolve(options.isa)?;
        let skip = options.skip_for::<T>()?;
        options.check_workspace()?;
        let pairs = LanePairs::new(shape, &options.betas, Some(isa.lanes_of::<T>()))?;
        Ok(Checked {
            direction,
            threads,
            isa,
            skip,
            pairs,
        })
    }

    /// Bytes of memory the plan holds: the chunk buffer ([`PartialPlan::scratch_bytes`]),
    /// the workers' FFT buffers and stacks, and the tables. A transform needs the caller's
    /// arrays on top and nothing else large. [`PartialPlan::memory_needed`] gives the same
    /// number before planning.
    pub fn memory_bytes(&self) -> usize {
        self.engine.memory_bytes()
    }

    /// The plan's worker threads.
    pub(crate) fn workers(&self) -> &WorkerPool {
        &self.engine.workers
    }

    /// Instruction set of the DWT kernels.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Runs `f` on the plan's worker threads (rayon's parallel iterators inside it use
    /// them), for work that goes with a transform, such as the SOFT layer's checks.
    pub(crate) fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.workers().pool().install(f)
    }

    /// The plan's shape.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// Which transforms the plan runs.
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// Worker threads.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// The number of chunks a single inverse (complex, or `real`) runs as one chain
    /// (their buffers in the output, each cluster's coefficients read once), 0 where it
    /// runs them one by one. For tests and benchmarks.
    #[doc(hidden)]
    pub fn chained_inverse_chunks(&self, real: bool) -> usize {
        self.engine.chained_chunks(real)
    }

    /// Coefficients of one transform ([`Shape::num_coeffs`]).
    pub fn num_coeffs(&self) -> usize {
        self.engine.layout.total
    }

    /// Samples of one transform: `n_alpha n_gamma` per beta slice, times the number of
    /// betas (`2 B_grid`, or the selection's length).
    pub fn num_samples(&self) -> usize {
        self.n_slices * self.shape.slice_len()
    }

    /// Number of beta slices of the samples.
    pub fn num_slices(&self) -> usize {
        self.n_slices
    }

    /// Forward: samples to coefficients; the time of each stage.
    pub fn forward(&self, samples: &[Complex<T>], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        self.forward_in(one(samples.len(), coeffs.len()), samples, coeffs, None)
    }

    /// Inverse: coefficients to samples; the time of each stage.
    pub fn inverse(&self, coeffs: &[Complex<T>], samples: &mut [Complex<T>]) -> Result<StageTimes> {
        self.inverse_in(one(coeffs.len(), samples.len()), coeffs, samples, None)
    }

    /// Forward of a real signal (`num_samples` doubles): every coefficient block written.
    pub fn forward_real(&self, samples: &[T], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        self.forward_real_in(one(samples.len(), coeffs.len()), samples, coeffs, None)
    }

    /// Inverse to a real signal: reads only the blocks `M' > 0`, or `M' = 0` and `M >= 0`,
    /// and takes the others as `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
    pub fn inverse_real(&self, coeffs: &[Complex<T>], samples: &mut [T]) -> Result<StageTimes> {
        self.inverse_real_in(one(coeffs.len(), samples.len()), coeffs, samples, None)
    }

    /// Bytes of [`Scratch`] a single transform with scratch needs: the chunk buffer of
    /// its lane rows (the larger of the complex and, on a real plan, the real transforms').
    pub fn scratch_bytes(&self) -> usize {
        self.engine.scratch_bytes()
    }

    /// [`PartialPlan::inverse`] that shows every output slice to `watch` as it is
    /// computed (a single transform; the slice index is the watch's first argument).
    pub(crate) fn inverse_watched(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
        watch: SliceWatch<T>,
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.check(false, false, b, coeffs.len(), samples.len())?;
        let out = Data::Complex(SendPtr(samples.as_mut_ptr()));
        self.run_inverse(b, coeffs, out, (None, Some(watch)))
    }

    /// [`PartialPlan::inverse_real`] with a watch, as [`PartialPlan::inverse_watched`].
    pub(crate) fn inverse_real_watched(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [T],
        watch: SliceWatch<T>,
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.check(false, true, b, coeffs.len(), samples.len())?;
        let out = Data::Real(SendPtr(samples.as_mut_ptr()));
        self.run_inverse(b, coeffs, out, (None, Some(watch)))
    }

    /// [`PartialPlan::inverse_real`] into a complex sample array: real parts are the
    /// samples, imaginary parts exactly 0 (for callers whose interface is complex, such as
    /// the C API with `SO3FFT_REAL` and the SOFT layer).
    pub(crate) fn inverse_real_to_complex(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.check(false, true, b, coeffs.len(), samples.len())?;
        let out = Data::RealParts(SendPtr(samples.as_mut_ptr()));
        self.run_inverse(b, coeffs, out, (None, None))
    }

    /// Real forward of the real parts of complex samples (the imaginary parts are not
    /// read): the real path for callers whose real data sit in a complex array.
    pub(crate) fn forward_real_parts(
        &self,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        let b = one(samples.len(), coeffs.len());
        self.check(true, true, b, samples.len(), coeffs.len())?;
        let inp = Data::RealParts(SendPtr(samples.as_ptr().cast_mut()));
        self.run_forward(b, inp, coeffs, None)
    }

    /// The engine's inverse of checked arguments.
    fn run_inverse(
        &self,
        batch: Batch,
        coeffs: &[Complex<T>],
        out: Data<T>,
        extras: (Option<&Scratch>, Option<SliceWatch<T>>),
    ) -> Result<StageTimes> {
        self.engine
            .inverse(batch, SendConstPtr(coeffs.as_ptr()), out, extras)
    }

    /// The engine's forward of checked arguments (`inp` only read).
    fn run_forward(
        &self,
        batch: Batch,
        inp: Data<T>,
        coeffs: &mut [Complex<T>],
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        self.engine
            .forward(batch, inp, SendPtr(coeffs.as_mut_ptr()), scratch)
    }

    /// `batch.count` forwards; the time of each stage.
    pub fn forward_many(
        &self,
        batch: Batch,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        self.forward_in(batch, samples, coeffs, None)
    }

    /// `batch.count` inverses; the time of each stage.
    pub fn inverse_many(
        &self,
        batch: Batch,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        self.inverse_in(batch, coeffs, samples, None)
    }

    /// `batch.count` real forwards; the time of each stage.
    pub fn forward_real_many(
        &self,
        batch: Batch,
        samples: &[T],
        coeffs: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        self.forward_real_in(batch, samples, coeffs, None)
    }

    /// `batch.count` real inverses; the time of each stage.
    pub fn inverse_real_many(
        &self,
        batch: Batch,
        coeffs: &[Complex<T>],
        samples: &mut [T],
    ) -> Result<StageTimes> {
        self.inverse_real_in(batch, coeffs, samples, None)
    }

    /// [`PartialPlan::forward_many`] in the caller's `scratch` if given (one transform).
    fn forward_in(
        &self,
        batch: Batch,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(true, false, batch, samples.len(), coeffs.len())?;
        // The samples are only read (see `Data`).
        let inp = Data::Complex(SendPtr(samples.as_ptr().cast_mut()));
        self.run_forward(batch, inp, coeffs, scratch.as_deref())
    }

    /// [`PartialPlan::inverse_many`] in the caller's `scratch` if given (one transform).
    fn inverse_in(
        &self,
        batch: Batch,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(false, false, batch, coeffs.len(), samples.len())?;
        let out = Data::Complex(SendPtr(samples.as_mut_ptr()));
        self.run_inverse(batch, coeffs, out, (scratch.as_deref(), None))
    }

    /// [`PartialPlan::forward_real_many`] in the caller's `scratch` if given (one
    /// transform).
    fn forward_real_in(
        &self,
        batch: Batch,
        samples: &[T],
        coeffs: &mut [Complex<T>],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(true, true, batch, samples.len(), coeffs.len())?;
        // The samples are only read (see `Data`).
        let inp = Data::Real(SendPtr(samples.as_ptr().cast_mut()));
        self.run_forward(batch, inp, coeffs, scratch.as_deref())
    }

    /// [`PartialPlan::inverse_real_many`] in the caller's `scratch` if given (one
    /// transform).
    fn inverse_real_in(
        &self,
        batch: Batch,
        coeffs: &[Complex<T>],
        samples: &mut [T],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(false, true, batch, coeffs.len(), samples.len())?;
        let out = Data::Real(SendPtr(samples.as_mut_ptr()));
        self.run_inverse(batch, coeffs, out, (scratch.as_deref(), None))
    }

    /// Input and output lengths of one transform.
    fn sizes(&self, forward: bool) -> (usize, usize) {
        if forward {
            (self.num_samples(), self.num_coeffs())
        } else {
            (self.num_coeffs(), self.num_samples())
        }
    }

    fn check(&self, forward: bool, real: bool, b: Batch, inp: usize, out: usize) -> Result<()> {
        self.engine.workers.check_process()?;
        self.direction.check_runs(forward)?;
        if real && !self.real {
            return Err(Error::InvalidArgument(
                "real-signal transform on a plan made without the real option".into(),
            ));
        }
        let (ilen, olen) = self.sizes(forward);
        let (iname, oname) = if forward {
            ("samples", "coefficients")
        } else {
            ("coefficients", "samples")
        };
        if b.count == 0 {
            return Err(Error::InvalidArgument("batch of 0 transforms".into()));
        }
        if b.count > 1 && b.out_dist < olen {
            return Err(Error::InvalidArgument(format!(
                "batch: outputs {} values apart overlap (each has {olen})",
                b.out_dist
            )));
        }
        let need = |dist: usize, len: usize| {
            dist.checked_mul(b.count - 1)
                .and_then(|x| x.checked_add(len))
                .unwrap_or(usize::MAX)
        };
        if inp < need(b.in_dist, ilen) {
            return Err(Error::LengthMismatch {
                what: iname,
                expected: need(b.in_dist, ilen),
                got: inp,
            });
        }
        if out < need(b.out_dist, olen) {
            return Err(Error::LengthMismatch {
                what: oname,
                expected: need(b.out_dist, olen),
                got: out,
            });
        }
        if b.count == 1 && (inp != ilen || out != olen) {
            let (what, expected, got) = if inp != ilen {
                (iname, ilen, inp)
            } else {
                (oname, olen, out)
            };
            return Err(Error::LengthMismatch {
                what,
                expected,
                got,
            });
        }
        Ok(())
    }
}

/// A batch of one for arrays of these lengths.
fn one(inp: usize, out: usize) -> Batch {
    Batch {
        count: 1,
        in_dist: inp,
        out_dist: out,
    }
}

impl<T: Real> Transform<T> for PartialPlan<T> {
    fn num_samples(&self) -> usize {
        PartialPlan::<T>::num_samples(self)
    }

    fn num_coeffs(&self) -> usize {
        PartialPlan::<T>::num_coeffs(self)
    }

    fn scratch_bytes(&self) -> usize {
        PartialPlan::<T>::scratch_bytes(self)
    }

    fn forward(&self, samples: &[Complex<T>], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        PartialPlan::<T>::forward(self, samples, coeffs)
    }

    fn inverse(&self, coeffs: &[Complex<T>], samples: &mut [Complex<T>]) -> Result<StageTimes> {
        PartialPlan::<T>::inverse(self, coeffs, samples)
    }

    fn forward_real(&self, samples: &[T], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        PartialPlan::<T>::forward_real(self, samples, coeffs)
    }

    fn inverse_real(&self, coeffs: &[Complex<T>], samples: &mut [T]) -> Result<StageTimes> {
        PartialPlan::<T>::inverse_real(self, coeffs, samples)
    }

    fn forward_with_scratch(
        &self,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(samples.len(), coeffs.len());
        self.forward_in(b, samples, coeffs, Some(scratch))
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.inverse_in(b, coeffs, samples, Some(scratch))
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[T],
        coeffs: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(samples.len(), coeffs.len());
        self.forward_real_in(b, samples, coeffs, Some(scratch))
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [T],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.inverse_real_in(b, coeffs, samples, Some(scratch))
    }
}

/// Whether a plan of `need` bytes fits in the available memory, and with the caller's
/// `arrays` in the machine (true where the system does not say).
fn fits_in_memory(need: usize, arrays: usize) -> bool {
    match (mem_available(), mem_total()) {
        (Some(avail), Some(total)) => need <= avail && need.saturating_add(arrays) <= total,
        _ => true,
    }
}
