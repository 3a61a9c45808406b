//! The FFTW stage: 2-D DFTs of beta slices over (alpha, gamma).
//!
//! FFTW's planner is not thread-safe, and the host program may use FFTW too: every planner
//! call (plan creation and destruction) holds the global planner lock, and
//! `fftw_make_planner_thread_safe()` is called once so planning from the host's own threads
//! is serialised with ours. Executing a plan on new arrays is thread-safe, so slices are
//! transformed in parallel on the plan's rayon pool.
//!
//! FFTW's process-wide thread setting: every plan is single-threaded (it runs inside the
//! library's workers); a host that has set FFTW's thread count for new plans above 1
//! keeps its setting, which is set to 1 only for the duration of each of the library's
//! planner calls, under the planner lock.
//!
//! - `planner`: the planner lock, owned FFTW plans;
//! - `buf`: page-aligned buffers and row copies;
//! - `wisdom`: FFTW's wisdom, exported and imported.

mod buf;
mod planner;
pub mod wisdom;

pub(crate) use buf::{copy_rows, AlignedBuf, ChunkBuffer};
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
