//! [`Correlation`]: the rotational correlation of two functions on the sphere over the SO(3)
//! grid, by two S^2 forward transforms, the combination of their coefficients and one
//! inverse SO(3) transform.

use super::combine::{add_combined, Combine};
use super::peaks::{Peak, SliceArgmax};
use super::series::SeriesTables;
use super::uncertainty::{uncertainty, NoiseModel, Uncertainty};
use super::weights::{degree_powers, DegreeWeights, Spectra};
use crate::engine::SliceRef;
use crate::error::{check_length, Error, Result};
use crate::grid::{coef_index, num_coeffs};
use crate::options::{Betas, Direction, Options};
use crate::partial::PartialPlan;
use crate::s2::{S2Limits, S2Plan};
use crate::shape::Shape;
use crate::transform::StageTimes;
use crate::workers::WorkerPool;
use crate::Real;
use num_complex::{Complex, Complex64};
use std::any::{Any, TypeId};
use std::borrow::Cow;
use std::sync::{Arc, Mutex, OnceLock};

/// `x` as values of `W`: the slice itself where `U` is `W` (a plan in `f64`), else each
/// value widened by `widen`.
fn widened<U: Copy + 'static, W: Copy + 'static>(x: &[U], widen: impl Fn(U) -> W) -> Cow<'_, [W]> {
    if TypeId::of::<U>() == TypeId::of::<W>() {
        // SAFETY: `U` and `W` are the same type, so the slice's values are `W`s.
        Cow::Borrowed(unsafe { std::slice::from_raw_parts(x.as_ptr().cast::<W>(), x.len()) })
    } else {
        Cow::Owned(x.iter().map(|&u| widen(u)).collect())
    }
}

/// What a [`Correlation`] computes, and the [`Options`] of its plans. Made with
/// [`CorrelationOptions::default`] and the `with_*` setters (the type is
/// `#[non_exhaustive]`: fields may be added).
#[non_exhaustive]
#[derive(Clone, Debug, Default)]
pub struct CorrelationOptions {
    /// Bandwidth of the SO(3) grid the correlation is evaluated on (`None`: the input
    /// bandwidth; larger values sample it more finely).
    pub b_out: Option<usize>,
    /// Highest degree combined (`None`: `min(b_in, b_out) - 1`).
    pub deg_lim: Option<usize>,
    /// Real inputs: a real correlation through the real-signal inverse (about half the work).
    pub real: bool,
    /// Normalised cross-correlation: the degree-0 terms (the means) left out and the result
    /// divided by the norms of signal and pattern over degrees `1..=deg_lim`, so that
    /// `|C| <= 1`, with 1 where the signal is an exactly rotated, scaled and shifted copy
    /// of the pattern.
    pub normalized: bool,
    /// Options of the correlation's S^2 and SO(3) plans (threads, rigour, instruction set,
    /// skip threshold); their direction and real form follow from the correlation.
    pub plans: Options,
    /// Weights of the degrees (`w_0..=w_deg_lim`): uniform, given, or estimated from the
    /// inputs' noise at each call. With `normalized`, the norms are weighted too.
    pub weights: DegreeWeights,
}

impl CorrelationOptions {
    /// With [`CorrelationOptions::b_out`].
    pub fn with_b_out(mut self, b_out: Option<usize>) -> CorrelationOptions {
        self.b_out = b_out;
        self
    }

    /// With [`CorrelationOptions::deg_lim`].
    pub fn with_deg_lim(mut self, deg_lim: Option<usize>) -> CorrelationOptions {
        self.deg_lim = deg_lim;
        self
    }

    /// With [`CorrelationOptions::real`].
    pub fn with_real(mut self, real: bool) -> CorrelationOptions {
        self.real = real;
        self
    }

    /// With [`CorrelationOptions::normalized`].
    pub fn with_normalized(mut self, normalized: bool) -> CorrelationOptions {
        self.normalized = normalized;
        self
    }

    /// With [`CorrelationOptions::plans`].
    pub fn with_plans(mut self, plans: Options) -> CorrelationOptions {
        self.plans = plans;
        self
    }

    /// With [`CorrelationOptions::weights`].
    pub fn with_weights(mut self, weights: DegreeWeights) -> CorrelationOptions {
        self.weights = weights;
        self
    }

