//! [`Correlation`]: the rotational correlation of two functions on the sphere over the SO(3)
//! grid, by two S^2 forward transforms, the combination of their coefficients and one
//! inverse SO(3) transform.

use super::combine::combine;
use crate::error::{Error, Result};
use crate::grid::num_coeffs;
use crate::s2::{S2Options, S2Plan};
use crate::{Direction, Plan, PlanOptions, Rigor};
use num_complex::Complex64;
use std::sync::Mutex;

/// Options of a [`Correlation`].
#[derive(Clone, Debug, Default)]
pub struct CorrelationOptions {
    /// Bandwidth of the SO(3) grid the correlation is evaluated on (`None`: the input
    /// bandwidth; larger values sample it more finely).
    pub b_out: Option<usize>,
    /// Highest degree combined (`None`: `min(b_in, b_out) - 1`).
    pub deg_lim: Option<usize>,
    /// Real inputs: a real correlation through the real-signal inverse (about half the work).
    pub real: bool,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// FFTW planner rigour.
    pub rigor: Rigor,
}

/// Coefficient arrays of one correlation (signal, pattern, SO(3)).
struct Buffers {
    sig: Vec<Complex64>,
    pat: Vec<Complex64>,
    so3: Vec<Complex64>,
}

/// The correlation `C(g) = int_{S^2} f(x) conj(h(g^-1 x)) dx` of a signal `f` and a pattern
/// `h` of bandwidth `b_in` (samples on SOFT's S^2 grid), for every rotation `g` of the SO(3)
/// grid of bandwidth `b_out`, stored like the SO(3) samples (beta slowest, gamma fastest;
/// see `docs/conventions.md`). `C` is largest where the signal is the pattern rotated by
/// `g = Rz(alpha) Ry(beta) Rz(gamma)`: `f(x) = h(g^-1 x)`.
pub struct Correlation {
    b_in: usize,
    b_out: usize,
    deg_lim: usize,
    real: bool,
    s2: S2Plan,
    so3: Plan,
    buffers: Mutex<Option<Buffers>>,
}

impl Correlation {
    /// A correlation plan for inputs of bandwidth `b_in`.
    pub fn new(b_in: usize, options: &CorrelationOptions) -> Result<Correlation> {
        let b_out = options.b_out.unwrap_or(b_in);
        let deg_lim = options.deg_lim.unwrap_or(b_in.min(b_out).saturating_sub(1));
        if b_in == 0 || b_out == 0 || deg_lim >= b_in.min(b_out) {
            return Err(Error::InvalidArgument(format!(
                "correlation of bandwidth {b_in} on the grid of bandwidth {b_out} with degree \
                 limit {deg_lim}: need 1 <= bandwidths and degree limit < both"
            )));
        }
        let s2 = S2Plan::new(
            b_in,
            &S2Options {
                threads: options.threads,
                rigor: options.rigor,
                isa: None,
            },
        )?;
        let so3 = Plan::new(
            b_out,
            &PlanOptions {
                direction: Direction::Inverse,
                threads: options.threads,
                rigor: options.rigor,
                real: options.real,
                ..PlanOptions::default()
            },
        )?;
        Ok(Correlation {
            b_in,
            b_out,
            deg_lim,
            real: options.real,
            s2,
            so3,
            buffers: Mutex::new(None),
        })
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

    /// Runs `f` with the plan's coefficient buffers (new ones when they are in use).
    fn with_buffers<R>(&self, f: impl FnOnce(&mut Buffers) -> Result<R>) -> Result<R> {
        let fresh = || -> Result<Buffers> {
            let vec = |n: usize| -> Result<Vec<Complex64>> {
                let mut v = Vec::new();
                v.try_reserve_exact(n)
                    .map_err(|_| Error::OutOfMemory { bytes: 16 * n })?;
                v.resize(n, Complex64::default());
                Ok(v)
            };
            let n = self.b_in * self.b_in;
            Ok(Buffers {
                sig: vec(n)?,
                pat: vec(n)?,
                so3: vec(num_coeffs(self.b_out))?,
            })
        };
        match self.buffers.try_lock() {
            Ok(mut guard) => {
                if guard.is_none() {
                    *guard = Some(fresh()?);
                }
                f(guard.as_mut().expect("just made"))
            }
            Err(_) => f(&mut fresh()?),
        }
    }

    /// The SO(3) coefficients of the correlation of complex samples (`(4 b_out^3 - b_out)/3`
    /// values, for [`So3Series`](super::So3Series) and peak refinement).
    pub fn coefficients(
        &self,
        signal: &[Complex64],
        pattern: &[Complex64],
        out: &mut [Complex64],
    ) -> Result<()> {
        let n = self.b_in * self.b_in;
        let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        self.s2.forward(signal, &mut sig)?;
        self.s2.forward(pattern, &mut pat)?;
        combine((&sig, &pat), self.b_in, self.deg_lim, self.b_out, out)
    }

    /// [`Correlation::coefficients`] of real samples.
    pub fn coefficients_real(
        &self,
        signal: &[f64],
        pattern: &[f64],
        out: &mut [Complex64],
    ) -> Result<()> {
        let n = self.b_in * self.b_in;
        let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        self.s2.forward_real(signal, &mut sig)?;
        self.s2.forward_real(pattern, &mut pat)?;
        combine((&sig, &pat), self.b_in, self.deg_lim, self.b_out, out)
    }

    /// Whether the plan takes real inputs.
    pub fn is_real(&self) -> bool {
        self.real
    }

    /// Highest degree combined.
    pub fn deg_lim(&self) -> usize {
        self.deg_lim
    }

    /// The correlation of complex samples (`(2 b_in)^2` each) into `out` (`(2 b_out)^3`).
    /// For a plan made with `real`, use [`Correlation::correlate_real`].
    pub fn correlate(
        &self,
        signal: &[Complex64],
        pattern: &[Complex64],
        out: &mut [Complex64],
    ) -> Result<()> {
        if self.real {
            return Err(Error::InvalidArgument(
                "complex correlation asked of a plan made for real inputs".into(),
            ));
        }
        self.with_buffers(|buf| {
            self.s2.forward(signal, &mut buf.sig)?;
            self.s2.forward(pattern, &mut buf.pat)?;
            combine(
                (&buf.sig, &buf.pat),
                self.b_in,
                self.deg_lim,
                self.b_out,
                &mut buf.so3,
            )?;
            self.so3.inverse(&buf.so3, out)
        })
    }

    /// The correlation of real samples into the real grid `out` (plan made with `real`).
    pub fn correlate_real(&self, signal: &[f64], pattern: &[f64], out: &mut [f64]) -> Result<()> {
        if !self.real {
            return Err(Error::InvalidArgument(
                "real correlation asked of a plan made for complex inputs".into(),
            ));
        }
        self.with_buffers(|buf| {
            self.s2.forward_real(signal, &mut buf.sig)?;
            self.s2.forward_real(pattern, &mut buf.pat)?;
            combine(
                (&buf.sig, &buf.pat),
                self.b_in,
                self.deg_lim,
                self.b_out,
                &mut buf.so3,
            )?;
            self.so3.inverse_real(&buf.so3, out)
        })
    }
}
