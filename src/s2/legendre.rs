//! The Legendre stage of the S^2 transforms: for each order `m`, sums over the rings of the
//! associated Legendre functions `Pt_l^m(cos theta_k) = dt^l_{m,0}(theta_k)`, run by the
//! parity kernels of `dwt` (the `m' = 0` case of the Wigner recurrence, with its
//! extended-exponent starting values).
//!
//! The rings pair up with their mirrors `theta -> pi - theta`, where
//! `dt^l_{m,0}(pi - theta) = (-1)^(l+m) dt^l_{m,0}(theta)`: the kernels run over the `B`
//! rings of the northern half only, on columns (one value per ring) holding, for one or two
//! column groups (orders `m` and `-m`, or two real fields), the even and odd combinations
//! of a ring and its mirror (`E = x + x'`, `O = x - x'`, real and imaginary parts). Degree
//! `l` takes the even combinations when `l + m` is even, else the odd ones.

use crate::dwt::{self, Lanes, Prefetch, Rec};
use crate::numeric::Ext;
use crate::simd::Isa;
use crate::wigner::{big, start_norm, BetaTables, RecCoeffs, RecTables, DEFAULT_SKIP_BITS};
use num_complex::Complex64;
use std::sync::Mutex;

/// Most columns of the kernels: `E` and `O`, real and imaginary parts, of two groups.
const P: usize = 8;

/// Where an order's ring spectra are: `F_m(theta_k)` at `base + k * row + column(m)`.
#[derive(Clone, Copy)]
pub(super) struct Spectra {
    /// The first ring's spectrum.
    pub base: *mut Complex64,
    /// Values from one ring to the next.
    pub row: usize,
    /// Real rings: only orders `m >= 0` are stored (`row = B + 1`), `F_{-m} = conj(F_m)`.
    pub real: bool,
}

// SAFETY: an address only; the tasks of one execution access disjoint columns through it
// (one order each), see the SAFETY comments at the dereferences.
unsafe impl Send for Spectra {}
// SAFETY: as for Send.
unsafe impl Sync for Spectra {}

impl Spectra {
    /// Pointer to `F_m` of ring `k` (`m` taken modulo the ring length for complex rings).
    fn at(&self, k: usize, m: isize) -> *mut Complex64 {
        let col = if self.real {
            m as usize
        } else {
            m.rem_euclid(self.row as isize) as usize
        };
        self.base.wrapping_add(k * self.row + col)
    }
}

/// Where an order's coefficients are: `fhat(l, m)` at `base + start(m) + (l - |m|)`.
#[derive(Clone, Copy)]
pub(super) struct CoeffRows {
    pub base: *mut Complex64,
    /// Start of each order's block, indexed by `m + B - 1`.
    pub starts: *const usize,
    pub b: usize,
}

// SAFETY: as for `Spectra`: each task reads or writes its own orders' blocks.
unsafe impl Send for CoeffRows {}
// SAFETY: as for Send.
unsafe impl Sync for CoeffRows {}

impl CoeffRows {
    /// Pointer to `fhat(|m|, m)`, the start of order `m`'s block.
    ///
    /// # Safety
    /// `|m| < b` and `starts` holds `2b - 1` entries.
    unsafe fn block(&self, m: isize) -> *mut Complex64 {
        // SAFETY: index `m + b - 1` is in `0..2b-1` (caller's contract).
        let start = unsafe { *self.starts.add((m + self.b as isize - 1) as usize) };
        self.base.wrapping_add(start)
    }
}

/// Four kernel columns (`E` and `O`, real and imaginary parts) of one order's spectra, and
/// where that order's coefficients go (or come from).
#[derive(Clone, Copy)]
pub(super) struct Group {
    pub spectra: Spectra,
    pub coef: CoeffRows,
    /// The order, `m` or `-m`.
    pub order: isize,
    /// Forward of a real function: also write `fhat(l, -m) = (-1)^m conj(fhat(l, m))`.
    pub partner: bool,
}

