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
use crate::real::Real;
use crate::simd::Isa;
use crate::wigner::{big, start_norm, BetaTables, RecCoeffs, RecTables, DEFAULT_SKIP_BITS};
use crate::workers::lock_free;
use num_complex::{Complex, Complex64};
use std::sync::Mutex;

/// Most columns of the kernels: `E` and `O`, real and imaginary parts, of two groups.
const P: usize = 8;

/// Where an order's ring spectra are: `F_m(theta_k)` at `base + k * row + column(m)`.
pub(super) struct Spectra<T> {
    /// The first ring's spectrum.
    pub base: *mut Complex<T>,
    /// Values from one ring to the next.
    pub row: usize,
    /// Real rings: only orders `m >= 0` are stored (`row = B + 1`), `F_{-m} = conj(F_m)`.
    pub real: bool,
    /// A block's copy (see [`Spectra::copy_block`]): the first order and the block's width.
    pub block: Option<(usize, usize)>,
}

// SAFETY: an address only; the tasks of one execution access disjoint columns through it
// (one order each), see the SAFETY comments at the dereferences.
unsafe impl<T> Send for Spectra<T> {}
// SAFETY: as for Send.
unsafe impl<T> Sync for Spectra<T> {}

impl<T> Clone for Spectra<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Spectra<T> {}

impl<T> Spectra<T> {
    /// Pointer to `F_m` of ring `k` (`m` taken modulo the ring length for complex rings).
    fn at(&self, k: usize, m: isize) -> *mut Complex<T> {
        let col = match self.block {
            // Orders first.. in the first `width` columns, their negatives in the next,
            // reversed (as they lie in a ring).
            Some((first, width)) if m < 0 => 2 * width - 1 - (m.unsigned_abs() - first),
            Some((first, _)) => m as usize - first,
            None if self.real => m as usize,
            None => m.rem_euclid(self.row as isize) as usize,
        };
        self.base.wrapping_add(k * self.row + col)
    }
}

impl<T: Copy> Spectra<T> {
    /// The view of a block's copy in `buf` (`rings * 2 width` values) of orders
    /// `first ..` (see [`Spectra::copy_block`]).
    pub(super) fn block_view(
        &self,
        (first, width): (usize, usize),
        buf: *mut Complex<T>,
    ) -> Spectra<T> {
        Spectra {
            base: buf,
            row: 2 * width,
            real: self.real,
            block: Some((first, width)),
        }
    }

    /// Copies orders `first .. first + len` (and, for complex rings, their negatives) of
    /// each of the `rings` between these spectra and the block view `block`: into the block
    /// with `gather`, else back. Each ring's orders are read as a few cache lines instead of
    /// one line per ring and order.
    ///
    /// # Safety
    /// Both hold the `rings` rings of those orders (`block` from [`Spectra::block_view`]
    /// with `len <= width`); no other task touches them meanwhile.
    pub(super) unsafe fn copy_block(
        &self,
        block: &Spectra<T>,
        rings: usize,
        len: usize,
        gather: bool,
    ) {
        let Some((first, _)) = block.block else {
            unreachable!("not a block view")
        };
        // Orders -(first + len - 1) ..= -lo, without -0: ascending columns in both.
        let lo = first.max(1);
        let top = -((first + len - 1) as isize);
        // SAFETY: orders first..first+len are contiguous in a ring (below the ring length),
        // so are their negatives (wrapped to the ring's end; reversed in the block view);
        // the caller's contract covers the rest.
        unsafe {
            for k in 0..rings {
                let (pos, neg) = (
                    (self.at(k, first as isize), block.at(k, first as isize)),
                    (self.at(k, top), block.at(k, top)),
                );
                let ((s1, d1), (s2, d2)) = if gather {
                    (pos, neg)
                } else {
                    ((pos.1, pos.0), (neg.1, neg.0))
                };
                std::ptr::copy_nonoverlapping(s1, d1, len);
                if !self.real && lo < first + len {
                    std::ptr::copy_nonoverlapping(s2, d2, first + len - lo);
                }
            }
        }
    }
}

/// `z` in doubles (exact).
fn widen<T: Real>(z: Complex<T>) -> Complex64 {
    Complex64::new(z.re.to_f64(), z.im.to_f64())
}

/// `z` rounded to `T`.
fn narrow<T: Real>(z: Complex64) -> Complex<T> {
    Complex::new(T::from_f64(z.re), T::from_f64(z.im))
}

