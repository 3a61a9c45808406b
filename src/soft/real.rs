//! Real-data symmetry of the coefficients, `fhat(l,-m,-m') = (-1)^(m-m') conj(fhat(l,m,m'))`,
//! for the `flag != 0` transforms.

use super::SoftResult;
use crate::ffi::{CallError, ErrorKind};
use crate::grid::block_start;
use crate::Complex64;
use std::collections::BTreeMap;
use std::sync::{Mutex, PoisonError};

// ----------------------------------------------------------------------------------------
// Real-data symmetry
// ----------------------------------------------------------------------------------------

/// The order pairs `(M, M')` other than `(0, 0)` whose blocks a real transform reads:
/// `(0, M' > 0)`, `(M > 0, M' != -M)` and `(-m, m)` for `m > 0`. Each one's partner
/// `(-M, -M')` is in none of these; together with `(0, 0)` they cover every block once.
pub(super) fn real_primary_pairs(b: usize) -> impl Iterator<Item = (isize, isize)> {
    let bi = b as isize;
    let zero = (1..bi).map(|mp| (0, mp));
    let pos = (1..bi).flat_map(move |m| {
        (-(bi - 1)..bi)
            .filter(move |&mp| mp != -m)
            .map(move |mp| (m, mp))
    });
    let anti = (1..bi).map(|m| (-m, m));
    zero.chain(pos).chain(anti)
}

/// Length of block `(m, m')`: `B - max(|m|, |m'|)`.
fn block_len(b: usize, m: isize, mp: isize) -> usize {
    b - m.unsigned_abs().max(mp.unsigned_abs())
}

/// `(-1)^(m - m')`.
pub(super) fn parity(m: isize, mp: isize) -> f64 {
    if (m - mp).rem_euclid(2) == 0 {
        1.0
    } else {
        -1.0
    }
}

/// Make forward coefficients exactly real-symmetric: each block pair becomes the transform
/// of the real part of the samples, `(c(M,M') + (-1)^(M-M') conj(c(-M,-M'))) / 2`, and
/// `fhat(l, 0, 0)` becomes real.
pub(super) fn symmetrize(b: usize, c: &mut [Complex64]) {
    let s00 = block_start(b, 0, 0);
    for v in &mut c[s00..s00 + b] {
        v.im = 0.0;
    }
    for (m, mp) in real_primary_pairs(b) {
        let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
        let s = parity(m, mp);
        for i in 0..block_len(b, m, mp) {
            let a = (c[p + i] + c[q + i].conj() * s) * 0.5;
            c[p + i] = a;
            c[q + i] = a.conj() * s;
        }
    }
}

/// Reusable coefficient buffers of the real inverse, one per bandwidth (taken out while in
/// use; a concurrent call allocates its own), so repeated calls do not pay page faults.
static REAL_BUFS: Mutex<BTreeMap<usize, Vec<Complex64>>> = Mutex::new(BTreeMap::new());

/// Private coefficient array for a real inverse: reads only `(0,0)` and the primary blocks
/// of `src`, fills each partner block by the symmetry (every entry is written). Hand it back
/// with [`release_real_buf`].
pub(super) fn expand_real(b: usize, src: &[Complex64]) -> SoftResult<Vec<Complex64>> {
    let cached = REAL_BUFS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .remove(&b);
    let mut c = match cached {
        Some(v) if v.len() == src.len() => v,
        _ => try_zeroed(src.len())?,
    };
    let s00 = block_start(b, 0, 0);
    c[s00..s00 + b].copy_from_slice(&src[s00..s00 + b]);
    for (m, mp) in real_primary_pairs(b) {
        let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
        let s = parity(m, mp);
        for i in 0..block_len(b, m, mp) {
            let a = src[p + i];
            c[p + i] = a;
            c[q + i] = a.conj() * s;
        }
    }
    Ok(c)
}

/// Return a buffer of [`expand_real`] to the pool.
pub(super) fn release_real_buf(b: usize, v: Vec<Complex64>) {
    REAL_BUFS
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .insert(b, v);
}

/// A zeroed vector, with allocation failure reported instead of aborting.
pub(super) fn try_zeroed(n: usize) -> SoftResult<Vec<Complex64>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        CallError::new(
            ErrorKind::NoMemory,
            format!("out of memory allocating {} bytes", n.saturating_mul(16)),
        )
    })?;
    v.resize(n, Complex64::new(0.0, 0.0));
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::real_primary_pairs;

    #[test]
    fn real_pairs_partition_blocks() {
        for b in 1..7usize {
            let bi = b as isize;
            let mut seen = std::collections::BTreeSet::new();
            seen.insert((0, 0));
            for (m, mp) in real_primary_pairs(b) {
                assert!(seen.insert((m, mp)), "dup {m} {mp}");
                assert!(seen.insert((-m, -mp)), "dup partner {m} {mp}");
            }
            assert_eq!(seen.len(), ((2 * bi - 1) * (2 * bi - 1)) as usize);
        }
    }
}
