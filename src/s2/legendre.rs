//! The Legendre stage of the S^2 transforms: for each order `m`, sums over the rings of the
//! associated Legendre functions `Pt_l^m(cos theta_k) = dt^l_{m,0}(theta_k)`, run by the
//! DWT kernels of the SO(3) transforms (the `m' = 0` case of the Wigner recurrence, with
//! its extended-exponent starting values).
//!
//! The rings pair up with their mirrors `theta -> pi - theta`, where
//! `dt^l_{m,0}(pi - theta) = (-1)^(l+m) dt^l_{m,0}(theta)`: the kernels run over the `B`
//! rings of the northern half only, on rows of eight columns holding, for the orders `m`
//! and `-m`, the even and odd combinations of a ring and its mirror (`E = x + x'`,
//! `O = x - x'`, real and imaginary parts). Degree `l` takes the even sums when `l + m` is
//! even, else the odd ones.

use crate::dwt::{self, Lanes, Prefetch, Rec};
use crate::numeric::Ext;
use crate::simd::Isa;
use crate::wigner::{big, start_norm, BetaTables, RecCoeffs, RecTables, DEFAULT_SKIP_BITS};
use num_complex::Complex64;
use std::sync::Mutex;

/// Columns of a kernel row: `E_m`, `O_m`, `E_-m`, `O_-m`, real and imaginary parts.
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

/// Per-worker scratch.
pub(super) struct Scratch {
    rec: RecCoeffs,
    tau: Vec<f64>,
    start: Vec<f64>,
    scale: Vec<f64>,
    /// Kernel rows of the rings (forward input, inverse output).
    rows: Vec<f64>,
    /// Forward: the kernel's sums; inverse: its input.
    sums: Vec<f64>,
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
        }
    }
}

