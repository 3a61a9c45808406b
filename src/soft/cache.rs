//! The plan cache of the SOFT layer: one plan per bandwidth, made on first use and kept for
//! the life of the process.

use super::SoftResult;
use crate::ffi::CallError;
use crate::{Direction, Plan, PlanOptions, Rigor};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

/// One slot per bandwidth; the slot's own lock serialises creation of that plan only.
type Slot = Arc<Mutex<Option<Arc<Plan>>>>;

static CACHE: Mutex<BTreeMap<usize, Slot>> = Mutex::new(BTreeMap::new());

/// Plan options of the cached plans (environment read once).
fn cache_options() -> &'static PlanOptions {
    static OPTS: OnceLock<PlanOptions> = OnceLock::new();
    OPTS.get_or_init(|| {
        let threads = std::env::var("SO3FFT_SOFT_THREADS")
            .ok()
            .and_then(|s| s.trim().parse::<usize>().ok())
            .unwrap_or(0);
        let rigor = match std::env::var("SO3FFT_SOFT_RIGOR")
            .unwrap_or_default()
            .trim()
            .to_ascii_lowercase()
            .as_str()
        {
            "estimate" => Rigor::Estimate,
            "patient" => Rigor::Patient,
            "exhaustive" => Rigor::Exhaustive,
            _ => Rigor::Measure,
        };
        PlanOptions {
            direction: Direction::Both,
            threads,
            rigor,
            // flag = 1 calls use the engine's real-signal path.
            real: true,
            ..PlanOptions::default()
        }
    })
}

/// The cached plan of bandwidth `b`, created on first use. A failed creation is not cached.
pub(super) fn plan_for(b: usize) -> SoftResult<Arc<Plan>> {
    let slot: Slot = {
        let mut map = CACHE.lock().unwrap_or_else(PoisonError::into_inner);
        map.entry(b).or_default().clone()
    };
    let mut g = slot.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(p) = g.as_ref() {
        if p.in_own_process() {
            return Ok(Arc::clone(p));
        }
        // A child after fork(): the cached plan's worker threads are the parent's. Make a
        // new one (dropping the old one in this process does not wait for them).
    }
    let p = Arc::new(
        Plan::new(b, cache_options())
            .map_err(|e| CallError::from(e).context(&format!("cannot plan bandwidth {b}")))?,
    );
    *g = Some(Arc::clone(&p));
    Ok(p)
}