    /// With the plans' [`Options::threads`].
    pub fn with_threads(mut self, threads: usize) -> CorrelationOptions {
        self.plans.threads = threads;
        self
    }
}

/// Coefficient arrays of one correlation (signal, pattern, SO(3)) in `C`.
struct Buffers<C> {
    sig: Vec<Complex<C>>,
    pat: Vec<Complex<C>>,
    /// The combined coefficients in the layout of bandwidth `deg_lim + 1`: the inverse
    /// plan's input (all higher degrees are zero).
    so3: Vec<Complex<C>>,
}

impl<C: Real> Buffers<C> {
    /// Zeroed buffers for inputs of bandwidth `b_in` combined up to `deg_lim`.
    fn new(b_in: usize, deg_lim: usize) -> Result<Buffers<C>> {
        let vec = |n: usize| -> Result<Vec<Complex<C>>> {
            let mut v = Vec::new();
            v.try_reserve_exact(n).map_err(|_| Error::OutOfMemory {
                bytes: 2 * C::BYTES * n,
            })?;
            v.resize(n, Complex::new(C::ZERO, C::ZERO));
            Ok(v)
        };
        Ok(Buffers {
            sig: vec(b_in * b_in)?,
            pat: vec(b_in * b_in)?,
            so3: vec(num_coeffs(deg_lim + 1))?,
        })
    }
}

/// The S^2 forward of one kind of samples into coefficients of `C`.
type S2Forward<'a, X, C> = &'a (dyn Fn(&[X], &mut [Complex<C>]) -> Result<StageTimes> + Sync);

/// The correlation `C(g) = int_{S^2} f(x) conj(h(g^-1 x)) dx` of a signal `f` and a pattern
/// `h` of bandwidth `b_in` (samples on SOFT's S^2 grid), for every rotation `g` of the SO(3)
/// grid of bandwidth `b_out`, stored like the SO(3) samples (beta slowest, gamma fastest;
/// see `docs/conventions.md`). `C` is largest where the signal is the pattern rotated by
/// `g = Rz(alpha) Ry(beta) Rz(gamma)`: `f(x) = h(g^-1 x)`.
///
/// `T` is the precision of the samples, the grid and the transforms: `f64`, or `f32` for
/// about half the time and memory. The SO(3) coefficients for refinement
/// ([`Correlation::coefficients`]) are always computed in `f64` from the samples (exactly
/// widened), so a refined rotation is the same in both precisions.
pub struct Correlation<T: Real = f64> {
    b_in: usize,
    b_out: usize,
    deg_lim: usize,
    real: bool,
    normalized: bool,
    weights: DegreeWeights,
    s2: S2Plan<T>,
    /// The inverse onto the grid: degrees `l <= deg_lim` (bandwidth `deg_lim + 1`).
    so3: PartialPlan<T>,
    buffers: Mutex<Option<Buffers<T>>>,
    /// Tables of [`So3Series`](super::So3Series) for refinement, built on first use.
    series: OnceLock<Arc<SeriesTables>>,
    /// An `f64` S^2 plan for the coefficients of an `f32` correlation, made on first use.
    s2_wide: OnceLock<S2Plan<f64>>,
    /// An `f64` S^2 plan of every degree for [`Correlation::spectra`] where neither plan
    /// is one, made on first use.
    s2_full: OnceLock<S2Plan<f64>>,
    /// The options the plans were made with (for `s2_wide`).
    plans: Options,
    workers: WorkerPool,
}

