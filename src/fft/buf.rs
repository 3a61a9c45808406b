//! Page-aligned buffers, the chunk buffer of a plan, and row copies.

use crate::error::{Error, Result};
use num_complex::Complex64;

/// A page-aligned complex buffer, zero-filled. Large buffers are mapped directly and
/// asked to use transparent huge pages: the chunk buffer is read and written with large
/// strides, and 4 KiB pages would make nearly every access a TLB miss.
pub(crate) struct AlignedBuf {
    ptr: *mut Complex64,
    bytes: usize,
}

// SAFETY: the buffer is plain memory owned by this value; moving it to another thread moves
// the ownership.
unsafe impl Send for AlignedBuf {}
// SAFETY: `&AlignedBuf` only hands out the pointer; whoever writes through it guarantees
// (with its own SAFETY argument) that concurrent writers use disjoint parts.
unsafe impl Sync for AlignedBuf {}

impl AlignedBuf {
    /// Allocate `len` complex values, zero-filled and touched (so page faults happen here).
    /// From 2 MiB on the mapping starts on a 2 MiB boundary and is a whole number of 2 MiB
    /// pages, so that transparent huge pages can back all of it (an unaligned mapping of a
    /// little over 2 MiB holds no huge page at all).
    pub fn new(len: usize) -> Result<AlignedBuf> {
        const HUGE: usize = 1 << 21;
        let want = len
            .checked_mul(16)
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?
            .max(4096);
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
            ptr: ptr.cast::<Complex64>(),
            bytes,
        })
    }

    /// Start of the buffer (valid for the `len` values asked for, while `self` lives).
    pub fn as_mut_ptr(&self) -> *mut Complex64 {
        self.ptr
    }

    /// Number of complex values the buffer holds (at least the `len` asked for).
    pub fn len(&self) -> usize {
        self.bytes / 16
    }

    /// The first `len` values (`len <= self.len()`).
    pub fn slice_mut(&mut self, len: usize) -> &mut [Complex64] {
        assert!(len <= self.len());
        // SAFETY: `len` values from `ptr` lie in the mapping this value owns, initialised
        // (zero-filled at creation); `&mut self` makes the borrow exclusive.
        unsafe { std::slice::from_raw_parts_mut(self.ptr, len) }
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

/// Copy `rows` rows of `len` doubles from rows `ss` doubles apart at `src` to rows `ds`
/// apart at `dst`; with `stream`, by non-temporal stores where `dst` and its rows are
/// 16-byte aligned (for memory the transform does not read again: ordinary stores would
/// first read every line).
///
/// # Safety
/// `src` is valid for reads and `dst` for writes of those extents (`rows` rows of `len`
/// doubles at the given strides), and the two do not overlap.
pub(crate) unsafe fn copy_rows(
    src: *const f64,
    ss: usize,
    dst: *mut f64,
    ds: usize,
    rows: usize,
    len: usize,
    stream: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if stream && (dst as usize).is_multiple_of(16) && ds.is_multiple_of(2) && len.is_multiple_of(2)
    {
        use std::arch::x86_64::{_mm_loadu_pd, _mm_sfence, _mm_stream_pd};
        for r in 0..rows {
            // SAFETY: row `r` of both extents is in bounds (this function's contract); each
            // store writes 2 doubles at an even offset of a 16-byte aligned row (checked
            // above), and SSE2 is part of x86_64.
            unsafe {
                let (s, d) = (src.add(r * ss), dst.add(r * ds));
                for i in (0..len).step_by(2) {
                    _mm_stream_pd(d.add(i), _mm_loadu_pd(s.add(i)));
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

    /// Runs `f` with a buffer of at least `len` complex values (see [`ChunkBuffer`]).
    pub(crate) fn with<R>(
        &self,
        len: usize,
        f: impl FnOnce(&AlignedBuf) -> Result<R>,
    ) -> Result<R> {
        use crate::system::{check_headroom, mem_available};
        use std::sync::TryLockError;
        let mut guard = match self.0.try_lock() {
            Ok(g) => g,
            Err(TryLockError::Poisoned(e)) => e.into_inner(),
            Err(TryLockError::WouldBlock) => {
                let bytes = 16 * len;
                if mem_available().is_none_or(|a| a / 2 >= bytes) && check_headroom(bytes).is_ok() {
                    return f(&AlignedBuf::new(len)?);
                }
                if rayon::current_thread_index().is_some() {
                    return Err(Error::OutOfMemory { bytes });
                }
                self.0.lock().unwrap_or_else(|e| e.into_inner())
            }
        };
        if guard.as_ref().is_none_or(|b| b.len() < len) {
            // The old buffer goes before the new one is mapped.
            *guard = None;
            check_headroom(16 * len)?;
            *guard = Some(AlignedBuf::new(len)?);
        }
        f(guard.as_ref().expect("just made"))
    }
}

#[cfg(test)]
mod tests {
    use super::{AlignedBuf, ChunkBuffer};
    use num_complex::Complex64;

    /// A chunk buffer is made on first use and kept, grown when more is asked, and an
    /// execution that finds it taken (here the same thread, one call inside another) gets
    /// a private buffer of its own size.
    #[test]
    fn chunk_buffer_is_kept_grown_and_never_shared() {
        let cb = ChunkBuffer::new(None);
        let first = cb.with(100, |b| Ok((b.as_mut_ptr(), b.len()))).unwrap();
        assert!(first.1 >= 100);
        let again = cb.with(50, |b| Ok(b.as_mut_ptr())).unwrap();
        assert_eq!(again, first.0, "kept");
        let grown = cb.with(1 << 16, |b| Ok(b.len())).unwrap();
        assert!(grown >= 1 << 16);
        cb.with(10, |outer| {
            let inner = cb.with(1000, |b| Ok((b.as_mut_ptr(), b.len())))?;
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
