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
//!
//! Double precision (FFTW's `fftw_*`, the default `f64` plans) and single precision
//! (`fftwf_*`, the `f32` plans) are separate FFTW libraries with separate wisdom: the
//! functions here handle the double-precision store, those of [`f32`] the other one.

use super::api::FftwApi;
use super::planner::planner_lock;
use crate::error::{Error, Result};
use crate::system::check_headroom;
use std::ffi::{CStr, CString};
use std::path::Path;

/// Headroom asked before FFTW parses or prints wisdom of `len` bytes (FFTW aborts the
/// process when an allocation fails inside it).
fn wisdom_bytes(len: usize) -> usize {
    (2usize << 20).saturating_add(len.saturating_mul(4))
}

/// All of FFTW's current wisdom (double precision: FFTW's `fftw_*` store), in FFTW's text
/// format.
pub fn export_to_string() -> Result<String> {
    export_string::<f64>()
}

/// Loads the wisdom in `wisdom` (FFTW's text format) into FFTW's double-precision store; an
/// [`Error::InvalidArgument`] if FFTW cannot read it.
pub fn import_from_string(wisdom: &str) -> Result<()> {
    import_string::<f64>(wisdom)
}

/// Writes FFTW's double-precision wisdom to the file `path` (created or replaced; written
/// to a temporary file beside it first and renamed, so a reader never sees a partial file).
pub fn export_to_file(path: &Path) -> Result<()> {
    export_file::<f64>(path)
}

/// Loads the wisdom in the file `path` into FFTW's double-precision store.
pub fn import_from_file(path: &Path) -> Result<()> {
    import_file::<f64>(path)
}

/// Forgets all of FFTW's double-precision wisdom (existing plans are not affected).
pub fn forget() {
    forget_all::<f64>()
}

/// The wisdom of single-precision FFTW (`fftwf_*`, libfftw3f), which the `f32` plans use.
/// It is a store of its own, separate from the double-precision wisdom of the functions
/// one level up: each precision's wisdom is exported, imported and forgotten on its own,
/// and a file of one precision's wisdom cannot be imported into the other.
pub mod f32 {
    use crate::error::Result;
    use std::path::Path;

    /// All of single-precision FFTW's current wisdom, in FFTW's text format.
    pub fn export_to_string() -> Result<String> {
        super::export_string::<f32>()
    }

    /// Loads the wisdom in `wisdom` (single-precision FFTW's text format); an
    /// [`Error::InvalidArgument`](crate::Error::InvalidArgument) if FFTW cannot read it
    /// (also for double-precision wisdom).
    pub fn import_from_string(wisdom: &str) -> Result<()> {
        super::import_string::<f32>(wisdom)
    }

    /// Writes single-precision FFTW's wisdom to the file `path` (created or replaced
    /// atomically, as [`super::export_to_file`]).
    pub fn export_to_file(path: &Path) -> Result<()> {
        super::export_file::<f32>(path)
    }

    /// Loads the wisdom in the file `path` into single-precision FFTW.
    pub fn import_from_file(path: &Path) -> Result<()> {
        super::import_file::<f32>(path)
    }

    /// Forgets all of single-precision FFTW's wisdom (existing plans are not affected).
    pub fn forget() {
        super::forget_all::<f32>()
    }
}

/// All of `T`'s FFTW wisdom, in FFTW's text format.
pub(crate) fn export_string<T: FftwApi>() -> Result<String> {
    let _lock = planner_lock();
    check_headroom(wisdom_bytes(1 << 20))?;
    // SAFETY: under the planner lock; FFTW returns a NUL-terminated string from malloc, or
    // NULL.
    let raw = unsafe { T::export_wisdom_to_string() };
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

/// Loads `wisdom` into `T`'s FFTW.
pub(crate) fn import_string<T: FftwApi>(wisdom: &str) -> Result<()> {
    let text = CString::new(wisdom)
        .map_err(|_| Error::InvalidArgument("wisdom contains a NUL byte".into()))?;
    let _lock = planner_lock();
    check_headroom(wisdom_bytes(wisdom.len()))?;
    // SAFETY: under the planner lock; `text` is NUL-terminated and outlives the call.
    if unsafe { T::import_wisdom_from_string(text.as_ptr()) } == 0 {
        return Err(Error::InvalidArgument(
            "FFTW could not read the wisdom (not FFTW wisdom, or from another FFTW build)".into(),
        ));
    }
    Ok(())
}

/// Writes `T`'s FFTW wisdom to the file `path`, through a temporary file and a rename.
pub(crate) fn export_file<T: FftwApi>(path: &Path) -> Result<()> {
    let text = export_string::<T>()?;
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

/// Loads the wisdom in the file `path` into `T`'s FFTW.
pub(crate) fn import_file<T: FftwApi>(path: &Path) -> Result<()> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::InvalidArgument(format!("cannot read wisdom from {}: {e}", path.display()))
    })?;
    import_string::<T>(&text).map_err(|e| match e {
        Error::InvalidArgument(msg) => Error::InvalidArgument(format!("{}: {msg}", path.display())),
        other => other,
    })
}

/// Forgets all of `T`'s FFTW wisdom.
pub(crate) fn forget_all<T: FftwApi>() {
    let _lock = planner_lock();
    // SAFETY: under the planner lock; takes no arguments.
    unsafe { T::forget_wisdom() };
}

