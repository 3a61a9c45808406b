//! [`PartialPlan`]: the public face of a partial plan: construction (the choice between
//! [`Plan`] for the full shape and the general engine, `general.rs`), the argument checks
//! and the transforms, single and batched.

use super::betas::LanePairs;
use super::general::{Data, General};
use super::options::Batch;
use super::shape::Shape;
use crate::error::{Error, Result};
use crate::options::{Betas, Direction, Options};
use crate::plan::{Plan, SliceWatch, StageTimes};
use crate::simd::Isa;
use crate::transform::{Scratch, Transform};
use crate::workers::{SendConstPtr, SendPtr, WorkerPool};
use num_complex::Complex64;

enum Engine {
    Full(Box<Plan>),
    General(Box<General>),
}

/// A transform on SO(3) that computes only what a [`Shape`] holds: band-limited,
/// order-limited, oversampled or undersampled in alpha and gamma, restricted to some
/// betas, several at once ([`Batch`]), complex or real.
///
/// The full shape ([`Shape::new`]) with all betas runs on [`Plan`]; everything else on
/// the general engine: the DWT kernels per cluster of order pairs over chunks of beta
/// pairs, and pruned slice DFTs. Execution takes `&self`; one plan may run on different
/// arrays from several threads.
pub struct PartialPlan {
    shape: Shape,
    direction: Direction,
    real: bool,
    threads: usize,
    n_slices: usize,
    engine: Engine,
}

impl PartialPlan {
    /// A plan for `shape` with `options`.
    pub fn new(shape: &Shape, options: &Options) -> Result<PartialPlan> {
        PartialPlan::new_on(shape, options, None)
    }

    /// [`PartialPlan::new`] on the workers of `shared` if given (with the plan's thread
    /// count).
    pub(crate) fn new_on(
        shape: &Shape,
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<PartialPlan> {
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
        let skip = options.skip()?;
        options.check_workspace()?;
        let pairs = LanePairs::new(shape, &options.betas, Some(isa.lanes()))?;
        let n_slices = pairs.n_slices;
        let engine = if shape.is_full() && !restricted && !options.general_engine {
            let po = Options {
                direction,
                threads,
                isa: Some(isa),
                ..options.clone()
            };
            Engine::Full(Box::new(Plan::new_on(shape.degree_limit, &po, shared)?))
        } else {
            Engine::General(Box::new(General::new(
                shape,
                pairs,
                (isa, skip, threads),
                options,
                shared,
            )?))
        };
        Ok(PartialPlan {
            shape: *shape,
            direction,
            real: options.real,
            threads,
            n_slices,
            engine,
        })
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

    /// Whether the plan runs on [`Plan`] (the full shape) rather than the general engine.
    pub fn uses_full_plan(&self) -> bool {
        matches!(self.engine, Engine::Full(_))
    }

    /// The number of chunks a single inverse (complex, or `real`) on the general engine
    /// runs as one chain (their buffers in the output, each cluster's coefficients read
    /// once), 0 where it runs them one by one or on [`Plan`]. For tests and benchmarks.
    #[doc(hidden)]
    pub fn chained_inverse_chunks(&self, real: bool) -> usize {
        match &self.engine {
            Engine::Full(_) => 0,
            Engine::General(g) => g.chained_chunks(real),
        }
    }

    /// Coefficients of one transform ([`Shape::num_coeffs`]).
    pub fn num_coeffs(&self) -> usize {
        match &self.engine {
            Engine::Full(p) => p.num_coeffs(),
            Engine::General(g) => g.layout.total,
        }
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
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        self.forward_in(one(samples.len(), coeffs.len()), samples, coeffs, None)
    }

    /// Inverse: coefficients to samples; the time of each stage.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        self.inverse_in(one(coeffs.len(), samples.len()), coeffs, samples, None)
    }

    /// Forward of a real signal (`num_samples` doubles): every coefficient block written.
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        self.forward_real_in(one(samples.len(), coeffs.len()), samples, coeffs, None)
    }

