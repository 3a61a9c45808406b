//! The FFTW stage: 2-D DFTs of beta slices over (alpha, gamma).
//!
//! Both precisions go through FFTW: `f64` through libfftw3 (`fftw_*`), `f32` through
//! libfftw3f (`fftwf_*`), reached by code generic over the element type through
//! [`FftwApi`] (`T::plan_many_dft`, `T::execute_dft`, ...; plans are [`RawPlan<T>`]).
//!
//! FFTW's planner is not thread-safe, and the host program may use FFTW too: every planner
//! call (plan creation and destruction) of either library holds the global planner lock,
//! and `fftw_make_planner_thread_safe()` and `fftwf_make_planner_thread_safe()` are called
//! once so planning from the host's own threads is serialised with ours. Executing a plan on
//! new arrays is thread-safe, so slices are transformed in parallel on the plan's rayon pool.
//!
//! FFTW's process-wide thread setting: every plan is single-threaded (it runs inside the
//! library's workers); a host that has set FFTW's thread count for new plans above 1
//! keeps its setting, which is set to 1 only for the duration of each of the library's
//! planner calls, under the planner lock.
//!
//! - `api`: the FFTW functions of each precision ([`FftwApi`]);
//! - `planner`: the planner lock, owned FFTW plans;
//! - `buf`: page-aligned buffers and row copies;
//! - `wisdom`: FFTW's wisdom, exported and imported (one store per precision).

mod api;
mod buf;
mod planner;
#[cfg(test)]
pub(crate) mod tests;
pub mod wisdom;

pub(crate) use api::FftwApi;
pub(crate) use buf::{copy_rows, AlignedBuf, ChunkBuffer, Plain};
pub(crate) use planner::{plan_guarded, planning_bytes, RawPlan};

use fftw_sys as fftw;

/// FFTW planner rigour (FFTW_ESTIMATE ... FFTW_EXHAUSTIVE).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Rigor {
    /// Heuristic plan, no measurement (fast planning).
    #[default]
    Estimate,
    /// Measure a few candidates (planning takes up to a second; faster transforms).
    Measure,
    /// Measure more candidates.
    Patient,
    /// Measure everything.
    Exhaustive,
}

impl Rigor {
    /// The FFTW planner flag of this rigour.
    pub(crate) fn flags(self) -> u32 {
        match self {
            Rigor::Estimate => fftw::FFTW_ESTIMATE,
            Rigor::Measure => fftw::FFTW_MEASURE,
            Rigor::Patient => fftw::FFTW_PATIENT,
            Rigor::Exhaustive => fftw::FFTW_EXHAUSTIVE,
        }
    }
}

/// Sign of the exponent: `+1` is FFTW_BACKWARD (used by the forward SO(3) transform).
pub(crate) const SIGN_PLUS: i32 = fftw::FFTW_BACKWARD as i32;
/// `-1` is FFTW_FORWARD (used by the inverse SO(3) transform).
pub(crate) const SIGN_MINUS: i32 = fftw::FFTW_FORWARD;