/// Where an order's coefficients are: `fhat(l, m)` at `base + start(m) + (l - |m|)`.
pub(super) struct CoeffRows<T> {
    pub base: *mut Complex<T>,
    /// Start of each order's block, indexed by `m + B - 1`.
    pub starts: *const usize,
    pub b: usize,
}

// SAFETY: as for `Spectra`: each task reads or writes its own orders' blocks.
unsafe impl<T> Send for CoeffRows<T> {}
// SAFETY: as for Send.
unsafe impl<T> Sync for CoeffRows<T> {}

impl<T> Clone for CoeffRows<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for CoeffRows<T> {}

impl<T> CoeffRows<T> {
    /// Pointer to `fhat(|m|, m)`, the start of order `m`'s block.
    ///
    /// # Safety
    /// `|m| < b` and `starts` holds `2b - 1` entries.
    unsafe fn block(&self, m: isize) -> *mut Complex<T> {
        // SAFETY: index `m + b - 1` is in `0..2b-1` (caller's contract).
        let start = unsafe { *self.starts.add((m + self.b as isize - 1) as usize) };
        self.base.wrapping_add(start)
    }
}

/// Four kernel columns (`E` and `O`, real and imaginary parts) of one order's spectra, and
/// where that order's coefficients go (or come from).
pub(super) struct Group<T> {
    pub spectra: Spectra<T>,
    pub coef: CoeffRows<T>,
    /// The order, `m` or `-m`.
    pub order: isize,
    /// Forward of a real function: also write `fhat(l, -m) = (-1)^m conj(fhat(l, m))`.
    pub partner: bool,
}

impl<T> Clone for Group<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Group<T> {}

impl<T> Group<T> {
    /// `(-1)^m` for a negative order (`dt^l_{-m,0} = (-1)^m dt^l_{m,0}`), else 1.
    fn sign(&self, m: usize) -> f64 {
        if self.order < 0 && m % 2 == 1 {
            -1.0
        } else {
            1.0
        }
    }
}

/// A worker's kernel buffers in the kernels' element type `K`.
struct KernelBufs<K> {
    tau: Vec<K>,
    start: Vec<K>,
    scale: Vec<K>,
    /// Kernel columns of the rings (forward input, inverse output).
    rows: Vec<K>,
    /// Forward: the kernel's sums (degree-major); inverse: its input.
    sums: Vec<K>,
    /// The forward kernel's partial sums (lanes = rings).
    part: Vec<K>,
}

impl<K: Real> KernelBufs<K> {
    /// Buffers for `lanes` lanes, vectors of `width`, the recurrence arguments `tau` of the
    /// `B` northern rings (the same for every order) set once; padding lanes stay 0.
    fn new(b: usize, lanes: usize, width: usize, tau: &[f64]) -> KernelBufs<K> {
        let z = K::ZERO;
        let mut t = vec![z; lanes];
        for (t, &x) in t.iter_mut().zip(&tau[..b]) {
            *t = K::from_f64(x);
        }
        KernelBufs {
            tau: t,
            start: vec![z; lanes],
            scale: vec![z; lanes],
            rows: vec![z; lanes * P],
            sums: vec![z; (b + width) * P],
            part: vec![z; dwt::parity_partial_len(b, 4, width)],
        }
    }
}

/// Per-worker scratch: the coefficients of an order (double, and rounded to floats for
/// float kernels) and the buffers of double and float kernels (made on first use).
pub(super) struct Scratch {
    rec: RecCoeffs,
    rec32: RecCoeffs<f32>,
    wide: Option<KernelBufs<f64>>,
    narrow: Option<KernelBufs<f32>>,
}

impl Scratch {
    fn new(b: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(b),
            rec32: RecCoeffs::new(0),
            wide: None,
            narrow: None,
        }
    }
}

/// The kernels' element type for an order: doubles, or floats (see
/// [`crate::wigner::single_precision_orders`]).
trait KernelElem: Real {
    /// This type's buffers in `sc` (made on first use), the order's coefficients in this
    /// type and their scales `S_i` in doubles.
    fn bufs<'a>(sc: &'a mut Scratch, dims: BufDims<'_>) -> KernelInputs<'a, Self>;
}

/// What [`KernelElem::bufs`] gives.
type KernelInputs<'a, K> = (&'a mut KernelBufs<K>, &'a RecCoeffs<K>, &'a [f64]);