impl Group {
    /// `(-1)^m` for a negative order (`dt^l_{-m,0} = (-1)^m dt^l_{m,0}`), else 1.
    fn sign(&self, m: usize) -> f64 {
        if self.order < 0 && m % 2 == 1 {
            -1.0
        } else {
            1.0
        }
    }
}

/// Per-worker scratch.
pub(super) struct Scratch {
    rec: RecCoeffs,
    tau: Vec<f64>,
    start: Vec<f64>,
    scale: Vec<f64>,
    /// Kernel columns of the rings (forward input, inverse output).
    rows: Vec<f64>,
    /// Forward: the kernel's sums (degree-major); inverse: its input.
    sums: Vec<f64>,
    /// The forward kernel's partial sums (lanes = rings).
    part: Vec<f64>,
}

impl Scratch {
    fn new(b: usize, lanes: usize, width: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(b),
            tau: vec![0.0; lanes],
            start: vec![0.0; lanes],
            scale: vec![0.0; lanes],
            rows: vec![0.0; lanes * P],
            sums: vec![0.0; (b + width) * P],
            part: vec![0.0; dwt::parity_partial_len(b, 4, width)],
        }
    }
}

/// Tables and scratch of the Legendre stage for one bandwidth.
pub(super) struct LegendreStage {
    b: usize,
    /// Degrees computed: `l < lend` (`lend <= b`; the others are zero).
    lend: usize,
    isa: Isa,
    /// Lanes: the `B` northern rings, padded to the vector width.
    lanes: usize,
    recurrence: RecTables,
    beta_tables: BetaTables,
    /// Norms of the starting values `dt^m_{m,0}`, per order.
    norms: Vec<Ext>,
    /// Quadrature weights of the northern rings (the southern ones are the same).
    weights: Vec<f64>,
    scratch: Vec<Mutex<Scratch>>,
}

impl LegendreStage {
    /// The stage for bandwidth `b` with `workers` scratches.
    pub(super) fn new(b: usize, lend: usize, isa: Isa, workers: usize) -> LegendreStage {
        assert!(0 < lend && lend <= b);
        let lanes = b.next_multiple_of(isa.lanes());
        LegendreStage {
            b,
            lend,
            isa,
            lanes,
            recurrence: RecTables::new(b),
            beta_tables: BetaTables::grid(b),
            norms: (0..b).map(|m| start_norm(m, 0)).collect(),
            weights: crate::grid::weights(b)[..b].to_vec(),
            scratch: (0..workers)
                .map(|_| Mutex::new(Scratch::new(b, lanes, isa.lanes())))
                .collect(),
        }
    }

    /// Bytes of the tables and scratch (approximately).
    pub(super) fn bytes(b: usize, workers: usize) -> usize {
        let lanes = b + 8;
        32 * (b + 1) * (b + 2)
            + 64 * 2 * b * (66 + b / 32)
            + 16 * b
            + workers * 8 * (9 * lanes + 16 * b + 4 * (b + 2) * 8)
    }

    /// Runs `f` with a free scratch (the worker's own, else another, else a new one).
    fn with_scratch<R>(&self, f: impl FnOnce(&mut Scratch) -> R) -> R {
        let n = self.scratch.len();
        let me = rayon::current_thread_index().unwrap_or(0);
        for i in 0..n {
            match self.scratch[(me + i) % n].try_lock() {
                Ok(mut g) => return f(&mut g),
                Err(std::sync::TryLockError::Poisoned(e)) => return f(&mut e.into_inner()),
                Err(std::sync::TryLockError::WouldBlock) => {}
            }
        }
        f(&mut Scratch::new(self.b, self.lanes, self.isa.lanes()))
    }

