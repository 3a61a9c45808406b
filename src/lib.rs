//! # so3fft
//!
//! Fast Fourier transform on the rotation group SO(3) and its inverse, after Kostelec and
//! Rockmore's FSOFT with the symmetry-clustered parallel discrete Wigner transform of
//! Lux, Wülker and Chirikjian. Conventions, sample and coefficient layouts are SOFT 2.0's
//! (see `docs/conventions.md`): samples `f(alpha_j1, beta_k, gamma_j2)` at index
//! `k (2B)^2 + j1 (2B) + j2`, coefficients in `so3CoefLoc` order.
//!
//! ```
//! use so3fft::{Complex64, Options, Plan};
//! let b = 8;
//! let plan = Plan::new(b, &Options::default()).unwrap();
//! let mut coeffs = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
//! coeffs[so3fft::coef_index(b, 3, -1, 2)] = Complex64::new(1.0, 0.5);
//! let mut samples = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
//! plan.inverse(&coeffs, &mut samples).unwrap();
//! let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
//! plan.forward(&samples, &mut back).unwrap();
//! assert!((back[so3fft::coef_index(b, 3, -1, 2)] - coeffs[so3fft::coef_index(b, 3, -1, 2)]).norm() < 1e-13);
//! ```

#![warn(missing_docs)]
#![deny(unsafe_op_in_unsafe_fn)]
#![deny(clippy::undocumented_unsafe_blocks)]

mod batch;
mod capi;
pub mod distributed;
mod dwt;
mod engine;
mod error;
mod ffi;
mod fft;
mod grid;
#[cfg(feature = "internals")]
#[doc(hidden)]
pub mod internals;
pub mod matching;
mod numeric;
mod options;
pub mod partial;
mod plan;
mod real;
pub mod s2;
mod shape;
mod simd;
mod soft;
mod symmetry;
mod system;
mod transform;
pub mod wigner;
mod workers;

pub use batch::Batch;
pub use distributed::{DistributedPlan, Exchange, ThreadExchange};
pub use error::{Error, Result};
pub use fft::{wisdom, Rigor};
pub use grid::MAX_BANDWIDTH;
pub use grid::{
    alpha, beta, coef_index, gamma, num_coeffs, num_samples, sample_index, try_coef_index, weights,
};
pub use num_complex::{Complex, Complex32, Complex64};
pub use options::{Betas, Direction, FftThreading, Options};
pub use partial::PartialPlan;
pub use plan::Plan;
pub use real::Real;
pub use shape::Shape;
pub use simd::{Isa, ISA_VARIABLE};
pub use transform::{Scratch, StageTimes, Transform};
