//! Page-aligned buffers, the chunk buffer of a plan, and row copies.

use crate::error::{Error, Result};
use crate::numeric::Elem;
use num_complex::{Complex, Complex64};

/// Element types an [`AlignedBuf`] may be viewed as: the library's reals and complex values
/// of them, plain data for which every bit pattern is a value and all-zero bytes are zero
/// (the buffer is zero-filled).
pub(crate) trait Plain: Copy + 'static {}

impl<T: Elem> Plain for T {}
impl<T: Elem> Plain for Complex<T> {}

/// A page-aligned buffer, zero-filled, sized in bytes and viewed as any [`Plain`] element
/// type (`f64`, `f32`, `Complex64`, `Complex32`); the names without a type (`new`,
/// `as_mut_ptr`, `len`, `slice_mut`) count `Complex64` values. Large buffers are mapped
/// directly and asked to use transparent huge pages: the chunk buffer is read and written
/// with large strides, and 4 KiB pages would make nearly every access a TLB miss.
pub(crate) struct AlignedBuf {
    ptr: *mut u8,
    bytes: usize,
}

// SAFETY: the buffer is plain memory owned by this value; moving it to another thread moves
// the ownership.
unsafe impl Send for AlignedBuf {}
// SAFETY: `&AlignedBuf` only hands out the pointer; whoever writes through it guarantees
// (with its own SAFETY argument) that concurrent writers use disjoint parts.
unsafe impl Sync for AlignedBuf {}

impl AlignedBuf {
    /// Allocate `len` complex values (`Complex64`), zero-filled and touched.
    pub fn new(len: usize) -> Result<AlignedBuf> {
        Self::of::<Complex64>(len)
    }

    /// Allocate `len` values of `U`, zero-filled and touched.
    pub fn of<U: Plain>(len: usize) -> Result<AlignedBuf> {
        let bytes = len
            .checked_mul(size_of::<U>())
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?;
        Self::with_bytes(bytes)
    }

    /// Allocate at least `want` bytes (4096 or more), zero-filled and touched (so page
    /// faults happen here). From 2 MiB on the mapping starts on a 2 MiB boundary and is a
    /// whole number of 2 MiB pages, so that transparent huge pages can back all of it (an
    /// unaligned mapping of a little over 2 MiB holds no huge page at all).
    pub fn with_bytes(want: usize) -> Result<AlignedBuf> {
        const HUGE: usize = 1 << 21;
        let want = want.max(4096);
        let huge = want >= HUGE;
        let bytes = if huge {
            want.checked_next_multiple_of(HUGE)
                .ok_or(Error::OutOfMemory { bytes: usize::MAX })?
        } else {
            want
        };
        // Room to move the start to a 2 MiB boundary.
        let map = bytes
            .checked_add(if huge { HUGE } else { 0 })
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?;
        // SAFETY: a new anonymous private mapping (no existing memory is affected); failure
        // is checked below.
        let raw = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                map,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS | libc::MAP_NORESERVE,
                -1,
                0,
            )
        };
        if raw == libc::MAP_FAILED {
            return Err(Error::OutOfMemory { bytes: want });
        }
        let ptr = if huge {
            // Give back the unaligned head and the tail beyond `bytes`.
            let start = raw as usize;
            let aligned = start.next_multiple_of(HUGE);
            let (head, tail) = (aligned - start, start + map - (aligned + bytes));
            // SAFETY: both ranges lie inside the mapping just made, are page-aligned, and
            // nothing points into them.
            unsafe {
                if head > 0 {
                    libc::munmap(raw, head);
                }
                if tail > 0 {
                    libc::munmap((aligned + bytes) as *mut libc::c_void, tail);
                }
            }
            aligned as *mut libc::c_void
        } else {
            raw
        };
        // SAFETY: `ptr .. ptr + bytes` is the part of the mapping we keep, readable and
        // writable, and not yet shared.
        unsafe {
            if huge {
                libc::madvise(ptr, bytes, libc::MADV_HUGEPAGE);
            }
            // Touch every page now rather than inside the first transform. With no swap
            // and overcommit, a failure here would be the kernel's OOM killer, so callers
            // check available memory for very large plans (see Plan::new).
            std::ptr::write_bytes(ptr.cast::<u8>(), 0, bytes);
        }
        Ok(AlignedBuf {
            ptr: ptr.cast::<u8>(),
            bytes,
        })
    }

    /// Size in bytes (at least the size asked for).
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// Start of the buffer as `U` values (page-aligned; valid for [`AlignedBuf::len_of`]
    /// of them while `self` lives).
    pub fn ptr<U: Plain>(&self) -> *mut U {
        self.ptr.cast::<U>()
    }

    /// Number of `U` values the buffer holds (at least the number asked for).
    pub fn len_of<U: Plain>(&self) -> usize {
        self.bytes / size_of::<U>()
    }

    /// The first `len` values of `U` (`len <= self.len_of::<U>()`).
    pub fn view_mut<U: Plain>(&mut self, len: usize) -> &mut [U] {
        assert!(len <= self.len_of::<U>());
        // SAFETY: `len` values from `ptr` lie in the mapping this value owns, page-aligned
        // (aligned for `U`) and initialised (zero-filled at creation; every bit pattern is
        // a `U`, `Plain`); `&mut self` makes the borrow exclusive.
        unsafe { std::slice::from_raw_parts_mut(self.ptr::<U>(), len) }
    }

    /// Start of the buffer as `Complex64` values (valid for the `len` values asked for,
    /// while `self` lives).
    pub fn as_mut_ptr(&self) -> *mut Complex64 {
        self.ptr::<Complex64>()
    }

    /// Number of `Complex64` values the buffer holds (at least the `len` asked for).
    pub fn len(&self) -> usize {
        self.len_of::<Complex64>()
    }
}

