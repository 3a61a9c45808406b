//! The whole matching pipeline in one call: the correlation grid and its peak, the peak
//! refined off the grid, how sure it is and how far it stands out.

use super::correlation::Correlation;
use super::peaks::{top_peaks, top_peaks_real, Peak};
use super::rotation::Rotation;
use super::uncertainty::Uncertainty;
use super::weights::Spectra;
use crate::error::Result;
use crate::grid::num_coeffs;
use crate::Real;
use num_complex::{Complex, Complex64};

/// The rotation that best maps a pattern onto a signal, and how sure it is
/// ([`Correlation::find`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Match {
    /// The peak refined off the grid.
    pub rotation: Rotation,
    /// `|C|^2` at [`Match::rotation`].
    pub value: f64,
    /// The grid's largest `|C|^2`, where the refinement started.
    pub grid_peak: Peak,
    /// The error to expect of [`Match::rotation`] from the noise in the inputs.
    pub uncertainty: Uncertainty,
    /// `|C|` at the peak over `|C|` at the next peak at least [`Match::separation`] away
    /// (both refined): near 1, the inputs cannot tell the two apart; infinite when the grid
    /// has no other peak.
    pub peak_ratio: f64,
    /// The angle (radians) beyond which another peak counts as separate: twice the grid
    /// step of the highest degree weighted at least a tenth of the largest weight.
    pub separation: f64,
    /// The inputs' spectra, noise floors and the degree weights applied.
    pub spectra: Spectra,
}

impl<T: Real> Correlation<T> {
    /// The correlation of complex samples into `grid` ([`Correlation::correlate_argmax`]),
    /// its peak refined ([`Correlation::refine`]), the peak's [`Uncertainty`] and its ratio
    /// to the next separate peak.
    pub fn find(
        &self,
        signal: &[Complex<T>],
        pattern: &[Complex<T>],
        grid: &mut [Complex<T>],
    ) -> Result<Match> {
        let best = self.correlate_argmax(signal, pattern, grid)?;
        let mut coeffs = vec![Complex64::default(); num_coeffs(self.b_out())];
        let spectra = self.coefficients_spectra((signal, pattern), &mut coeffs)?;
        let separation = separation(&spectra.weights);
        let others = top_peaks(self.b_out(), grid, 2, separation);
        self.finish((best, &others, separation), (&coeffs, spectra))
    }

    /// [`Correlation::find`] of real samples.
    pub fn find_real(&self, signal: &[T], pattern: &[T], grid: &mut [T]) -> Result<Match> {
        let best = self.correlate_real_argmax(signal, pattern, grid)?;
        let mut coeffs = vec![Complex64::default(); num_coeffs(self.b_out())];
        let spectra = self.coefficients_spectra_real((signal, pattern), &mut coeffs)?;
        let separation = separation(&spectra.weights);
        let others = top_peaks_real(self.b_out(), grid, 2, separation);
        self.finish((best, &others, separation), (&coeffs, spectra))
    }

    /// Refines the best grid peak and the next one of `peaks` at least `separation` from
    /// it, and assesses the best.
    fn finish(
        &self,
        (best, peaks, separation): (Peak, &[Peak], f64),
        (coeffs, spectra): (&[Complex64], Spectra),
    ) -> Result<Match> {
        let start = best.rotation();
        // The next peak: the first of the top two not within the separation of the best.
        let next = peaks
            .iter()
            .find(|p| p.rotation().angle_to(&start) >= separation);
        let mut starts = vec![start];
        starts.extend(next.map(Peak::rotation));
        let refined = self.refine_many(coeffs, &starts)?;
        let (rotation, value) = refined[0];
        // A second start that climbed onto the best peak says nothing of another peak:
        // its grid value is then the ratio's best estimate.
        let peak_ratio = match (refined.get(1), next) {
            (Some(&(g, v)), _) if v > 0.0 && g.angle_to(&rotation) >= 0.5 * separation => {
                (value / v).sqrt()
            }
            (_, Some(p)) if p.value > 0.0 => (best.value / p.value).sqrt(),
            _ => f64::INFINITY,
        };
        let uncertainty = self.uncertainty(coeffs, &rotation, &spectra)?;
        Ok(Match {
            rotation,
            value,
            grid_peak: best,
            uncertainty,
            peak_ratio,
            separation,
            spectra,
        })
    }
}

/// `2 pi / (L + 1)`, `L` the highest degree weighted at least a tenth of the largest.
fn separation(weights: &[f64]) -> f64 {
    let max = weights.iter().fold(0.0f64, |m, &w| m.max(w));
    let top = weights.iter().rposition(|&w| w >= 0.1 * max).unwrap_or(0);
    2.0 * std::f64::consts::PI / (top + 1) as f64
}
