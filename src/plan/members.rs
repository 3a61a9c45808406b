//! Which order pairs of a cluster a layout holds: all members (complex transforms) or one
//! of each negation pair (real signals, see `real.rs`).

use crate::symmetry::{Cluster, Member};

/// All members of a cluster (the complex layout's slots), then padding, and their number.
pub(super) fn all_members(cl: &Cluster) -> ([Member; 8], usize) {
    let mut m = [cl.members()[0]; 8];
    m[..cl.members().len()].copy_from_slice(cl.members());
    (m, cl.members().len())
}

/// Whether `mem` is the representative of its negation pair `(M, M') <-> (-M, -M')`.
fn representative(mem: &Member) -> bool {
    mem.mp > 0 || (mem.mp == 0 && mem.m >= 0)
}

/// The representatives of a cluster (1, 2 or 4 members, then padding) and their number.
pub(super) fn representatives(cl: &Cluster) -> ([Member; 8], usize) {
    let mut reps = [cl.members()[0]; 8];
    let mut nr = 0;
    for mem in cl.members().iter().filter(|m| representative(m)) {
        reps[nr] = *mem;
        nr += 1;
    }
    (reps, nr)
}

/// `(-1)^(M - M')`: the sign in `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
pub(super) fn neg_sign(m: isize, mp: isize) -> f64 {
    if (m - mp).rem_euclid(2) == 0 {
        1.0
    } else {
        -1.0
    }
}