/// The sizes of new [`KernelBufs`] (`b`, lanes, vector width) and the rings' `tau`.
type BufDims<'t> = (usize, usize, usize, &'t [f64]);

impl KernelElem for f64 {
    fn bufs<'a>(sc: &'a mut Scratch, (b, lanes, w, tau): BufDims<'_>) -> KernelInputs<'a, f64> {
        let bufs = sc
            .wide
            .get_or_insert_with(|| KernelBufs::new(b, lanes, w, tau));
        (bufs, &sc.rec, &sc.rec.s)
    }
}

impl KernelElem for f32 {
    fn bufs<'a>(sc: &'a mut Scratch, (b, lanes, w, tau): BufDims<'_>) -> KernelInputs<'a, f32> {
        sc.rec32.narrow_from(&sc.rec);
        let bufs = sc
            .narrow
            .get_or_insert_with(|| KernelBufs::new(b, lanes, w, tau));
        (bufs, &sc.rec32, &sc.rec.s)
    }
}

/// Tables and scratch of the Legendre stage for one bandwidth, samples and coefficients in
/// `T`.
pub(super) struct LegendreStage<T> {
    b: usize,
    /// Degrees computed: `l < lend` (`lend <= b`; the others are zero).
    lend: usize,
    isa: Isa,
    /// Lanes: the `B` northern rings, padded to the vector width of `T` (a multiple of
    /// the double width too).
    lanes: usize,
    /// Orders `m >= narrow_from` run float kernels (`T = f32`); the others double ones.
    narrow_from: usize,
    recurrence: RecTables,
    beta_tables: BetaTables,
    /// Norms of the starting values `dt^m_{m,0}`, per order.
    norms: Vec<Ext>,
    /// Quadrature weights of the northern rings (the southern ones are the same).
    weights: Vec<f64>,
    scratch: Vec<Mutex<Scratch>>,
    element: std::marker::PhantomData<T>,
}

impl<T: Real> LegendreStage<T> {
    /// The stage for bandwidth `b` with `workers` scratches.
    pub(super) fn new(b: usize, lend: usize, isa: Isa, workers: usize) -> LegendreStage<T> {
        assert!(0 < lend && lend <= b);
        let lanes = b.next_multiple_of(isa.lanes_of::<T>());
        let narrow_from = if T::BYTES == 4 {
            crate::wigner::single_precision_orders(b)
        } else {
            usize::MAX
        };
        LegendreStage {
            b,
            lend,
            isa,
            lanes,
            narrow_from,
            recurrence: RecTables::new(b),
            beta_tables: BetaTables::grid(b),
            norms: (0..b).map(|m| start_norm(m, 0)).collect(),
            weights: crate::grid::weights(b)[..b].to_vec(),
            scratch: (0..workers).map(|_| Mutex::new(Scratch::new(b))).collect(),
            element: std::marker::PhantomData,
        }
    }

    /// Bytes of the tables and scratch (approximately).
    pub(super) fn bytes(b: usize, workers: usize) -> usize {
        let lanes = b + 16;
        let kernel = |size: usize| size * (9 * lanes + 16 * b + 4 * (b + 2) * 16);
        let per_worker = 8 * 5 * b
            + kernel(8)
            + if T::BYTES == 4 {
                kernel(4) + 4 * 5 * b
            } else {
                0
            };
        32 * (b + 1) * (b + 2) + 64 * 2 * b * (66 + b / 32) + 16 * b + workers * per_worker
    }

    /// Runs `f` with a free scratch (the worker's own, else another, else a new one).
    fn with_scratch<R>(&self, f: impl FnOnce(&mut Scratch) -> R) -> R {
        match lock_free(&self.scratch) {
            Some(mut g) => f(&mut g),
            None => f(&mut Scratch::new(self.b)),
        }
    }

    /// The recurrence coefficients of order `m` into `sc`; the number of degrees.
    fn coeffs(&self, sc: &mut Scratch, m: usize) -> usize {
        let n = self.lend - m;
        sc.rec.resize(n);
        self.recurrence.coeffs(m, 0, &mut sc.rec);
        n
    }

    /// The starting values of order `m` in `bufs` (the padding lanes stay 0).
    fn lane_inputs<K: Real>(&self, bufs: &mut KernelBufs<K>, m: usize) {
        let b = self.b;
        self.beta_tables.starts::<K>(
            self.isa,
            0,
            m,
            0,
            self.norms[m],
            DEFAULT_SKIP_BITS,
            &mut bufs.start[..b],
            &mut bufs.scale[..b],
        );
    }

