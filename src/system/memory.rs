//! Memory facts from Linux's `/proc` and the resource limits, read into stack buffers.

use crate::error::{Error, Result};

/// Reads the file at `path` (NUL-terminated) into `buf` without allocating; the bytes read.
fn read_proc(path: &std::ffi::CStr, buf: &mut [u8]) -> Option<usize> {
    // SAFETY: `path` is NUL-terminated; the descriptor is closed below on every path.
    let fd = unsafe { libc::open(path.as_ptr(), libc::O_RDONLY | libc::O_CLOEXEC) };
    if fd < 0 {
        return None;
    }
    let mut len = 0;
    while len < buf.len() {
        let rest = &mut buf[len..];
        // SAFETY: `rest` is a valid, writable region of `rest.len()` bytes.
        let n = unsafe { libc::read(fd, rest.as_mut_ptr().cast(), rest.len()) };
        if n < 0 && std::io::Error::last_os_error().kind() == std::io::ErrorKind::Interrupted {
            continue;
        }
        if n <= 0 {
            break;
        }
        len += n as usize;
    }
    // SAFETY: `fd` was opened above and is closed once.
    unsafe { libc::close(fd) };
    Some(len)
}

/// The first unsigned decimal number in `text` at or after `from`.
fn number_after(text: &[u8], from: usize) -> Option<usize> {
    let digits = text.get(from..)?;
    let start = digits.iter().position(u8::is_ascii_digit)?;
    let mut value: usize = 0;
    for &c in digits[start..].iter().take_while(|c| c.is_ascii_digit()) {
        value = value.checked_mul(10)?.checked_add(usize::from(c - b'0'))?;
    }
    Some(value)
}

/// A field of `/proc/meminfo` (e.g. `"MemAvailable:"`) in bytes, if known.
fn meminfo(field: &str) -> Option<usize> {
    let mut buf = [0u8; 8192];
    let len = read_proc(c"/proc/meminfo", &mut buf)?;
    let text = &buf[..len];
    let key = field.as_bytes();
    let at = text
        .split(|&c| c == b'\n')
        .scan(0usize, |offset, line| {
            let here = *offset;
            *offset += line.len() + 1;
            Some((here, line))
        })
        .find(|(_, line)| line.starts_with(key))?
        .0;
    number_after(text, at + key.len())?.checked_mul(1024)
}

/// Bytes of memory the system can still give us (`MemAvailable`), if known.
pub(crate) fn mem_available() -> Option<usize> {
    meminfo("MemAvailable:")
}

/// The machine's memory (`MemTotal`), if known.
pub(crate) fn mem_total() -> Option<usize> {
    meminfo("MemTotal:")
}

/// The soft limit of resource `resource`, `None` if unlimited or unknown.
fn soft_limit(resource: libc::__rlimit_resource_t) -> Option<usize> {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: `lim` is a valid rlimit to write into.
    if unsafe { libc::getrlimit(resource, &mut lim) } != 0 || lim.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    usize::try_from(lim.rlim_cur).ok()
}

/// Bytes of address space this process may still map under its `RLIMIT_AS`, `None` if it
/// has no such limit (or its size cannot be read).
fn address_space_left() -> Option<usize> {
    let limit = soft_limit(libc::RLIMIT_AS)?;
    let mut buf = [0u8; 256];
    let len = read_proc(c"/proc/self/statm", &mut buf)?;
    let pages = number_after(&buf[..len], 0)?;
    // SAFETY: sysconf only reads a system constant.
    let page = usize::try_from(unsafe { libc::sysconf(libc::_SC_PAGESIZE) }).ok()?;
    Some(limit.saturating_sub(pages.saturating_mul(page)))
}

/// `Ok` when `bytes` more can be mapped: within the address-space limit and, where
/// `/proc/meminfo` tells, within the available memory; else [`Error::OutOfMemory`].
pub(crate) fn check_headroom(bytes: usize) -> Result<()> {
    let fits = |left: Option<usize>| left.is_none_or(|left| left >= bytes);
    if fits(address_space_left()) && fits(mem_available()) {
        Ok(())
    } else {
        Err(Error::OutOfMemory { bytes })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meminfo_fields_are_consistent() {
        let (Some(avail), Some(total)) = (mem_available(), mem_total()) else {
            return; // not Linux
        };
        assert!(
            avail > 0 && avail <= total,
            "available {avail} total {total}"
        );
    }

    #[test]
    fn numbers_are_parsed_after_the_offset() {
        assert_eq!(number_after(b"MemTotal:   123 kB\n", 9), Some(123));
        assert_eq!(number_after(b"5 6", 1), Some(6));
        assert_eq!(number_after(b"none", 0), None);
        assert_eq!(number_after(b"99999999999999999999999", 0), None);
    }

    #[test]
    fn headroom_of_a_small_request_is_there_and_of_an_absurd_one_not() {
        assert!(check_headroom(1 << 20).is_ok());
        if mem_available().is_some() {
            assert!(check_headroom(usize::MAX / 2).is_err());
        }
    }
}
