//! FFTW wisdom: the FFTW plans chosen by measurement, saved and restored.
//!
//! Planning with [`Rigor::Measure`](crate::Rigor) or stronger times candidate FFTW
//! algorithms, which takes seconds at large bandwidths and may pick different algorithms in
//! different processes (results then differ in the last bits). Wisdom exported once and
//! imported before planning makes FFTW take the recorded algorithms without measuring:
//! planning is fast and every process gets the same FFTW plans, hence the same bits (see
//! `docs/c-api.md`, "FFTW wisdom", for what else must match).
//!
//! FFTW's wisdom is process-wide: these functions see and change the host program's
//! FFTW wisdom too. They hold the planner lock.

use super::planner::planner_lock;
use crate::error::{Error, Result};
use crate::system::check_headroom;
use fftw_sys as fftw;
use std::ffi::{CStr, CString};
use std::path::Path;

/// Headroom asked before FFTW parses or prints wisdom of `len` bytes (FFTW aborts the
/// process when an allocation fails inside it).
fn wisdom_bytes(len: usize) -> usize {
    (2usize << 20).saturating_add(len.saturating_mul(4))
}

/// All of FFTW's current wisdom, in FFTW's text format.
pub fn export_to_string() -> Result<String> {
    let _lock = planner_lock();
    check_headroom(wisdom_bytes(1 << 20))?;
    // SAFETY: under the planner lock; FFTW returns a NUL-terminated string from malloc, or
    // NULL.
    let raw = unsafe { fftw::fftw_export_wisdom_to_string() };
    if raw.is_null() {
        return Err(Error::OutOfMemory { bytes: 0 });
    }
    // SAFETY: `raw` is a valid NUL-terminated string (above).
    let text = unsafe { CStr::from_ptr(raw) }
        .to_string_lossy()
        .into_owned();
    // SAFETY: FFTW's string is released with free() (FFTW's documentation), once.
    unsafe { libc::free(raw.cast()) };
    Ok(text)
}

/// Loads the wisdom in `wisdom` (FFTW's text format) into FFTW; an
/// [`Error::InvalidArgument`] if FFTW cannot read it.
pub fn import_from_string(wisdom: &str) -> Result<()> {
    let text = CString::new(wisdom)
        .map_err(|_| Error::InvalidArgument("wisdom contains a NUL byte".into()))?;
    let _lock = planner_lock();
    check_headroom(wisdom_bytes(wisdom.len()))?;
    // SAFETY: under the planner lock; `text` is NUL-terminated and outlives the call.
    if unsafe { fftw::fftw_import_wisdom_from_string(text.as_ptr()) } == 0 {
        return Err(Error::InvalidArgument(
            "FFTW could not read the wisdom (not FFTW wisdom, or from another FFTW build)".into(),
        ));
    }
    Ok(())
}

/// Writes FFTW's wisdom to the file `path` (created or replaced; written to a temporary
/// file beside it first and renamed, so a reader never sees a partial file).
pub fn export_to_file(path: &Path) -> Result<()> {
    let text = export_to_string()?;
    let io = |e: std::io::Error| {
        Error::InvalidArgument(format!("cannot write wisdom to {}: {e}", path.display()))
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(format!(".tmp-{}", std::process::id()));
    std::fs::write(&tmp, text).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

/// Loads the wisdom in the file `path` into FFTW.
pub fn import_from_file(path: &Path) -> Result<()> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::InvalidArgument(format!("cannot read wisdom from {}: {e}", path.display()))
    })?;
    import_from_string(&text).map_err(|e| match e {
        Error::InvalidArgument(msg) => Error::InvalidArgument(format!("{}: {msg}", path.display())),
        other => other,
    })
}

/// Forgets all of FFTW's wisdom (existing plans are not affected).
pub fn forget() {
    let _lock = planner_lock();
    // SAFETY: under the planner lock; takes no arguments.
    unsafe { fftw::fftw_forget_wisdom() };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fft::Rigor;
    use crate::{Options, PartialPlan, Shape};

    #[test]
    fn wisdom_survives_a_round_trip_through_a_file() {
        // A measured plan leaves wisdom about its 12-point slice DFTs.
        let options = Options::default().with_rigor(Rigor::Measure);
        PartialPlan::new(&Shape::new(6), &options).unwrap();
        let before = export_to_string().unwrap();
        assert!(before.starts_with("(fftw-3"), "{before}");
        let path = std::env::temp_dir().join(format!("so3fft-wisdom-{}", std::process::id()));
        export_to_file(&path).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), before);
        import_from_file(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn bad_wisdom_is_an_error() {
        assert!(matches!(
            import_from_string("not wisdom"),
            Err(Error::InvalidArgument(_))
        ));
        assert!(import_from_string("a\0b").is_err());
        let missing = Path::new("/nonexistent/so3fft/wisdom");
        assert!(matches!(
            import_from_file(missing),
            Err(Error::InvalidArgument(_))
        ));
        assert!(matches!(
            export_to_file(missing),
            Err(Error::InvalidArgument(_))
        ));
    }
}