    fn lanes<'a, K: Real>(&self, bufs: &'a KernelBufs<K>) -> Lanes<'a, K> {
        Lanes {
            tau: &bufs.tau,
            p: &bufs.start,
            sc: &bufs.scale,
            upper_from: self.lanes,
            big: big::<K>(DEFAULT_SKIP_BITS),
            skip: true,
            interleaved: false,
            prefetch: Prefetch::none(),
            stream: false,
            pair_stride: 0,
            row_gap: 0,
        }
    }

    /// Whether order `m` runs float kernels.
    fn narrow(&self, m: usize) -> bool {
        m >= self.narrow_from
    }

    /// Forward (analysis) of order `m >= 0` for up to two column groups (see [`Group`]):
    /// `fhat(l, g.order) = factor sign(g) sum_k w_k dt^l_{m,0}(theta_k) F_{g.order}(theta_k)`,
    /// `sign = (-1)^m` for a negative order.
    ///
    /// # Safety
    /// Each group's spectra hold the `2B` rings, its coefficients the whole array; no other
    /// task touches the groups' orders meanwhile.
    pub(super) unsafe fn analyse(&self, m: usize, groups: &[Group<T>], factor: f64) {
        // SAFETY: the caller's contract.
        unsafe {
            if self.narrow(m) {
                self.analyse_in::<f32>(m, groups, factor)
            } else {
                self.analyse_in::<f64>(m, groups, factor)
            }
        }
    }

    /// [`LegendreStage::analyse`] with kernels in `K`.
    ///
    /// # Safety
    /// As for [`LegendreStage::analyse`].
    unsafe fn analyse_in<K: KernelElem>(&self, m: usize, groups: &[Group<T>], factor: f64) {
        assert!(!groups.is_empty() && groups.len() <= 2);
        let b = self.b;
        let w = self.isa.lanes_of::<K>();
        self.with_scratch(|sc| {
            let n = self.coeffs(sc, m);
            let (bufs, rc, s) = K::bufs(sc, (b, self.lanes, w, &self.beta_tables.tau_lo));
            self.lane_inputs(bufs, m);
            // Kernel input: the even combinations of each group's spectra (re, im), then the
            // odd ones, weighted, one column of `nb` rings each.
            let c = 2 * groups.len();
            let nb = self.lanes;
            let mut x = std::mem::take(&mut bufs.rows);
            // The padding lanes are 0; the others are written below.
            for column in x[..2 * c * nb].chunks_exact_mut(nb) {
                column[b..].fill(K::ZERO);
            }
            for (q, g) in groups.iter().enumerate() {
                for k in 0..b {
                    let wk = self.weights[k];
                    let mirror = 2 * b - 1 - k;
                    // SAFETY: rings k and mirror < 2B hold the group's order; read only.
                    let (u, v) = unsafe {
                        (
                            widen(*g.spectra.at(k, g.order)),
                            widen(*g.spectra.at(mirror, g.order)),
                        )
                    };
                    let (e, o) = ((u + v) * wk, (u - v) * wk);
                    x[(2 * q) * nb + k] = K::from_f64(e.re);
                    x[(2 * q + 1) * nb + k] = K::from_f64(e.im);
                    x[(c + 2 * q) * nb + k] = K::from_f64(o.re);
                    x[(c + 2 * q + 1) * nb + k] = K::from_f64(o.im);
                }
            }
            let rec = Rec::new(rc, n);
            let mut sums = std::mem::take(&mut bufs.sums);
            let mut part = std::mem::take(&mut bufs.part);
            let lanes = self.lanes(bufs);
            dwt::forward_parity(self.isa, c, &rec, &lanes, &x, (&mut part, &mut sums));
            let zero = Complex::new(T::ZERO, T::ZERO);
            for (q, g) in groups.iter().enumerate() {
                let f = g.sign(m) * factor;
                // SAFETY: |order| < b; the block has b - m >= n entries, this task's alone
                // (caller's contract), as has the partner block written below.
                let (own, partner) = unsafe { (g.coef.block(g.order), g.coef.block(-g.order)) };
                for i in n..b - m {
                    // SAFETY: entry i < b - m of the blocks: degrees beyond the limit are 0.
                    unsafe {
                        *own.add(i) = zero;
                        if g.partner && m > 0 {
                            *partner.add(i) = zero;
                        }
                    }
                }
                for i in 0..n {
                    let z = &sums[i * c + 2 * q..][..2];
                    let v = narrow(Complex64::new(z[0].to_f64(), z[1].to_f64()) * (s[i] * f));
                    // SAFETY: entry i < n of the blocks (above).
                    unsafe {
                        *own.add(i) = v;
                        if g.partner && m > 0 {
                            *partner.add(i) = if m.is_multiple_of(2) {
                                Complex::new(v.re, -v.im)
                            } else {
                                Complex::new(-v.re, v.im)
                            };
                        }
                    }
                }
            }
            bufs.sums = sums;
            bufs.part = part;
            bufs.rows = x;
        });
    }

    /// Zeros for order `m` (not computed: beyond a degree or order limit): the groups'
    /// coefficient blocks (and partners) with `coeffs`, else their ring spectra.
    ///
    /// # Safety
    /// As for [`LegendreStage::analyse`].
    pub(super) unsafe fn zero_order(&self, m: usize, groups: &[Group<T>], coeffs: bool) {
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
                    unsafe { *g.spectra.at(k, g.order) = Complex::new(T::ZERO, T::ZERO) };
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
    pub(super) unsafe fn synthesise(&self, m: usize, groups: &[Group<T>], factor: f64) {
        // SAFETY: the caller's contract.
        unsafe {
            if self.narrow(m) {
                self.synthesise_in::<f32>(m, groups, factor)
            } else {
                self.synthesise_in::<f64>(m, groups, factor)
            }
        }
    }

    /// [`LegendreStage::synthesise`] with kernels in `K`.
    ///
    /// # Safety
    /// As for [`LegendreStage::synthesise`].
    unsafe fn synthesise_in<K: KernelElem>(&self, m: usize, groups: &[Group<T>], factor: f64) {
        assert!(!groups.is_empty() && groups.len() <= 2);
        let b = self.b;
        let w = self.isa.lanes_of::<K>();
        self.with_scratch(|sc| {
            let n = self.coeffs(sc, m);
            let (bufs, rc, s) = K::bufs(sc, (b, self.lanes, w, &self.beta_tables.tau_lo));
            self.lane_inputs(bufs, m);
            // Kernel input: per degree, the scaled coefficients of each group (re, im).
            let c = 2 * groups.len();
            let mut fin = std::mem::take(&mut bufs.sums);
            for (q, g) in groups.iter().enumerate() {
                // SAFETY: |order| < b; the block has at least n entries, only read here.
                let block = unsafe { g.coef.block(g.order) }.cast_const();
                let f = g.sign(m) * factor;
                for (i, &si) in s[..n].iter().enumerate() {
                    // SAFETY: entry i < n of the block (above).
                    let v = widen(unsafe { *block.add(i) }) * (si * f);
                    fin[i * c + 2 * q] = K::from_f64(v.re);
                    fin[i * c + 2 * q + 1] = K::from_f64(v.im);
                }
            }
            let rec = Rec::new(rc, n);
            let mut rows = std::mem::take(&mut bufs.rows);
            let lanes = self.lanes(bufs);
            dwt::inverse_parity(self.isa, c, &rec, &lanes, &fin[..n * c], &mut rows);
            // Columns of the output: even sums, then odd sums, `nb` lanes each.
            let nb = self.lanes;
            let column =
                |par: usize, q: usize, part: usize| &rows[(par * c + 2 * q + part) * nb..][..b];
            for (q, g) in groups.iter().enumerate() {
                let (er, ei) = (column(0, q, 0), column(0, q, 1));
                let (or, oi) = (column(1, q, 0), column(1, q, 1));
                for k in 0..b {
                    let (e, o) = (
                        Complex::new(er[k].to_f64(), ei[k].to_f64()),
                        Complex::new(or[k].to_f64(), oi[k].to_f64()),
                    );
                    let mirror = 2 * b - 1 - k;
                    // SAFETY: rings k and mirror, the group's order's column: this task's.
                    unsafe {
                        *g.spectra.at(k, g.order) = narrow(e + o);
                        *g.spectra.at(mirror, g.order) = narrow(e - o);
                    }
                }
            }
            bufs.sums = fin;
            bufs.rows = rows;
        });
    }
}
