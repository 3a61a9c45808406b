//! Rotational matching: the correlation of two functions on the sphere over the rotations
//! of the SO(3) grid ([`Correlation`]), the combination of their S^2 coefficients
//! ([`combine`]), the grid's peak ([`grid_argmax`]), peaks refined off the grid
//! ([`So3Series::maximise`]) and the rotation of functions on the sphere
//! ([`rotate_s2_coeffs`]).
//!
//! Conventions (`docs/conventions-s2.md`): `C(g) = int f(x) conj(h(g^-1 x)) dx`; its peak is
//! the rotation `g = Rz(alpha) Ry(beta) Rz(gamma)` that maps the pattern `h` onto the
//! signal `f`, `f(x) ~ h(g^-1 x)`.

mod combine;
mod correlation;
mod find;
mod peaks;
mod refine;
mod rotation;
pub mod scene;
mod series;
mod uncertainty;
mod weights;

pub use combine::combine;
pub use correlation::{Correlation, CorrelationOptions};
pub use find::Match;
pub(crate) use peaks::SliceArgmax;
pub use peaks::{grid_argmax, grid_argmax_real, top_peaks, top_peaks_real, Peak};
pub use refine::So3Series;
pub use rotation::{rotate_s2_coeffs, rotate_s2_coeffs_to, Rotation};
pub use uncertainty::Uncertainty;
pub use weights::{degree_powers, noise_floor, noise_weights, DegreeWeights, Spectra};
