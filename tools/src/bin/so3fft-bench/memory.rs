//! Resident memory of this process: current (`VmRSS`) and peak (`VmHWM`) from
//! `/proc/self/status`, and a reset of the peak so that one phase can be measured alone.
//!
//! Linux resets the peak resident set size to the current one when `5` is written to
//! `/proc/self/clear_refs` (since Linux 4.0). Where that file or `/proc` is missing the
//! functions return `None` / `false` and the bench prints n/a.

/// Resident set size now, in bytes.
pub fn rss_bytes() -> Option<u64> {
    status_field("VmRSS:")
}

/// Peak resident set size since the start or the last [`reset_peak`], in bytes.
pub fn peak_bytes() -> Option<u64> {
    status_field("VmHWM:")
}

/// Resets the peak to the current resident set size; `false` if the kernel refused.
pub fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn status_field(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Peak memory of one measured phase.
#[derive(Clone, Copy, Debug, Default)]
pub struct Phase {
    /// Resident bytes when the phase started (after the reset).
    pub start: u64,
    /// Peak resident bytes during the phase.
    pub peak: u64,
}

/// Resets the peak, runs `f` and reports the phase's peak (`None` if not measurable).
///
/// The peak is process-wide, so phases are serialised by a lock: a reset by a second phase
/// (another test thread, say) in the middle of this one would erase its peak.
pub fn measure<R>(f: impl FnOnce() -> R) -> (R, Option<Phase>) {
    static PHASE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _guard = PHASE.lock().unwrap_or_else(|e| e.into_inner());
    let ok = reset_peak();
    let start = rss_bytes();
    let r = f();
    let phase = match (ok, start, peak_bytes()) {
        (true, Some(start), Some(peak)) => Some(Phase { start, peak }),
        _ => None,
    };
    (r, phase)
}

#[cfg(test)]
mod tests {
    use super::measure;

    #[test]
    fn peak_follows_a_large_allocation_and_resets() {
        let Some((_, Some(before))) = Some(measure(|| ())) else {
            eprintln!("peak RSS not measurable here: skipped");
            return;
        };
        let (_, phase) = measure(|| {
            let v = vec![1u8; 64 << 20];
            std::hint::black_box(&v);
        });
        let phase = phase.unwrap();
        assert!(phase.peak >= phase.start + (60 << 20), "{phase:?}");
        let (_, after) = measure(|| ());
        let after = after.unwrap();
        assert!(
            after.peak < before.peak + (16 << 20),
            "{after:?} vs {before:?}"
        );
    }
}