impl<T: Real> Correlation<T> {
    /// A correlation plan for inputs of bandwidth `b_in`.
    pub fn new(b_in: usize, options: &CorrelationOptions) -> Result<Correlation<T>> {
        let b_out = options.b_out.unwrap_or(b_in);
        let deg_lim = options.deg_lim.unwrap_or(b_in.min(b_out).saturating_sub(1));
        if b_in == 0 || b_out == 0 || deg_lim >= b_in.min(b_out) {
            return Err(Error::InvalidArgument(format!(
                "correlation of bandwidth {b_in} on the grid of bandwidth {b_out} with degree \
                 limit {deg_lim}: need 1 <= bandwidths and degree limit < both"
            )));
        }
        options.weights.check(deg_lim, options.normalized)?;
        // One pool for both plans: an execution enters it once, and each stage of the
        // pipeline runs on its workers directly (at small bandwidths waking the workers
        // for every stage cost as much as the stages).
        let threads = crate::workers::thread_count(options.plans.threads)?;
        let workers = WorkerPool::process(threads)?;
        let s2 = S2Plan::new_on(
            b_in,
            Self::s2_limits(deg_lim, &options.weights),
            &options.plans,
            Some(&workers),
        )?;
        // Degrees up to `deg_lim` on the grid of `b_out`: a partial plan when that is less
        // than the grid's bandwidth (the full plan otherwise).
        let so3 = PartialPlan::new_on(
            &Shape::new(deg_lim + 1).with_grid(b_out, 2 * b_out, 2 * b_out),
            &Options {
                direction: Direction::Inverse,
                real: options.real,
                betas: Betas::All,
                ..options.plans.clone()
            },
            Some(&workers),
        )?;
        Ok(Correlation {
            b_in,
            b_out,
            deg_lim,
            real: options.real,
            normalized: options.normalized,
            weights: options.weights.clone(),
            s2,
            so3,
            buffers: Mutex::new(None),
            series: OnceLock::new(),
            s2_wide: OnceLock::new(),
            s2_full: OnceLock::new(),
            plans: options.plans.clone(),
            workers,
        })
    }

    /// The S^2 plans' limits: only the combined degrees are needed, unless the weights
    /// are estimated from the noise at the high degrees.
    fn s2_limits(deg_lim: usize, weights: &DegreeWeights) -> S2Limits {
        S2Limits {
            degree_limit: (*weights != DegreeWeights::Automatic).then_some(deg_lim + 1),
            order_limit: None,
        }
    }

    /// Whether the S^2 plans compute every degree of the input.
    fn s2_complete(&self) -> bool {
        self.weights == DegreeWeights::Automatic || self.deg_lim + 1 == self.b_in
    }

    /// An `f64` S^2 plan of every degree: the plan's own where it is one.
    fn s2_every_degree(&self) -> Result<&S2Plan<f64>> {
        if self.s2_complete() {
            return self.s2_f64();
        }
        if let Some(p) = self.s2_full.get() {
            return Ok(p);
        }
        let made = S2Plan::new_on(
            self.b_in,
            S2Limits::default(),
            &self.plans,
            Some(&self.workers),
        )?;
        Ok(self.s2_full.get_or_init(|| made))
    }

    /// The plan's S^2 plan in `f64`: its own for `T = f64`, else one made on first use.
    fn s2_f64(&self) -> Result<&S2Plan<f64>> {
        if let Some(own) = (&self.s2 as &dyn Any).downcast_ref::<S2Plan<f64>>() {
            return Ok(own);
        }
        if let Some(p) = self.s2_wide.get() {
            return Ok(p);
        }
        let made = S2Plan::new_on(
            self.b_in,
            Self::s2_limits(self.deg_lim, &self.weights),
            &self.plans,
            Some(&self.workers),
        )?;
        Ok(self.s2_wide.get_or_init(|| made))
    }

    /// Input bandwidth.
    pub fn b_in(&self) -> usize {
        self.b_in
    }

    /// Bandwidth of the output grid.
    pub fn b_out(&self) -> usize {
        self.b_out
    }

    /// Values of the output grid, `(2 b_out)^3`.
    pub fn num_grid(&self) -> usize {
        self.so3.num_samples()
    }

    /// Runs `f` with the plan's coefficient buffers (new ones when they are in use), on
    /// the plans' worker threads.
    fn with_buffers<R: Send>(
        &self,
        f: impl FnOnce(&mut Buffers<T>) -> Result<R> + Send,
    ) -> Result<R> {
        self.s2.install(|| self.with_buffers_here(f))
    }

    /// [`Correlation::with_buffers`] on the calling thread.
    fn with_buffers_here<R>(&self, f: impl FnOnce(&mut Buffers<T>) -> Result<R>) -> Result<R> {
        self.with_buffers_in(&self.buffers, f)
    }

