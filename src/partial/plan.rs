//! [`PartialPlan`]: the public face of a partial plan: construction (the choice between
//! [`Plan`] for the full shape and the general engine, `general.rs`), the argument checks
//! and the transforms, single and batched.

use super::betas::{Betas, LanePairs};
use super::general::{Data, General};
use super::options::{skip_bits, Batch, PartialOptions};
use super::shape::Shape;
use crate::error::{Error, Result};
use crate::plan::{Direction, Plan, PlanOptions, SliceWatch, StageTimes};
use crate::simd::Isa;
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
    pub fn new(shape: &Shape, options: &PartialOptions) -> Result<PartialPlan> {
        PartialPlan::new_on(shape, options, None)
    }

    /// [`PartialPlan::new`] on the workers of `shared` if given (with the plan's thread
    /// count).
    pub(crate) fn new_on(
        shape: &Shape,
        options: &PartialOptions,
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
        let bits = skip_bits(options.skip_bits)?;
        if let Some(0) = options.max_workspace_bytes {
            return Err(Error::InvalidArgument("max_workspace_bytes is 0".into()));
        }
        let pairs = LanePairs::new(shape, &options.betas, Some(isa.lanes()))?;
        let n_slices = pairs.n_slices;
        let engine = if shape.is_full() && !restricted && !options.general_engine {
            let po = PlanOptions {
                direction,
                threads,
                rigor: options.rigor,
                max_workspace_bytes: options.max_workspace_bytes,
                isa: Some(isa),
                skip_bits: Some(bits),
                real: options.real,
                ..PlanOptions::default()
            };
            Engine::Full(Box::new(Plan::new_on(shape.degree_limit, &po, shared)?))
        } else {
            Engine::General(Box::new(General::new(
                shape,
                pairs,
                (isa, bits, threads),
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

    /// Forward: samples to coefficients.
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<()> {
        self.forward_many(one(samples.len(), coeffs.len()), samples, coeffs)
            .map(|_| ())
    }

    /// Inverse: coefficients to samples.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<()> {
        self.inverse_many(one(coeffs.len(), samples.len()), coeffs, samples)
            .map(|_| ())
    }

    /// Forward of a real signal (`num_samples` doubles): every coefficient block written.
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<()> {
        self.forward_real_many(one(samples.len(), coeffs.len()), samples, coeffs)
            .map(|_| ())
    }

    /// Inverse to a real signal: reads only the blocks `M' > 0`, or `M' = 0` and `M >= 0`,
    /// and takes the others as `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<()> {
        self.inverse_real_many(one(coeffs.len(), samples.len()), coeffs, samples)
            .map(|_| ())
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
            _ => self.inverse(coeffs, samples).map(|()| false),
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
            _ => self.inverse_real(coeffs, samples).map(|()| false),
        }
    }

    /// `batch.count` forwards; the time of each stage.
    pub fn forward_many(
        &self,
        batch: Batch,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, false, batch, samples.len(), coeffs.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(true), |i, o| {
                p.forward_timed(&samples[i..][..o.0], &mut coeffs[o.1..][..o.2])
            }),
            Engine::General(g) => g.forward(
                batch,
                SendConstPtr(samples.as_ptr().cast()),
                SendPtr(coeffs.as_mut_ptr()),
                false,
            ),
        }
    }

    /// `batch.count` inverses; the time of each stage.
    pub fn inverse_many(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(false, false, batch, coeffs.len(), samples.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(false), |i, o| {
                p.inverse_timed(&coeffs[i..][..o.0], &mut samples[o.1..][..o.2])
            }),
            Engine::General(g) => g.inverse(
                batch,
                SendConstPtr(coeffs.as_ptr()),
                Data::Complex(SendPtr(samples.as_mut_ptr())),
            ),
        }
    }

    /// `batch.count` real forwards; the time of each stage.
    pub fn forward_real_many(
        &self,
        batch: Batch,
        samples: &[f64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, true, batch, samples.len(), coeffs.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(true), |i, o| {
                p.forward_real_timed(&samples[i..][..o.0], &mut coeffs[o.1..][..o.2])
            }),
            Engine::General(g) => g.forward(
                batch,
                SendConstPtr(samples.as_ptr().cast()),
                SendPtr(coeffs.as_mut_ptr()),
                true,
            ),
        }
    }

    /// `batch.count` real inverses; the time of each stage.
    pub fn inverse_real_many(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [f64],
    ) -> Result<StageTimes> {
        self.check(false, true, batch, coeffs.len(), samples.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(false), |i, o| {
                p.inverse_real_timed(&coeffs[i..][..o.0], &mut samples[o.1..][..o.2])
            }),
            Engine::General(g) => g.inverse(
                batch,
                SendConstPtr(coeffs.as_ptr()),
                Data::Real(SendPtr(samples.as_mut_ptr())),
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