impl Drop for AlignedBuf {
    fn drop(&mut self) {
        // SAFETY: the mapping was created in `new` with this start and size and is unmapped
        // once; no pointer into it outlives `self` (the users' contract of `as_mut_ptr`).
        unsafe {
            libc::munmap(self.ptr.cast::<libc::c_void>(), self.bytes);
        }
    }
}

/// Copy `rows` rows of `len` values from rows `ss` values apart at `src` to rows `ds`
/// apart at `dst`; with `stream`, by non-temporal stores where `dst` is 16-byte aligned and
/// its rows and their stride whole 16-byte units (for memory the transform does not read
/// again: ordinary stores would first read every line).
///
/// # Safety
/// `src` is valid for reads and `dst` for writes of those extents (`rows` rows of `len`
/// values at the given strides), and the two do not overlap.
pub(crate) unsafe fn copy_rows<U: Plain>(
    src: *const U,
    ss: usize,
    dst: *mut U,
    ds: usize,
    rows: usize,
    len: usize,
    stream: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if stream
        && (dst as usize).is_multiple_of(16)
        && (ds * size_of::<U>()).is_multiple_of(16)
        && (len * size_of::<U>()).is_multiple_of(16)
    {
        use std::arch::x86_64::{_mm_loadu_pd, _mm_sfence, _mm_stream_pd};
        let row_bytes = len * size_of::<U>();
        for r in 0..rows {
            // SAFETY: row `r` of both extents is in bounds (this function's contract); each
            // store writes 16 bytes at a multiple of 16 bytes into a 16-byte aligned row
            // (checked above), moving the bits unchanged; SSE2 is part of x86_64.
            unsafe {
                let (s, d) = (src.add(r * ss).cast::<u8>(), dst.add(r * ds).cast::<u8>());
                for i in (0..row_bytes).step_by(16) {
                    _mm_stream_pd(d.add(i).cast::<f64>(), _mm_loadu_pd(s.add(i).cast::<f64>()));
                }
            }
        }
        // SAFETY: a store fence (SSE, part of x86_64) orders the streaming stores before
        // any later access.
        unsafe { _mm_sfence() };
        return;
    }
    let _ = stream;
    for r in 0..rows {
        // SAFETY: row `r` of both extents is in bounds and they do not overlap (this
        // function's contract).
        unsafe { std::ptr::copy_nonoverlapping(src.add(r * ss), dst.add(r * ds), len) };
    }
}

/// A plan's chunk buffer, which one execution at a time uses: made at planning or on first
/// use, grown when a batch needs more. An execution that finds it taken by another gets a
/// private buffer while the memory it needs is available twice over; otherwise a plain
/// thread waits for the plan's, and a worker of some rayon pool (which must not block: the
/// holder may be further down its own stack) gets [`Error::OutOfMemory`].
pub(crate) struct ChunkBuffer(std::sync::Mutex<Option<AlignedBuf>>);

impl ChunkBuffer {
    /// The buffer `made` at planning, or `None` to make it on first use.
    pub(crate) fn new(made: Option<AlignedBuf>) -> ChunkBuffer {
        ChunkBuffer(std::sync::Mutex::new(made))
    }