/// Tables and scratch of the Legendre stage for one bandwidth.
pub(super) struct LegendreStage {
    b: usize,
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
    pub(super) fn new(b: usize, isa: Isa, workers: usize) -> LegendreStage {
        let lanes = b.next_multiple_of(isa.lanes());
        LegendreStage {
            b,
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
            + workers * 8 * (9 * lanes + 16 * b)
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
        let n = self.b - m;
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

    /// Forward (analysis) of order `m >= 0` and, for complex rings and `m > 0`, of `-m`:
    /// `fhat(l, +-m) = factor sum_k w_k dt^l_{m,0}(theta_k) F_{+-m}(theta_k)` (with
    /// `(-1)^m` for `-m`); real rings also write `fhat(l, -m) = (-1)^m conj(fhat(l, m))`.
    ///
    /// # Safety
    /// `spectra` holds the `2B` rings' spectra, `coef` the coefficient array; no other task
    /// touches order `+-m`'s blocks meanwhile.
    pub(super) unsafe fn analyse(&self, m: usize, spectra: Spectra, coef: CoeffRows, factor: f64) {
        let (b, mi) = (self.b, m as isize);
        let negative = m > 0 && !spectra.real;
        self.with_scratch(|sc| {
            let n = self.setup(sc, m);
            // Rows: E and O of F_m and F_-m, weighted.
            for k in 0..b {
                let w = self.weights[k];
                let mirror = 2 * b - 1 - k;
                let row = &mut sc.rows[k * P..][..P];
                // SAFETY: rings k and mirror < 2B hold order m's (and -m's) value; read only.
                let (x, y) = unsafe { (*spectra.at(k, mi), *spectra.at(mirror, mi)) };
                let (e, o) = ((x + y) * w, (x - y) * w);
                row[..4].copy_from_slice(&[e.re, e.im, o.re, o.im]);
                if negative {
                    // SAFETY: as above, order -m.
                    let (x, y) = unsafe { (*spectra.at(k, -mi), *spectra.at(mirror, -mi)) };
                    let (e, o) = ((x + y) * w, (x - y) * w);
                    row[4..].copy_from_slice(&[e.re, e.im, o.re, o.im]);
                } else {
                    row[4..].fill(0.0);
                }
            }
            sc.rows[b * P..].fill(0.0);
            let rec = Rec::new(&sc.rec, n);
            let mut sums = std::mem::take(&mut sc.sums);
            let lanes = self.lanes(sc);
            let lo = dwt::forward(self.isa, P, &rec, &lanes, &sc.rows, &mut sums);
            let sign_neg = if m.is_multiple_of(2) { factor } else { -factor };
            // SAFETY: |m| < b; order m's block (and -m's) has n = b - m entries, this
            // task's alone (caller's contract).
            let (pos, neg) = unsafe { (coef.block(mi), coef.block(-mi)) };
            for i in 0..n {
                let odd = i % 2;
                let row = &sums[i * P..][..P];
                let s = sc.rec.s[i];
                let (f, g) = if i < lo {
                    (Complex64::default(), Complex64::default())
                } else {
                    (
                        Complex64::new(row[2 * odd], row[2 * odd + 1]) * (s * factor),
                        Complex64::new(row[4 + 2 * odd], row[5 + 2 * odd]) * (s * sign_neg),
                    )
                };
                // SAFETY: entry i < n of the blocks (above).
                unsafe {
                    *pos.add(i) = f;
                    if negative {
                        *neg.add(i) = g;
                    } else if spectra.real && m > 0 {
                        *neg.add(i) = if m.is_multiple_of(2) {
                            f.conj()
                        } else {
                            -f.conj()
                        };
                    }
                }
            }
            sc.sums = sums;
        });
    }

    /// Inverse (synthesis) of order `m >= 0` and, for complex rings and `m > 0`, of `-m`:
    /// `F_{+-m}(theta_k) = factor sum_l fhat(l, +-m) dt^l_{+-m,0}(theta_k)` into the ring
    /// spectra (real rings: order `m` only).
    ///
    /// # Safety
    /// As for [`LegendreStage::analyse`], with the roles of the arrays exchanged.
    pub(super) unsafe fn synthesise(
        &self,
        m: usize,
        coef: CoeffRows,
        spectra: Spectra,
        factor: f64,
    ) {
        let (b, mi) = (self.b, m as isize);
        let negative = m > 0 && !spectra.real;
        self.with_scratch(|sc| {
            let n = self.setup(sc, m);
            let sign_neg = if m.is_multiple_of(2) { factor } else { -factor };
            // SAFETY: |m| < b; the blocks have n entries, only read here.
            let (pos, neg) = unsafe {
                (
                    coef.block(mi) as *const Complex64,
                    coef.block(-mi) as *const Complex64,
                )
            };
            let scales = &sc.rec.s;
            let mut fill = |fin: &mut [f64], from: usize, to: usize| {
                for i in from..to {
                    let s = scales[i];
                    // SAFETY: i < n (the kernel fills rows of its n degrees).
                    let f = unsafe { *pos.add(i) } * (s * factor);
                    let g = if negative {
                        // SAFETY: as above.
                        (unsafe { *neg.add(i) }) * (s * sign_neg)
                    } else {
                        Complex64::default()
                    };
                    let row = &mut fin[i * P..][..P];
                    row.fill(0.0);
                    let odd = i % 2;
                    row[2 * odd] = f.re;
                    row[2 * odd + 1] = f.im;
                    row[4 + 2 * odd] = g.re;
                    row[5 + 2 * odd] = g.im;
                }
            };
            let rec = Rec::new(&sc.rec, n);
            let mut sums = std::mem::take(&mut sc.sums);
            let mut rows = std::mem::take(&mut sc.rows);
            let lanes = self.lanes(sc);
            dwt::inverse(
                self.isa,
                P,
                &rec,
                &lanes,
                &mut sums[..n * P],
                &mut fill,
                &mut rows,
            );
            for k in 0..b {
                let row = &rows[k * P..][..P];
                let mirror = 2 * b - 1 - k;
                let (e, o) = (
                    Complex64::new(row[0], row[1]),
                    Complex64::new(row[2], row[3]),
                );
                // SAFETY: rings k and mirror, order m's column: this task's alone.
                unsafe {
                    *spectra.at(k, mi) = e + o;
                    *spectra.at(mirror, mi) = e - o;
                }
                if negative {
                    let (e, o) = (
                        Complex64::new(row[4], row[5]),
                        Complex64::new(row[6], row[7]),
                    );
                    // SAFETY: as above, order -m's column.
                    unsafe {
                        *spectra.at(k, -mi) = e + o;
                        *spectra.at(mirror, -mi) = e - o;
                    }
                }
            }
            sc.sums = sums;
            sc.rows = rows;
        });
    }
}