    /// Inverse to a real signal: reads only the blocks `M' > 0`, or `M' = 0` and `M >= 0`,
    /// and takes the others as `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        self.inverse_real_in(one(coeffs.len(), samples.len()), coeffs, samples, None)
    }

    /// Bytes of [`Scratch`] a single transform with scratch needs.
    pub fn scratch_bytes(&self) -> usize {
        match &self.engine {
            Engine::Full(p) => p.workspace_bytes(),
            Engine::General(g) => g.scratch_bytes(),
        }
    }

    /// [`PartialPlan::inverse`] that shows every output slice to `watch` as it is
    /// computed, where the plan runs on [`Plan`] (the full shape); `Ok(false)` (and
    /// `watch` never called) on the general engine.
    pub(crate) fn inverse_watched(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        watch: SliceWatch,
    ) -> Result<bool> {
        match &self.engine {
            Engine::Full(p) if self.direction != Direction::Forward => {
                p.inverse_watched(coeffs, samples, watch).map(|()| true)
            }
            _ => self.inverse(coeffs, samples).map(|_| false),
        }
    }

    /// [`PartialPlan::inverse_real`] with a watch, as [`PartialPlan::inverse_watched`].
    pub(crate) fn inverse_real_watched(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        watch: SliceWatch,
    ) -> Result<bool> {
        match &self.engine {
            Engine::Full(p) if self.real && self.direction != Direction::Forward => p
                .inverse_real_watched(coeffs, samples, watch)
                .map(|()| true),
            _ => self.inverse_real(coeffs, samples).map(|_| false),
        }
    }

    /// `batch.count` forwards; the time of each stage.
    pub fn forward_many(
        &self,
        batch: Batch,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.forward_in(batch, samples, coeffs, None)
    }

    /// `batch.count` inverses; the time of each stage.
    pub fn inverse_many(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.inverse_in(batch, coeffs, samples, None)
    }

    /// `batch.count` real forwards; the time of each stage.
    pub fn forward_real_many(
        &self,
        batch: Batch,
        samples: &[f64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.forward_real_in(batch, samples, coeffs, None)
    }

    /// `batch.count` real inverses; the time of each stage.
    pub fn inverse_real_many(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [f64],
    ) -> Result<StageTimes> {
        self.inverse_real_in(batch, coeffs, samples, None)
    }

    /// [`PartialPlan::forward_many`] in the caller's `scratch` if given (one transform).
    fn forward_in(
        &self,
        batch: Batch,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(true, false, batch, samples.len(), coeffs.len())?;
        match (&self.engine, scratch) {
            (Engine::Full(p), Some(s)) => p.forward_with_scratch(samples, coeffs, s),
            (Engine::Full(p), None) => full_many(batch, self.sizes(true), |i, o| {
                p.forward(&samples[i..][..o.0], &mut coeffs[o.1..][..o.2])
            }),
            (Engine::General(g), s) => g.forward(
                batch,
                SendConstPtr(samples.as_ptr().cast()),
                SendPtr(coeffs.as_mut_ptr()),
                (false, s.as_deref()),
            ),
        }
    }

    /// [`PartialPlan::inverse_many`] in the caller's `scratch` if given (one transform).
    fn inverse_in(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(false, false, batch, coeffs.len(), samples.len())?;
        match (&self.engine, scratch) {
            (Engine::Full(p), Some(s)) => p.inverse_with_scratch(coeffs, samples, s),
            (Engine::Full(p), None) => full_many(batch, self.sizes(false), |i, o| {
                p.inverse(&coeffs[i..][..o.0], &mut samples[o.1..][..o.2])
            }),
            (Engine::General(g), s) => g.inverse(
                batch,
                SendConstPtr(coeffs.as_ptr()),
                Data::Complex(SendPtr(samples.as_mut_ptr())),
                s.as_deref(),
            ),
        }
    }

    /// [`PartialPlan::forward_real_many`] in the caller's `scratch` if given (one
    /// transform).
    fn forward_real_in(
        &self,
        batch: Batch,
        samples: &[f64],
        coeffs: &mut [Complex64],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(true, true, batch, samples.len(), coeffs.len())?;
        match (&self.engine, scratch) {
            (Engine::Full(p), Some(s)) => p.forward_real_with_scratch(samples, coeffs, s),
            (Engine::Full(p), None) => full_many(batch, self.sizes(true), |i, o| {
                p.forward_real(&samples[i..][..o.0], &mut coeffs[o.1..][..o.2])
            }),
            (Engine::General(g), s) => g.forward(
                batch,
                SendConstPtr(samples.as_ptr().cast()),
                SendPtr(coeffs.as_mut_ptr()),
                (true, s.as_deref()),
            ),
        }
    }

    /// [`PartialPlan::inverse_real_many`] in the caller's `scratch` if given (one
    /// transform).
    fn inverse_real_in(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [f64],
        scratch: Option<&mut Scratch>,
    ) -> Result<StageTimes> {
        self.check(false, true, batch, coeffs.len(), samples.len())?;
        match (&self.engine, scratch) {
            (Engine::Full(p), Some(s)) => p.inverse_real_with_scratch(coeffs, samples, s),
            (Engine::Full(p), None) => full_many(batch, self.sizes(false), |i, o| {
                p.inverse_real(&coeffs[i..][..o.0], &mut samples[o.1..][..o.2])
            }),
            (Engine::General(g), s) => g.inverse(
                batch,
                SendConstPtr(coeffs.as_ptr()),
                Data::Real(SendPtr(samples.as_mut_ptr())),
                s.as_deref(),
            ),
        }
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
        if let Engine::General(g) = &self.engine {
            // (A full plan checks its own.)
            g.workers.check_process()?;
        }
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

/// A batch on the full plan: `run(in_offset, (in_len, out_offset, out_len))` per transform.
fn full_many(
    b: Batch,
    (ilen, olen): (usize, usize),
    mut run: impl FnMut(usize, (usize, usize, usize)) -> Result<StageTimes>,
) -> Result<StageTimes> {
    let mut sum = StageTimes::default();
    for t in 0..b.count {
        sum += run(t * b.in_dist, (ilen, t * b.out_dist, olen))?;
    }
    Ok(sum)
}

impl Transform for PartialPlan {
    fn num_samples(&self) -> usize {
        PartialPlan::num_samples(self)
    }

    fn num_coeffs(&self) -> usize {
        PartialPlan::num_coeffs(self)
    }

    fn scratch_bytes(&self) -> usize {
        PartialPlan::scratch_bytes(self)
    }

    fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        PartialPlan::forward(self, samples, coeffs)
    }

    fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        PartialPlan::inverse(self, coeffs, samples)
    }

    fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        PartialPlan::forward_real(self, samples, coeffs)
    }

    fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        PartialPlan::inverse_real(self, coeffs, samples)
    }

    fn forward_with_scratch(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(samples.len(), coeffs.len());
        self.forward_in(b, samples, coeffs, Some(scratch))
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.inverse_in(b, coeffs, samples, Some(scratch))
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[f64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(samples.len(), coeffs.len());
        self.forward_real_in(b, samples, coeffs, Some(scratch))
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let b = one(coeffs.len(), samples.len());
        self.inverse_real_in(b, coeffs, samples, Some(scratch))
    }
}
