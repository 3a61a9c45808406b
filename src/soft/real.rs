//! Real-data symmetry of the coefficients, `fhat(l,-m,-m') = (-1)^(m-m') conj(fhat(l,m,m'))`,
//! for the `flag != 0` transforms.

use super::SoftResult;
use crate::ffi::{CallError, ErrorKind};
use crate::grid::block_start;
use crate::{Complex64, Plan};
use rayon::prelude::*;
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

// Which automatic real path a `flag = 0` call took, counted per calling thread for the
// tests (`[forward, inverse]`); nothing outside the tests.
#[cfg(test)]
thread_local! {
    pub(super) static REAL_PATHS: std::cell::Cell<[usize; 2]> =
        const { std::cell::Cell::new([0, 0]) };
}

/// Count a `flag = 0` call that took the real path (`inverse`: the inverse, else the
/// forward), in the tests only.
pub(super) fn note_real_path(inverse: bool) {
    #[cfg(test)]
    REAL_PATHS.with(|c| {
        let mut v = c.get();
        v[usize::from(inverse)] += 1;
        c.set(v);
    });
    let _ = inverse;
}

/// Values per piece of the parallel scans for real data (a piece is read at memory speed
/// in a few microseconds; a scan of fewer values runs on the calling thread).
const SCAN_PIECE: usize = 1 << 15;

/// Whether `f` holds for every piece of `0..n` (pieces of [`SCAN_PIECE`]), on the plan's
/// workers when there are several pieces; stops soon after a piece where it fails.
fn all_pieces(plan: &Plan, n: usize, f: impl Fn(usize, usize) -> bool + Sync) -> bool {
    if n <= SCAN_PIECE {
        return f(0, n);
    }
    plan.install(|| {
        (0..n.div_ceil(SCAN_PIECE))
            .into_par_iter()
            .all(|i| f(i * SCAN_PIECE, ((i + 1) * SCAN_PIECE).min(n)))
    })
}

/// Whether complex samples are real data: every imaginary part exactly 0 (either sign) and
/// every real part finite. A `flag = 0` forward on such samples may take the real path.
pub(super) fn real_samples(plan: &Plan, samples: &[Complex64]) -> bool {
    all_pieces(plan, samples.len(), |i0, i1| {
        // No early exit inside a piece: the loop vectorises.
        samples[i0..i1]
            .iter()
            .fold(true, |ok, z| ok & (z.im == 0.0) & z.re.is_finite())
    })
}

/// Whether coefficients (bandwidth `b`) have the real symmetry exactly: all finite,
/// `fhat(l,0,0)` real, and `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))` for every pair
/// (compared as numbers: `+0` and `-0` are equal). A `flag = 0` inverse of such coefficients
/// is real, and the real inverse (which reads one block of each pair) gives it.
pub(super) fn real_symmetric(plan: &Plan, b: usize, c: &[Complex64]) -> bool {
    let bi = b as isize;
    // Row `m`'s blocks `(m, M' > 0)`, and `(m, 0)` for `m > 0`, against their partners
    // `(-m, -M')`: with `(0, 0)`, every pair once.
    let row = |m: isize| -> bool {
        let lowest = if m > 0 { 0 } else { 1 };
        (lowest..bi).all(|mp| {
            let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
            let n = block_len(b, m, mp);
            let s = parity(m, mp);
            c[p..p + n]
                .iter()
                .zip(&c[q..q + n])
                .fold(true, |ok, (a, z)| {
                    ok & a.re.is_finite()
                        & a.im.is_finite()
                        & (z.re == s * a.re)
                        & (z.im == -s * a.im)
                })
        })
    };
    let s00 = block_start(b, 0, 0);
    let zero = c[s00..s00 + b]
        .iter()
        .all(|z| z.im == 0.0 && z.re.is_finite());
    zero && if c.len() <= SCAN_PIECE {
        (-(bi - 1)..bi).all(row)
    } else {
        plan.install(|| (-(bi - 1)..bi).into_par_iter().all(row))
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