#[cfg(test)]
mod tests {
    use super::{export_to_file, export_to_string, import_from_file, import_from_string};
    use crate::error::Error;
    use crate::fft::tests::{plan_dft, Batch};
    use crate::fft::{AlignedBuf, Rigor, SIGN_MINUS};
    use crate::real::Real;
    use crate::{Options, PartialPlan, Shape};
    use num_complex::Complex;
    use std::path::Path;
    use std::sync::Mutex;

    /// Serialises the tests that forget single-precision wisdom (a test's planning must
    /// not be forgotten by another one between its steps).
    static F32_WISDOM: Mutex<()> = Mutex::new(());

    /// Whether `T`'s FFTW has wisdom for the batch `b` at rigour `rigor`: planning with
    /// `FFTW_WISDOM_ONLY` succeeds only then.
    fn knows<T: Real>(b: Batch, rigor: Rigor) -> bool {
        let buf = AlignedBuf::of::<Complex<T>>(b.extent()).unwrap();
        let flags = rigor.flags() | fftw_sys::FFTW_WISDOM_ONLY;
        // SAFETY: `buf` holds the batch's extent.
        unsafe { plan_dft::<T>(b, buf.ptr(), SIGN_MINUS, flags) }.is_ok()
    }

    /// Plans the batch `b` in `T` with `rigor` (leaving wisdom where it measures).
    fn plan<T: Real>(b: Batch, rigor: Rigor) {
        let buf = AlignedBuf::of::<Complex<T>>(b.extent()).unwrap();
        // SAFETY: `buf` holds the batch's extent.
        unsafe { plan_dft::<T>(b, buf.ptr(), SIGN_MINUS, rigor.flags()) }.unwrap();
    }

    /// Single-precision wisdom: made by measuring an f32 plan, exported, forgotten (FFTW
    /// then cannot plan from wisdom alone), imported back from the string and from a file
    /// (and then it can).
    #[test]
    fn f32_wisdom_round_trip() {
        let _serial = F32_WISDOM.lock().unwrap_or_else(|e| e.into_inner());
        let b = Batch {
            n: 36,
            howmany: 3,
            stride: 1,
            dist: 40,
        };
        plan::<f32>(b, Rigor::Measure);
        assert!(knows::<f32>(b, Rigor::Measure));
        let text = super::f32::export_to_string().unwrap();
        assert!(
            text.starts_with("(fftw-3") && text.contains("fftwf_wisdom"),
            "{text}"
        );
        super::f32::forget();
        assert!(!knows::<f32>(b, Rigor::Measure), "forgotten");
        super::f32::import_from_string(&text).unwrap();
        assert!(knows::<f32>(b, Rigor::Measure), "imported from the string");

        let path = std::env::temp_dir().join(format!("so3fft-wisdomf-{}", std::process::id()));
        super::f32::export_to_file(&path).unwrap();
        super::f32::forget();
        assert!(!knows::<f32>(b, Rigor::Measure));
        super::f32::import_from_file(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert!(knows::<f32>(b, Rigor::Measure), "imported from the file");
    }

    /// The two precisions keep separate wisdom: forgetting single-precision wisdom leaves
    /// the double-precision store, a measured f64 plan teaches single precision nothing, and
    /// one precision's wisdom text is refused by the other.
    #[test]
    fn f32_and_f64_wisdom_are_separate() {
        let _serial = F32_WISDOM.lock().unwrap_or_else(|e| e.into_inner());
        let b = Batch {
            n: 44,
            howmany: 2,
            stride: 1,
            dist: 48,
        };
        plan::<f64>(b, Rigor::Measure);
        super::f32::forget();
        assert!(knows::<f64>(b, Rigor::Measure), "f64 wisdom kept");
        assert!(
            !knows::<f32>(b, Rigor::Measure),
            "no f32 wisdom from an f64 plan"
        );

        let double = export_to_string().unwrap();
        assert!(double.contains("fftw_wisdom") && !double.contains("fftwf_wisdom"));
        assert!(matches!(
            super::f32::import_from_string(&double),
            Err(Error::InvalidArgument(_))
        ));
        let c = Batch {
            n: 52,
            howmany: 2,
            stride: 1,
            dist: 52,
        };
        plan::<f32>(c, Rigor::Measure);
        let single = super::f32::export_to_string().unwrap();
        assert!(matches!(
            import_from_string(&single),
            Err(Error::InvalidArgument(_))
        ));
        assert!(
            !knows::<f64>(c, Rigor::Measure),
            "no f64 wisdom from an f32 plan"
        );
    }

    #[test]
    fn bad_f32_wisdom_is_an_error() {
        assert!(matches!(
            super::f32::import_from_string("not wisdom"),
            Err(Error::InvalidArgument(_))
        ));
        assert!(super::f32::import_from_string("a\0b").is_err());
        let missing = Path::new("/nonexistent/so3fft/wisdom");
        assert!(matches!(
            super::f32::import_from_file(missing),
            Err(Error::InvalidArgument(_))
        ));
        assert!(matches!(
            super::f32::export_to_file(missing),
            Err(Error::InvalidArgument(_))
        ));
    }

    #[test]
    fn wisdom_survives_a_round_trip_through_a_file() {
        // A measured plan leaves wisdom about its 12-point slice DFTs.
        let options = Options::default().with_rigor(Rigor::Measure);
        PartialPlan::<f64>::new(&Shape::new(6), &options).unwrap();
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
