//! Where a slice's values are in the chunk buffer: [`LaneRows`], a slice's lane rows, and
//! [`SlotTable`], the flat table of every slot of a lane row that the FFT stage's scatters
//! and gathers read.

use super::dwt_stage::DwtStage;
use crate::error::{Error, Result};

/// A slice's lane rows (values of `T`): its own and its mirror's, for the clusters
/// `clusters.0 .. clusters.1`; cluster `c`'s slots start `offset(c)` values after the
/// pointers (which may point before the rows when they hold only a later part of the
/// clusters).
#[derive(Clone, Copy)]
pub(crate) struct LaneRows<T = f64> {
    pub(crate) own: *mut T,
    pub(crate) mirror: *mut T,
    pub(crate) clusters: (usize, usize),
}

impl<T> LaneRows<T> {
    /// Rows that hold the clusters `clusters` only, the first of which at offset `first`
    /// of the full lane row: their slots at `own` and `mirror` onwards.
    pub(crate) fn part(
        (own, mirror): (*mut T, *mut T),
        clusters: (usize, usize),
        first: usize,
    ) -> LaneRows<T> {
        LaneRows {
            own: own.wrapping_sub(first),
            mirror: mirror.wrapping_sub(first),
            clusters,
        }
    }

    /// Where a slot of a [`SlotTable`] entry is.
    #[inline(always)]
    pub(crate) fn at(&self, at: u32) -> *mut T {
        let row = if at & SlotTable::MIRROR != 0 {
            self.mirror
        } else {
            self.own
        };
        row.wrapping_add((at & !SlotTable::MIRROR) as usize)
    }
}

/// Every slot of a lane row in cluster order, flat: the FFT stage's scatters and gathers
/// read 8 bytes a slot here (one table for the complex layout, one for the real) instead of
/// each cluster's list of slots (a heap allocation per cluster, 64 bytes a slot: at
/// B = 128 about 4 MB read per slice).
pub(crate) struct SlotTable {
    /// `(offset in the lane row, or'ed with MIRROR for a reversed member, whose value is in
    /// the mirror's row; index in the FFT stage's work buffer)`.
    entries: Vec<(u32, u32)>,
    /// First entry of each cluster, then the total.
    start: Vec<usize>,
    /// The same for the real layout's half buffer (`n_alpha` rows `hs` apart, `M' >= 0`):
    /// the index of `(M, M')` if `M' >= 0`, else of `(-M, -M')` or'ed with `CONJ` (the real
    /// forward reads the value there unconjugated; the real inverse skips it).
    real: Vec<(u32, u32)>,
}

impl SlotTable {
    pub(crate) const MIRROR: u32 = 1 << 31;
    pub(crate) const CONJ: u32 = 1 << 31;

    /// The table of `dwt`'s clusters; the real entries for a half buffer of `na` rows `hs`
    /// apart.
    pub(crate) fn new<T: crate::Real>(
        dwt: &DwtStage<T>,
        (na, hs): (usize, usize),
    ) -> Result<SlotTable> {
        let too_large =
            || Error::InvalidArgument("shape too large for the engine's slot table".into());
        let fits = |x: usize| u32::try_from(x).ok().filter(|a| a & (1 << 31) == 0);
        let half = |m: isize, mp: isize| m.rem_euclid(na as isize) as usize * hs + mp as usize;
        let mut entries = Vec::new();
        let mut real = Vec::new();
        let mut start = Vec::with_capacity(dwt.clusters.len() + 1);
        for cl in &dwt.clusters {
            start.push(entries.len());
            for (q, s) in cl.slots.iter().enumerate() {
                let mem = &s.member;
                let (Some(at), Ok(work)) = (fits(cl.offset + 2 * q), u32::try_from(s.work)) else {
                    return Err(too_large());
                };
                let at = at | if mem.reversed { Self::MIRROR } else { 0 };
                entries.push((at, work));
                let idx = if mem.mp >= 0 {
                    fits(half(mem.m, mem.mp))
                } else {
                    fits(half(-mem.m, -mem.mp)).map(|i| i | Self::CONJ)
                };
                real.push((at, idx.ok_or_else(too_large)?));
            }
        }
        start.push(entries.len());
        Ok(SlotTable {
            entries,
            start,
            real,
        })
    }

    /// The positions of a work buffer (`rows` rows `stride` apart) in the columns `cols` of
    /// each row that no entry fills: of the complex table, or with `real` of the real one
    /// (its entries `M' >= 0`).
    pub(crate) fn holes(
        &self,
        real: bool,
        (rows, stride): (usize, usize),
        cols: &[std::ops::Range<usize>],
    ) -> Vec<usize> {
        let mut filled = vec![false; rows * stride];
        let entries = if real { &self.real } else { &self.entries };
        for &(_, idx) in entries {
            if !real || idx & Self::CONJ == 0 {
                filled[idx as usize] = true;
            }
        }
        (0..rows)
            .flat_map(|r| {
                cols.iter()
                    .flat_map(move |c| c.clone().map(move |j| r * stride + j))
            })
            .filter(|&i| !filled[i])
            .collect()
    }

    /// The entries of clusters `a..b`.
    pub(crate) fn of(&self, (a, b): (usize, usize)) -> &[(u32, u32)] {
        &self.entries[self.start[a]..self.start[b]]
    }

    /// The real entries of clusters `a..b`.
    pub(crate) fn real_of(&self, (a, b): (usize, usize)) -> &[(u32, u32)] {
        &self.real[self.start[a]..self.start[b]]
    }
}

/// What the inverse zeroes in a worker's buffer before a slice's values go in: the
/// positions the previous slice's transforms wrote that no slot fills.
pub(crate) enum Clear {
    /// Few positions (the full shape: the Nyquist row and column), one by one.
    Holes(Vec<usize>),
    /// These columns of every row (`rows` rows `stride` apart).
    Columns {
        cols: Vec<std::ops::Range<usize>>,
        rows: usize,
        stride: usize,
    },
}

impl Clear {
    /// The clear of the columns `cols` of a buffer of `rows` rows `stride` apart, of which
    /// the slots of `table` (complex, or `real`) fill all but `holes`.
    pub(crate) fn new(
        table: &SlotTable,
        real: bool,
        (rows, stride): (usize, usize),
        cols: &[std::ops::Range<usize>],
    ) -> Clear {
        let holes = table.holes(real, (rows, stride), cols);
        let written: usize = rows * cols.iter().map(|c| c.len()).sum::<usize>();
        if 8 * holes.len() <= written {
            Clear::Holes(holes)
        } else {
            Clear::Columns {
                cols: cols.to_vec(),
                rows,
                stride,
            }
        }
    }

    /// Zeroes them in `w`.
    pub(crate) fn apply<T: Copy + Default>(&self, w: &mut [T]) {
        let zero = T::default();
        match self {
            Clear::Holes(h) => h.iter().for_each(|&i| w[i] = zero),
            Clear::Columns { cols, rows, stride } => {
                for row in w.chunks_exact_mut(*stride).take(*rows) {
                    for c in cols {
                        row[c.clone()].fill(zero);
                    }
                }
            }
        }
    }
}
