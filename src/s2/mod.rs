//! Spherical-harmonic transforms on S^2 ([`S2Plan`]), on the grid and in the conventions of
//! SOFT 2.0 (`docs/conventions-s2.md`).
//!
//! A transform is a DFT over `phi` of each ring (`rings`) and, per order `m`, a sum over
//! the rings of the associated Legendre functions (`legendre`), which are the Wigner
//! `d^l_{m,0}`: the SO(3) transforms' recurrence, starting values and kernels do that
//! part. `layout`: the coefficient order (`seanindex`).

mod layout;
mod legendre;
mod plan;
mod rings;

pub(crate) use layout::order_start;
pub use layout::{s2_coef_index, s2_num_coeffs, s2_num_samples, s2_try_coef_index};
pub use plan::{S2Limits, S2Plan, S2_MAX_BANDWIDTH};