    /// Recurrence coefficients and lane inputs of order `m`; the number of degrees.
    fn setup(&self, sc: &mut Scratch, m: usize) -> usize {
        let n = self.lend - m;
        sc.rec.resize(n);
        self.recurrence.coeffs(m, 0, &mut sc.rec);
        let b = self.b;
        self.beta_tables.starts(
            self.isa,
            0,
            m,
            0,
            self.norms[m],
            DEFAULT_SKIP_BITS,
            &mut sc.start[..b],
            &mut sc.scale[..b],
        );
        sc.tau[..b].copy_from_slice(&self.beta_tables.tau_lo[..b]);
        for v in [&mut sc.tau, &mut sc.start, &mut sc.scale] {
            v[b..].fill(0.0);
        }
        n
    }

    fn lanes<'a>(&self, sc: &'a Scratch) -> Lanes<'a> {
        Lanes {
            tau: &sc.tau,
            p: &sc.start,
            sc: &sc.scale,
            upper_from: self.lanes,
            big: big(DEFAULT_SKIP_BITS),
            skip: true,
            interleaved: false,
            prefetch: Prefetch::none(),
            stream: false,
            pair_stride: 0,
            row_gap: 0,
        }
    }

    /// Forward (analysis) of order `m >= 0` for up to two column groups (see [`Group`]):
    /// `fhat(l, g.order) = factor sign(g) sum_k w_k dt^l_{m,0}(theta_k) F_{g.order}(theta_k)`,
    /// `sign = (-1)^m` for a negative order.
    ///
    /// # Safety
    /// Each group's spectra hold the `2B` rings, its coefficients the whole array; no other
    /// task touches the groups' orders meanwhile.
    pub(super) unsafe fn analyse(&self, m: usize, groups: &[Group], factor: f64) {
        assert!(!groups.is_empty() && groups.len() <= 2);
        let b = self.b;
        self.with_scratch(|sc| {
            let n = self.setup(sc, m);
            // Kernel input: the even combinations of each group's spectra (re, im), then the
            // odd ones, weighted, one column of `nb` rings each.
            let c = 2 * groups.len();
            let nb = self.lanes;
            let mut x = std::mem::take(&mut sc.rows);
            // The padding lanes are 0; the others are written below.
            for column in x[..2 * c * nb].chunks_exact_mut(nb) {
                column[b..].fill(0.0);
            }
            for (q, g) in groups.iter().enumerate() {
                for k in 0..b {
                    let w = self.weights[k];
                    let mirror = 2 * b - 1 - k;
                    // SAFETY: rings k and mirror < 2B hold the group's order; read only.
                    let (u, v) =
                        unsafe { (*g.spectra.at(k, g.order), *g.spectra.at(mirror, g.order)) };
                    let (e, o) = ((u + v) * w, (u - v) * w);
                    x[(2 * q) * nb + k] = e.re;
                    x[(2 * q + 1) * nb + k] = e.im;
                    x[(c + 2 * q) * nb + k] = o.re;
                    x[(c + 2 * q + 1) * nb + k] = o.im;
                }
            }
            let rec = Rec::new(&sc.rec, n);
            let mut sums = std::mem::take(&mut sc.sums);
            let mut part = std::mem::take(&mut sc.part);
            let lanes = self.lanes(sc);
            dwt::forward_parity(self.isa, c, &rec, &lanes, &x, (&mut part, &mut sums));
            for (q, g) in groups.iter().enumerate() {
                let f = g.sign(m) * factor;
                // SAFETY: |order| < b; the block has b - m >= n entries, this task's alone
                // (caller's contract), as has the partner block written below.
                let (own, partner) = unsafe { (g.coef.block(g.order), g.coef.block(-g.order)) };
                for i in n..b - m {
                    // SAFETY: entry i < b - m of the blocks: degrees beyond the limit are 0.
                    unsafe {
                        *own.add(i) = Complex64::default();
                        if g.partner && m > 0 {
                            *partner.add(i) = Complex64::default();
                        }
                    }
                }
                for i in 0..n {
                    let z = &sums[i * c + 2 * q..][..2];
                    let v = Complex64::new(z[0], z[1]) * (sc.rec.s[i] * f);
                    // SAFETY: entry i < n of the blocks (above).
                    unsafe {
                        *own.add(i) = v;
                        if g.partner && m > 0 {
                            *partner.add(i) = if m.is_multiple_of(2) {
                                v.conj()
                            } else {
                                -v.conj()
                            };
                        }
                    }
                }
            }
            sc.sums = sums;
            sc.part = part;
            sc.rows = x;
        });
    }

    /// Zeros for order `m` (not computed: beyond a degree or order limit): the groups'
    /// coefficient blocks (and partners) with `coeffs`, else their ring spectra.
    ///
    /// # Safety
    /// As for [`LegendreStage::analyse`].
    pub(super) unsafe fn zero_order(&self, m: usize, groups: &[Group], coeffs: bool) {
        let b = self.b;
        for g in groups {
            if coeffs {
                // SAFETY: |order| < b: blocks of b - m entries, this task's (caller's contract).
                unsafe {
                    let own = g.coef.block(g.order);
                    std::ptr::write_bytes(own, 0, b - m);
                    if g.partner && m > 0 {
                        std::ptr::write_bytes(g.coef.block(-g.order), 0, b - m);
                    }
                }
            } else {
                for k in 0..2 * b {
                    // SAFETY: ring k's value of the order, this task's column.
                    unsafe { *g.spectra.at(k, g.order) = Complex64::default() };
                }
            }
        }
    }

    /// Whether order `m` is computed (within the degree limit).
    pub(super) fn computes(&self, m: usize) -> bool {
        m < self.lend
    }

    /// Inverse (synthesis) of order `m >= 0` for up to two column groups:
    /// `F_{g.order}(theta_k) = factor sign(g) sum_l fhat(l, g.order) dt^l_{m,0}(theta_k)` into
    /// each group's spectra.
    ///
    /// # Safety
    /// As for [`LegendreStage::analyse`], with the roles of the arrays exchanged.
    pub(super) unsafe fn synthesise(&self, m: usize, groups: &[Group], factor: f64) {
        assert!(!groups.is_empty() && groups.len() <= 2);
        let b = self.b;
        self.with_scratch(|sc| {
            let n = self.setup(sc, m);
            // Kernel input: per degree, the scaled coefficients of each group (re, im).
            let c = 2 * groups.len();
            let mut fin = std::mem::take(&mut sc.sums);
            for (q, g) in groups.iter().enumerate() {
                // SAFETY: |order| < b; the block has at least n entries, only read here.
                let block = unsafe { g.coef.block(g.order) }.cast_const();
                let f = g.sign(m) * factor;
                for (i, &s) in sc.rec.s[..n].iter().enumerate() {
                    // SAFETY: entry i < n of the block (above).
                    let v = unsafe { *block.add(i) } * (s * f);
                    fin[i * c + 2 * q] = v.re;
                    fin[i * c + 2 * q + 1] = v.im;
                }
            }
            let rec = Rec::new(&sc.rec, n);
            let mut rows = std::mem::take(&mut sc.rows);
            let lanes = self.lanes(sc);
            dwt::inverse_parity(self.isa, c, &rec, &lanes, &fin[..n * c], &mut rows);
            // Columns of the output: even sums, then odd sums, `nb` lanes each.
            let nb = self.lanes;
            let column =
                |par: usize, q: usize, part: usize| &rows[(par * c + 2 * q + part) * nb..][..b];
            for (q, g) in groups.iter().enumerate() {
                let (er, ei) = (column(0, q, 0), column(0, q, 1));
                let (or, oi) = (column(1, q, 0), column(1, q, 1));
                for k in 0..b {
                    let (e, o) = (Complex64::new(er[k], ei[k]), Complex64::new(or[k], oi[k]));
                    let mirror = 2 * b - 1 - k;
                    // SAFETY: rings k and mirror, the group's order's column: this task's.
                    unsafe {
                        *g.spectra.at(k, g.order) = e + o;
                        *g.spectra.at(mirror, g.order) = e - o;
                    }
                }
            }
            sc.sums = fin;
            sc.rows = rows;
        });
    }
}