    /// Runs `f` with a buffer of at least `bytes` bytes (see [`ChunkBuffer`]).
    pub(crate) fn with_bytes<R>(
        &self,
        bytes: usize,
        f: impl FnOnce(&AlignedBuf) -> Result<R>,
    ) -> Result<R> {
        use crate::system::{check_headroom, mem_available};
        use std::sync::TryLockError;
        let mut guard = match self.0.try_lock() {
            Ok(g) => g,
            Err(TryLockError::Poisoned(e)) => e.into_inner(),
            Err(TryLockError::WouldBlock) => {
                if mem_available().is_none_or(|a| a / 2 >= bytes) && check_headroom(bytes).is_ok() {
                    return f(&AlignedBuf::with_bytes(bytes)?);
                }
                if rayon::current_thread_index().is_some() {
                    return Err(Error::OutOfMemory { bytes });
                }
                self.0.lock().unwrap_or_else(|e| e.into_inner())
            }
        };
        if guard.as_ref().is_none_or(|b| b.bytes() < bytes) {
            // The old buffer goes before the new one is mapped.
            *guard = None;
            check_headroom(bytes)?;
            *guard = Some(AlignedBuf::with_bytes(bytes)?);
        }
        f(guard.as_ref().expect("just made"))
    }
}

#[cfg(test)]
mod tests {
    use super::{copy_rows, AlignedBuf, ChunkBuffer};
    use num_complex::{Complex32, Complex64};

    /// Rows copied in either precision, streamed (rows of whole 16-byte units into an
    /// aligned destination) or not (odd row lengths, or not asked), land where they should
    /// and nowhere else.
    #[test]
    fn copy_rows_of_both_precisions() {
        fn check<U: super::Plain + PartialEq + std::fmt::Debug>(value: impl Fn(usize) -> U) {
            for (len, stream) in [(8, true), (8, false), (3, true), (5, false)] {
                let (rows, ss, ds) = (4, len + 2, len + 4);
                let src: Vec<U> = (0..rows * ss).map(&value).collect();
                let mut dst = AlignedBuf::of::<U>(rows * ds).unwrap();
                let zero = dst.view_mut::<U>(1)[0];
                // SAFETY: `rows` rows of `len` values at strides `ss` and `ds` lie inside
                // `src` and `dst`, which do not overlap.
                unsafe { copy_rows(src.as_ptr(), ss, dst.ptr::<U>(), ds, rows, len, stream) };
                let d = dst.view_mut::<U>(rows * ds);
                for r in 0..rows {
                    for i in 0..ds {
                        let want = if i < len { src[r * ss + i] } else { zero };
                        assert_eq!(d[r * ds + i], want, "len {len} stream {stream} ({r}, {i})");
                    }
                }
            }
        }
        check(|i| Complex32::new(i as f32, -(i as f32)));
        check(|i| Complex64::new(i as f64, 0.5));
        check(|i| i as f32 + 1.0);
        check(|i| i as f64 + 1.0);
    }

    /// A chunk buffer is made on first use and kept, grown when more is asked, and an
    /// execution that finds it taken (here the same thread, one call inside another) gets
    /// a private buffer of its own size.
    #[test]
    fn chunk_buffer_is_kept_grown_and_never_shared() {
        let cb = ChunkBuffer::new(None);
        let first = cb
            .with_bytes(16 * 100, |b| Ok((b.as_mut_ptr(), b.len())))
            .unwrap();
        assert!(first.1 >= 100);
        let again = cb.with_bytes(16 * 50, |b| Ok(b.as_mut_ptr())).unwrap();
        assert_eq!(again, first.0, "kept");
        let grown = cb.with_bytes(16 << 16, |b| Ok(b.len())).unwrap();
        assert!(grown >= 1 << 16);
        cb.with_bytes(16 * 10, |outer| {
            let inner = cb.with_bytes(16 * 1000, |b| Ok((b.as_mut_ptr(), b.len())))?;
            assert_ne!(inner.0, outer.as_mut_ptr(), "a taken buffer is not shared");
            assert!(inner.1 >= 1000);
            Ok(())
        })
        .unwrap();
    }

    /// Buffers from 2 MiB on start on a 2 MiB boundary; every size is zero-filled and
    /// writable to its last value, and dropping gives the memory back (no crash when
    /// many are made and dropped).
    #[test]
    fn aligned_buffers() {
        for len in [
            1usize,
            255,
            4096,
            (1 << 17) - 1,
            1 << 17,
            (1 << 17) + 1,
            300_000,
        ] {
            for _ in 0..3 {
                let b = AlignedBuf::new(len).unwrap();
                let p = b.as_mut_ptr();
                if len * 16 >= 1 << 21 {
                    assert_eq!(p as usize % (1 << 21), 0, "len {len}");
                } else {
                    assert_eq!(p as usize % 4096, 0, "len {len}");
                }
                // SAFETY: `len` values were allocated and `b` outlives the slice.
                let s = unsafe { std::slice::from_raw_parts_mut(p, len) };
                assert!(s.iter().all(|z| z.re == 0.0 && z.im == 0.0));
                s[len - 1] = Complex64::new(1.0, 2.0);
                s[0] = Complex64::new(3.0, 4.0);
            }
        }
    }
}