    /// Runs `f` with the buffers kept in `slot` (made on first use; new ones when they are
    /// in use).
    fn with_buffers_in<C: Real, R>(
        &self,
        slot: &Mutex<Option<Buffers<C>>>,
        f: impl FnOnce(&mut Buffers<C>) -> Result<R>,
    ) -> Result<R> {
        let fresh = || Buffers::new(self.b_in, self.deg_lim);
        match slot.try_lock() {
            Ok(mut guard) => {
                if guard.is_none() {
                    *guard = Some(fresh()?);
                }
                f(guard.as_mut().expect("just made"))
            }
            Err(_) => f(&mut fresh()?),
        }
    }

    /// Adds shell `(signal, pattern, weight)`'s combined coefficients to `buf.so3`, or
    /// writes them (`mode`) (with `forward` the S^2 transform of the samples); with
    /// `normalized`, from degree 1 on, and the weighted squared norms of degrees
    /// `1..=deg_lim` added to `norms`.
    fn add_shell<X, C: Real>(
        &self,
        (signal, pattern, weight): (&[X], &[X], f64),
        (forward, half, mode): (S2Forward<X, C>, bool, Combine),
        buf: &mut Buffers<C>,
        norms: &mut [f64; 2],
    ) -> Result<()> {
        if !weight.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "shell weight {weight} is not finite"
            )));
        }
        forward(signal, &mut buf.sig)?;
        forward(pattern, &mut buf.pat)?;
        let from = usize::from(self.normalized);
        // The automatic weights' estimate has the degree powers the norms need.
        let (degree_weights, powers) = match &self.weights {
            DegreeWeights::Uniform => (vec![1.0; self.deg_lim + 1], None),
            DegreeWeights::Given(w) => (w.clone(), None),
            DegreeWeights::Automatic => {
                let s =
                    Spectra::estimate((&buf.sig, &buf.pat), self.b_in, self.deg_lim, &self.weights);
                (s.weights, Some([s.signal_power, s.pattern_power]))
            }
        };
        if self.normalized {
            let powers =
                powers.unwrap_or_else(|| [&buf.sig, &buf.pat].map(|c| degree_powers(c, self.b_in)));
            for (norm, powers) in norms.iter_mut().zip(powers) {
                let sq: f64 = (from..=self.deg_lim)
                    .map(|l| degree_weights[l] * powers[l])
                    .sum();
                *norm += weight.abs() * sq;
            }
        }
        let factors: Vec<f64> = degree_weights.iter().map(|w| w * weight).collect();
        let (sig, pat, so3) = (&buf.sig, &buf.pat, &mut buf.so3);
        // On the plan's workers (the orders spread over them).
        self.s2.install(|| {
            add_combined(
                (sig, pat),
                self.b_in,
                (from, self.deg_lim),
                self.deg_lim + 1,
                (&factors, so3),
                (half, mode),
            )
        });
        Ok(())
    }

    /// The SO(3) coefficients of the weighted sum over `shells` into `buf.so3` (normalised
    /// if the plan says so); with `half`, only those a real-signal inverse reads.
    fn combine_shells<X, C: Real>(
        &self,
        shells: &[(&[X], &[X], f64)],
        (forward, half): (S2Forward<X, C>, bool),
        buf: &mut Buffers<C>,
    ) -> Result<()> {
        if shells.is_empty() {
            return Err(Error::InvalidArgument("no shells given".into()));
        }
        let mut norms = [0.0; 2];
        // The first shell writes every coefficient the inverse reads, the others add.
        for (k, &shell) in shells.iter().enumerate() {
            let mode = if k == 0 {
                Combine::Assign
            } else {
                Combine::Add
            };
            self.add_shell(shell, (forward, half, mode), buf, &mut norms)?;
        }
        if self.normalized {
            let denominator = (norms[0] * norms[1]).sqrt();
            let scale = if denominator > 0.0 {
                1.0 / denominator
            } else {
                0.0
            };
            let scale = |x: C| C::from_f64(x.to_f64() * scale);
            buf.so3
                .iter_mut()
                .for_each(|c| *c = Complex::new(scale(c.re), scale(c.im)));
        }
        Ok(())
    }

    /// The SO(3) coefficients of the correlation of complex samples (`(4 b_out^3 - b_out)/3`
    /// values, for [`So3Series`](super::So3Series) and peak refinement), in `f64` whatever
    /// `T` is.
    pub fn coefficients(
        &self,
        signal: &[Complex<T>],
        pattern: &[Complex<T>],
        out: &mut [Complex64],
    ) -> Result<()> {
        let s2 = self.s2_f64()?;
        let wide = |z: Complex<T>| Complex64::new(z.re.to_f64(), z.im.to_f64());
        let fwd = |x: &[Complex<T>], c: &mut [Complex64]| s2.forward(&widened(x, wide), c);
        self.coefficients_in((signal, pattern), &fwd, out, false)
            .map(|_| ())
    }

    /// [`Correlation::coefficients`] of real samples.
    pub fn coefficients_real(
        &self,
        signal: &[T],
        pattern: &[T],
        out: &mut [Complex64],
    ) -> Result<()> {
        let s2 = self.s2_f64()?;
        let fwd = |x: &[T], c: &mut [Complex64]| s2.forward_real(&widened(x, T::to_f64), c);
        self.coefficients_in((signal, pattern), &fwd, out, false)
            .map(|_| ())
    }

    /// [`Correlation::coefficients`] and [`Correlation::spectra`] of complex samples, the
    /// S^2 transforms shared where the plan's cover every degree.
    pub(crate) fn coefficients_spectra(
        &self,
        (signal, pattern): (&[Complex<T>], &[Complex<T>]),
        out: &mut [Complex64],
    ) -> Result<Spectra> {
        let s2 = self.s2_f64()?;
        let wide = |z: Complex<T>| Complex64::new(z.re.to_f64(), z.im.to_f64());
        let fwd = |x: &[Complex<T>], c: &mut [Complex64]| s2.forward(&widened(x, wide), c);
        match self.coefficients_in((signal, pattern), &fwd, out, true)? {
            Some(spectra) => Ok(spectra),
            None => self.spectra(signal, pattern),
        }
    }

    /// [`Correlation::coefficients_spectra`] of real samples.
    pub(crate) fn coefficients_spectra_real(
        &self,
        (signal, pattern): (&[T], &[T]),
        out: &mut [Complex64],
    ) -> Result<Spectra> {
        let s2 = self.s2_f64()?;
        let fwd = |x: &[T], c: &mut [Complex64]| s2.forward_real(&widened(x, T::to_f64), c);
        match self.coefficients_in((signal, pattern), &fwd, out, true)? {
            Some(spectra) => Ok(spectra),
            None => self.spectra_real(signal, pattern),
        }
    }

    /// The body of the `coefficients` functions, with the `f64` S^2 forward `fwd`; with
    /// `spectra`, also the inputs' [`Spectra`] where the S^2 plans cover every degree.
    fn coefficients_in<X: Sync>(
        &self,
        (signal, pattern): (&[X], &[X]),
        fwd: S2Forward<X, f64>,
        out: &mut [Complex64],
        spectra: bool,
    ) -> Result<Option<Spectra>> {
        let mut run = |buf: &mut Buffers<f64>| {
            self.combine_shells(&[(signal, pattern, 1.0)], (fwd, false), buf)?;
            self.widen(&buf.so3, out)?;
            Ok((spectra && self.s2_complete()).then(|| {
                Spectra::estimate((&buf.sig, &buf.pat), self.b_in, self.deg_lim, &self.weights)
            }))
        };
        self.s2.install(|| {
            // A plan in f64 uses its own buffers; one in f32 makes f64 ones for the call.
            match (&self.buffers as &dyn Any).downcast_ref::<Mutex<Option<Buffers<f64>>>>() {
                Some(own) => self.with_buffers_in(own, run),
                None => run(&mut Buffers::new(self.b_in, self.deg_lim)?),
            }
        })
    }

    /// The rotation near `start` where `|C|^2` of the correlation with SO(3) coefficients
    /// `coeffs` (from [`Correlation::coefficients`]) is largest, and `|C|^2` there
    /// ([`So3Series::maximise`](super::So3Series::maximise) on the plan's threads).
    pub fn refine(
        &self,
        coeffs: &[Complex64],
        start: &super::Rotation,
    ) -> Result<(super::Rotation, f64)> {
        Ok(self.refine_many(coeffs, std::slice::from_ref(start))?[0])
    }

    /// [`Correlation::refine`] from every rotation of `starts`, in lock step
    /// ([`So3Series::maximise_many`](super::So3Series::maximise_many): one pass over the
    /// coefficients per step serves all peaks).
    pub fn refine_many(
        &self,
        coeffs: &[Complex64],
        starts: &[super::Rotation],
    ) -> Result<Vec<(super::Rotation, f64)>> {
        check_length("SO(3) coefficients", num_coeffs(self.b_out), coeffs.len())?;
        if let Some(g) = starts.iter().find(|g| !g.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "start rotation {g:?} is not finite"
            )));
        }
        Ok(self.s2.install(|| {
            let tables = self
                .series
                .get_or_init(|| Arc::new(SeriesTables::new(self.b_out, self.deg_lim)))
                .clone();
            super::So3Series::with_tables(tables, coeffs).maximise_many(starts)
        }))
    }

    /// The power spectra of complex samples `signal` and `pattern`, their noise floors and
    /// the degree weights the plan applies to them (computed in `f64`, as for
    /// [`Correlation::coefficients`]).
    pub fn spectra(&self, signal: &[Complex<T>], pattern: &[Complex<T>]) -> Result<Spectra> {
        self.need(false)?;
        let s2 = self.s2_every_degree()?;
        let wide = |z: Complex<T>| Complex64::new(z.re.to_f64(), z.im.to_f64());
        let fwd = |x: &[Complex<T>], c: &mut [Complex64]| s2.forward(&widened(x, wide), c);
        self.spectra_in((signal, pattern), &fwd)
    }

    /// [`Correlation::spectra`] of real samples.
    pub fn spectra_real(&self, signal: &[T], pattern: &[T]) -> Result<Spectra> {
        self.need(true)?;
        let s2 = self.s2_every_degree()?;
        let fwd = |x: &[T], c: &mut [Complex64]| s2.forward_real(&widened(x, T::to_f64), c);
        self.spectra_in((signal, pattern), &fwd)
    }

    fn spectra_in<X: Sync>(
        &self,
        (signal, pattern): (&[X], &[X]),
        fwd: S2Forward<X, f64>,
    ) -> Result<Spectra> {
        let n = self.b_in * self.b_in;
        let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        self.s2.install(|| -> Result<()> {
            fwd(signal, &mut sig)?;
            fwd(pattern, &mut pat)?;
            Ok(())
        })?;
        Ok(Spectra::estimate(
            (&sig, &pat),
            self.b_in,
            self.deg_lim,
            &self.weights,
        ))
    }

    /// How sure the peak `at` (refined with [`Correlation::refine`] from `coeffs`) is, with
    /// the noise of the inputs `spectra` ([`Correlation::spectra`] of the same samples):
    /// the covariance of its error from the curvature of `|C|` at `at` and the noise's
    /// share of each degree (`docs/matching-noise.md`). A linear estimate: it holds while
    /// the error is small against the peak's width and the peak is the right one (see
    /// the peak ratio of [`Correlation::find`](Correlation::find)).
    pub fn uncertainty(
        &self,
        coeffs: &[Complex64],
        at: &super::Rotation,
        spectra: &Spectra,
    ) -> Result<Uncertainty> {
        check_length("SO(3) coefficients", num_coeffs(self.b_out), coeffs.len())?;
        check_length("degree weights", self.deg_lim + 1, spectra.weights.len())?;
        for (what, p) in [
            ("signal power", &spectra.signal_power),
            ("pattern power", &spectra.pattern_power),
        ] {
            check_length(what, self.b_in, p.len())?;
        }
        if !at.is_finite() {
            return Err(Error::InvalidArgument(format!(
                "rotation {at:?} is not finite"
            )));
        }
        let model = NoiseModel {
            spectra,
            real: self.real,
            normalized: self.normalized,
        };
        Ok(self.s2.install(|| {
            let tables = self
                .series
                .get_or_init(|| Arc::new(SeriesTables::new(self.b_out, self.deg_lim)))
                .clone();
            uncertainty(&super::So3Series::with_tables(tables, coeffs), at, &model)
        }))
    }

    /// The plan's degree weights.
    pub fn weights(&self) -> &DegreeWeights {
        &self.weights
    }

    /// Whether the plan takes real inputs.
    pub fn is_real(&self) -> bool {
        self.real
    }

    /// Highest degree combined.
    pub fn deg_lim(&self) -> usize {
        self.deg_lim
    }

    /// `small` (the layout of bandwidth `deg_lim + 1`) into `out` in the layout of
    /// bandwidth `b_out`, zero above `deg_lim`.
    fn widen(&self, small: &[Complex64], out: &mut [Complex64]) -> Result<()> {
        check_length("SO(3) coefficients", num_coeffs(self.b_out), out.len())?;
        let l = self.deg_lim + 1;
        if l == self.b_out {
            out.copy_from_slice(small);
            return Ok(());
        }
        out.fill(Complex64::default());
        let lim = self.deg_lim as isize;
        for m in -lim..=lim {
            for mp in -lim..=lim {
                let lo = m.unsigned_abs().max(mp.unsigned_abs());
                let from = coef_index(l, lo, m, mp);
                let to = coef_index(self.b_out, lo, m, mp);
                out[to..to + l - lo].copy_from_slice(&small[from..from + l - lo]);
            }
        }
        Ok(())
    }

    /// An error unless the plan takes inputs of this kind (`real` or complex).
    pub(crate) fn need(&self, real: bool) -> Result<()> {
        if real != self.real {
            return Err(Error::InvalidArgument(format!(
                "{} correlation asked of a plan made for {} inputs",
                if real { "real" } else { "complex" },
                if self.real { "real" } else { "complex" }
            )));
        }
        Ok(())
    }

    /// The correlation of complex samples (`(2 b_in)^2` each) into `out` (`(2 b_out)^3`).
    /// For a plan made with `real`, use [`Correlation::correlate_real`].
    pub fn correlate(
        &self,
        signal: &[Complex<T>],
        pattern: &[Complex<T>],
        out: &mut [Complex<T>],
    ) -> Result<()> {
        self.correlate_shells(&[(signal, pattern, 1.0)], out)
    }

    /// The correlation of real samples into the real grid `out` (plan made with `real`).
    pub fn correlate_real(&self, signal: &[T], pattern: &[T], out: &mut [T]) -> Result<()> {
        self.correlate_shells_real(&[(signal, pattern, 1.0)], out)
    }

    /// The weighted sum `sum_s w_s C_s` of the correlations of several shells (pairs of
    /// signal and pattern samples, e.g. the radial shells of two volumes): one pair of S^2
    /// transforms per shell and one inverse SO(3) transform.
    #[allow(clippy::type_complexity)]
    pub fn correlate_shells(
        &self,
        shells: &[(&[Complex<T>], &[Complex<T>], f64)],
        out: &mut [Complex<T>],
    ) -> Result<()> {
        self.need(false)?;
        self.with_buffers(|buf| {
            let fwd = |x: &[Complex<T>], c: &mut [Complex<T>]| self.s2.forward(x, c);
            self.combine_shells(shells, (&fwd, false), buf)?;
            self.so3.inverse(&buf.so3, out).map(|_| ())
        })
    }

    /// [`Correlation::correlate_shells`] of real samples.
    pub fn correlate_shells_real(&self, shells: &[(&[T], &[T], f64)], out: &mut [T]) -> Result<()> {
        self.need(true)?;
        self.with_buffers(|buf| {
            let fwd = |x: &[T], c: &mut [Complex<T>]| self.s2.forward_real(x, c);
            self.combine_shells(shells, (&fwd, true), buf)?;
            self.so3.inverse_real(&buf.so3, out).map(|_| ())
        })
    }

    /// [`Correlation::correlate`] and the grid's largest `|C|^2` ([`grid_argmax`](super::grid_argmax): the
    /// same point, value and tie rule), found while the inverse computes each slice of the
    /// grid instead of in a second pass over it.
    pub fn correlate_argmax(
        &self,
        signal: &[Complex<T>],
        pattern: &[Complex<T>],
        out: &mut [Complex<T>],
    ) -> Result<Peak> {
        self.need(false)?;
        self.with_buffers(|buf| {
            let fwd = |x: &[Complex<T>], c: &mut [Complex<T>]| self.s2.forward(x, c);
            self.combine_shells(&[(signal, pattern, 1.0)], (&fwd, false), buf)?;
            let seen = SliceArgmax::new(self.b_out);
            let watch = |k: usize, s: SliceRef<T>| seen.watch(k, s);
            self.so3.inverse_watched(&buf.so3, out, &watch)?;
            Ok(seen.peak())
        })
    }

    /// [`Correlation::correlate_real`] and the grid's largest `C^2`
    /// ([`grid_argmax_real`](super::grid_argmax_real)), as [`Correlation::correlate_argmax`].
    pub fn correlate_real_argmax(
        &self,
        signal: &[T],
        pattern: &[T],
        out: &mut [T],
    ) -> Result<Peak> {
        self.need(true)?;
        self.with_buffers(|buf| {
            let fwd = |x: &[T], c: &mut [Complex<T>]| self.s2.forward_real(x, c);
            self.combine_shells(&[(signal, pattern, 1.0)], (&fwd, true), buf)?;
            let seen = SliceArgmax::new(self.b_out);
            let watch = |k: usize, s: SliceRef<T>| seen.watch(k, s);
            self.so3.inverse_real_watched(&buf.so3, out, &watch)?;
            Ok(seen.peak())
        })
    }

    /// One signal against `howmany` patterns stored one after another (`howmany (2 b_in)^2`
    /// samples) into `howmany` grids stored one after another: the signal is transformed
    /// once.
    pub fn correlate_many(
        &self,
        signal: &[Complex<T>],
        patterns: &[Complex<T>],
        out: &mut [Complex<T>],
    ) -> Result<()> {
        self.need(false)?;
        let forward = |x: &[Complex<T>], c: &mut [Complex<T>]| self.s2.forward(x, c);
        let inverse = |c: &[Complex<T>], g: &mut [Complex<T>]| self.so3.inverse(c, g);
        self.many((signal, patterns, out), (forward, false), inverse)
    }

    /// [`Correlation::correlate_many`] of real samples.
    pub fn correlate_many_real(&self, signal: &[T], patterns: &[T], out: &mut [T]) -> Result<()> {
        self.need(true)?;
        let forward = |x: &[T], c: &mut [Complex<T>]| self.s2.forward_real(x, c);
        let inverse = |c: &[Complex<T>], g: &mut [T]| self.so3.inverse_real(c, g);
        self.many((signal, patterns, out), (forward, true), inverse)
    }

    /// The body of the `correlate_many` functions, with the S^2 forward and SO(3) inverse
    /// of the plan's kind of samples.
    fn many<X: Sync, G: Send>(
        &self,
        (signal, patterns, out): (&[X], &[X], &mut [G]),
        (forward, half): (
            impl Fn(&[X], &mut [Complex<T>]) -> Result<StageTimes> + Sync,
            bool,
        ),
        inverse: impl Fn(&[Complex<T>], &mut [G]) -> Result<StageTimes> + Sync,
    ) -> Result<()> {
        let (ns, ng) = (4 * self.b_in * self.b_in, self.num_grid());
        check_many(patterns.len(), ns, out.len(), ng)?;
        self.with_buffers(|buf| {
            let mut sig = vec![Complex::new(T::ZERO, T::ZERO); self.b_in * self.b_in];
            forward(signal, &mut sig)?;
            // The signal's transform is made once; the patterns' each time.
            let known = |x: &[X], c: &mut [Complex<T>]| {
                if std::ptr::eq(x, signal) {
                    c.copy_from_slice(&sig);
                    Ok(StageTimes::default())
                } else {
                    forward(x, c)
                }
            };
            for (pattern, grid) in patterns.chunks_exact(ns).zip(out.chunks_exact_mut(ng)) {
                self.combine_shells(&[(signal, pattern, 1.0)], (&known, half), buf)?;
                inverse(&buf.so3, grid)?;
            }
            Ok(())
        })
    }
}

/// An error unless `patterns` holds a positive number of fields of `ns` and `out` as many
/// of `ng`.
fn check_many(patterns: usize, ns: usize, out: usize, ng: usize) -> Result<()> {
    if patterns == 0 || !patterns.is_multiple_of(ns) {
        return Err(Error::InvalidArgument(format!(
            "{patterns} pattern samples are not a positive multiple of {ns}"
        )));
    }
    check_length("correlation grids", patterns / ns * ng, out)
}
