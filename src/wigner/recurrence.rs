//! Recurrence coefficients of the Wigner-d three-term recurrence in `l`, each the double
//! nearest to its exact value.

use crate::numeric::Dd;
use crate::real::Elem;

/// Tables from which the recurrence coefficients of any base pair follow by a few
/// double-double multiplications per degree (no square root per cluster), so that every
/// coefficient the kernels use is the double nearest to its exact value (to within a few
/// units in the 30th decimal place). Correct rounding matters: coefficients formed as
/// products of rounded table values (3-5 roundings each) give clearly larger round-trip
/// errors.
pub struct RecTables {
    stride: usize,
    /// `sqrt((l+1) sqrt((2l+3)(2l+1)) / ((l+1)^2 - m^2))` at `[m * stride + l]` (`l >= m`):
    /// `A_l = a_factor[m][l] a_factor[m'][l]`.
    a_factor: DdVec,
    /// `sqrt(sqrt((2l+3)/(2l-1)) (l+1)/l (l^2 - m^2) / ((l+1)^2 - m^2))` (`l >= m`, 0 at
    /// `l = 0`): `Bc_l = bc_factor[m][l] bc_factor[m'][l]`.
    bc_factor: DdVec,
    /// `1 / (l(l+1))` (0 at `l = 0`).
    inv_l_l1: DdVec,
    /// `l(l+1)` (a table, so that the coefficient loop converts no integers and vectorises).
    l_l1: Vec<f64>,
    /// Row of order `m` in `a_factor` and `bc_factor` (`usize::MAX`: not tabulated).
    order_row: Vec<usize>,
    /// x86-64 with FMA and AVX2: the coefficients are computed in a function compiled for
    /// them (the double-double products need fused multiply-adds; without the feature
    /// `f64::mul_add` is a library call there, equally exact but slow).
    use_fma: bool,
}

/// A table of double-double values as separate arrays of high and low parts.
#[derive(Default)]
struct DdVec {
    hi: Vec<f64>,
    lo: Vec<f64>,
}

impl DdVec {
    fn from_fn(n: usize, f: impl Fn(usize) -> Dd) -> DdVec {
        let (hi, lo) = (0..n).map(f).map(|d| (d.hi, d.lo)).unzip();
        DdVec { hi, lo }
    }

    /// High and low parts of entries `at .. at + n`.
    #[inline(always)]
    fn run(&self, at: usize, n: usize) -> (&[f64], &[f64]) {
        (&self.hi[at..at + n], &self.lo[at..at + n])
    }
}

fn fma_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("fma") && is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

impl RecTables {
    /// Tables for degrees up to `lmax` (coefficients for `l <= lmax`).
    pub fn new(lmax: usize) -> RecTables {
        let orders: Vec<usize> = (0..=lmax).collect();
        Self::for_orders(lmax, &orders)
    }

    /// Tables for degrees up to `lmax` holding only the rows of the orders `orders`
    /// (`O(lmax)` per order): enough for the base pairs made of them.
    pub fn for_orders(lmax: usize, orders: &[usize]) -> RecTables {
        let use_fma = fma_available();
        #[cfg(target_arch = "x86_64")]
        if use_fma {
            // SAFETY: the CPU supports FMA and AVX2 (`fma_available`).
            return unsafe { Self::new_fma(lmax, orders) };
        }
        Self::new_body(lmax, orders, use_fma)
    }

    /// [`RecTables::for_orders`] compiled for FMA and AVX2.
    ///
    /// # Safety
    /// The CPU supports FMA and AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn new_fma(lmax: usize, orders: &[usize]) -> RecTables {
        Self::new_body(lmax, orders, true)
    }

    #[inline(always)]
    fn new_body(lmax: usize, orders: &[usize], use_fma: bool) -> RecTables {
        let stride = lmax + 2;
        let mut order_row = vec![usize::MAX; lmax + 1];
        let mut tabulated = Vec::new();
        for &m in orders {
            assert!(m <= lmax, "order {m} above lmax {lmax}");
            if order_row[m] == usize::MAX {
                order_row[m] = tabulated.len();
                tabulated.push(m);
            }
        }
        // `l^2 - m^2` and `(l+1)^2 - m^2` are exact integers in a double (l < 2^26).
        let sq = |k: usize| (k * k) as f64;
        let a_numerator = |l: usize| {
            let l = l as f64;
            Dd::prod(2.0 * l + 3.0, 2.0 * l + 1.0).sqrt().mul_f(l + 1.0)
        };
        let bc_numerator = |l: usize| {
            let l = l as f64;
            Dd::new(2.0 * l + 3.0)
                .div(Dd::new(2.0 * l - 1.0))
                .sqrt()
                .mul_f(l + 1.0)
                .div(Dd::new(l))
        };
        let a_factor = DdVec::from_fn(tabulated.len() * stride, |k| {
            let (m, l) = (tabulated[k / stride], k % stride);
            if l >= m && l <= lmax {
                a_numerator(l).div(Dd::new(sq(l + 1) - sq(m))).sqrt()
            } else {
                Dd::new(0.0)
            }
        });
        let bc_factor = DdVec::from_fn(tabulated.len() * stride, |k| {
            let (m, l) = (tabulated[k / stride], k % stride);
            if l >= m && l <= lmax && l > 0 {
                bc_numerator(l)
                    .mul_f(sq(l) - sq(m))
                    .div(Dd::new(sq(l + 1) - sq(m)))
                    .sqrt()
            } else {
                Dd::new(0.0)
            }
        });
        let inv_l_l1 = DdVec::from_fn(lmax + 1, |l| {
            let l = l as f64;
            if l == 0.0 {
                Dd::new(0.0)
            } else {
                Dd::new(1.0).div(Dd::new(l * (l + 1.0)))
            }
        });
        RecTables {
            stride,
            a_factor,
            bc_factor,
            inv_l_l1,
            l_l1: (0..=lmax).map(|l| (l * (l + 1)) as f64).collect(),
            order_row,
            use_fma,
        }
    }

    /// Recurrence coefficients of base pair `(m, mp)` for `l = m .. m + n`, `l = m + i`.
    ///
    /// The three-term recurrence is
    /// `dt^{l+1} = (A_l x + C_l) dt^l - Bc_l dt^{l-1}` with (`q(l) = sqrt((l^2-m^2)(l^2-m'^2))`)
    /// `A_l = (l+1) sqrt((2l+3)(2l+1)) / q(l+1)`, `C_l = -A_l m m' / (l(l+1))`,
    /// `Bc_l = sqrt((2l+3)/(2l-1)) (l+1)/l q(l)/q(l+1)`.
    ///
    /// The kernels run it on scaled values `e_i = dt^{m+i} / S_i` with `S_0 = S_1 = 1` and
    /// `S_{i+1} = Bc_{m+i} S_{i-1}`, for which the last coefficient is 1:
    /// `e_{i+1} = (A'_i x + C'_i) e_i - e_{i-1}`, `A'_i = A_{m+i} S_i / S_{i+1}` (likewise
    /// `C'`). That saves one multiplication per step and value vector (a tenth of the
    /// 8-column kernels' operations). The scale `S_i` (stored in `s`, between 0.08 and 1.13
    /// up to B = 512) is applied where the coefficients are copied to or from the kernels'
    /// rows. `S_{i+1}` is the rounded product of the rounded `Bc` and `S_{i-1}`: the
    /// recurrence the kernels run differs from the exact one by that rounding (as by the
    /// rounding of `Bc` itself), and the values are scaled back by the same stored `S_i`,
    /// so the error of the running product cancels. `A'` and `C'` are formed from `S_i` and
    /// `S_{i+1}` in double-double and rounded once.
    ///
    /// `A'` and `C'` are stored for the two argument forms the kernels use: with
    /// `x = 1 - tau`, `A x + C = (A + C) - A tau`, and with `x = tau - 1`,
    /// `A x + C = A tau + (C - A)`; `A + C = A (1 - m m' / (l(l+1)))` is formed without
    /// cancellation.
    pub fn coeffs(&self, m: usize, mp: usize, r: &mut RecCoeffs) {
        let n = r.len();
        assert!(m + n < self.stride && mp <= m);
        assert!(
            self.order_row[m] != usize::MAX && self.order_row[mp] != usize::MAX,
            "orders ({m}, {mp}) not tabulated"
        );
        #[cfg(target_arch = "x86_64")]
        if self.use_fma {
            // SAFETY: `use_fma` is set only where the CPU supports FMA and AVX2.
            return unsafe { self.coeffs_fma(m, mp, r) };
        }
        self.coeffs_body(m, mp, r)
    }

    /// [`RecTables::coeffs`] compiled for FMA and AVX2.
    ///
    /// # Safety
    /// The CPU supports FMA and AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn coeffs_fma(&self, m: usize, mp: usize, r: &mut RecCoeffs) {
        self.coeffs_body(m, mp, r)
    }

    #[inline(always)]
    fn coeffs_body(&self, m: usize, mp: usize, r: &mut RecCoeffs) {
        let n = r.len();
        if n == 0 {
            return;
        }
        let stride = self.stride;
        let mm = (m * mp) as f64;
        // Table runs for `l = m .. m + n`, as slices of length `n` so that the loops below
        // have no bounds checks and vectorise.
        let (inv_ll_hi, inv_ll_lo) = self.inv_l_l1.run(m, n);
        let (row_m, row_mp) = (self.order_row[m] * stride, self.order_row[mp] * stride);
        let (a_m_hi, a_m_lo) = self.a_factor.run(row_m + m, n);
        let (a_mp_hi, a_mp_lo) = self.a_factor.run(row_mp + m, n);
        let (bc_m_hi, bc_m_lo) = self.bc_factor.run(row_m + m, n);
        let (bc_mp_hi, bc_mp_lo) = self.bc_factor.run(row_mp + m, n);
        let l_l1 = &self.l_l1[m..m + n];
        let dd = |h: &[f64], l: &[f64], i: usize| Dd { hi: h[i], lo: l[i] };
        // `Bc` rounded (into `r.c_minus_a` for now), then the scales `S_i`.
        let bc = &mut r.c_minus_a[..n];
        for (i, b) in bc.iter_mut().enumerate() {
            *b = dd(bc_m_hi, bc_m_lo, i)
                .mul(dd(bc_mp_hi, bc_mp_lo, i))
                .to_f64();
        }
        let scale = &mut r.s[..n];
        let (mut s0, mut s1) = (1.0, 1.0);
        for i in 0..n {
            scale[i] = s1;
            // `S_{i+1}`: `S_1 = 1` (the step from `i = 0` has no `dt^{l-1}` term).
            let s2 = if i == 0 { 1.0 } else { bc[i] * s0 };
            (s0, s1) = (s1, s2);
        }
        let (out_a, out_neg_a, out_a_plus_c, out_c_minus_a) = (
            &mut r.a[..n],
            &mut r.neg_a[..n],
            &mut r.a_plus_c[..n],
            &mut r.c_minus_a[..n],
        );
        let scale = &r.s[..n];
        // Written out twice (a closure would not be inlined into this `target_feature`
        // function, and would then neither vectorise nor use FMA instructions).
        macro_rules! coeff {
            ($i:expr, $s_next:expr) => {{
                let i = $i;
                // `A' = A S_i / S_{i+1}`.
                let f = Dd::quot(scale[i], $s_next);
                let a = dd(a_m_hi, a_m_lo, i).mul(dd(a_mp_hi, a_mp_lo, i)).mul(f);
                // `A + C = A (ll - mm) / ll`, `C - A = -A (ll + mm) / ll`: exact integers
                // times `1 / ll`, no cancellation.
                let ll = l_l1[i];
                let d = a.mul(dd(inv_ll_hi, inv_ll_lo, i).mul_f(ll - mm));
                out_a[i] = a.to_f64();
                out_neg_a[i] = -out_a[i];
                out_a_plus_c[i] = d.to_f64();
                out_c_minus_a[i] = -a.mul(dd(inv_ll_hi, inv_ll_lo, i).mul_f(ll + mm)).to_f64();
            }};
        }
        for i in 0..n - 1 {
            coeff!(i, scale[i + 1]);
        }
        // The last degree's coefficient is never used (it would step to degree `m + n`),
        // so any scale does there.
        coeff!(n - 1, scale[n - 1]);
        if m == 0 {
            // `l = 0`: `C = 0` (`1 / ll` is stored as 0).
            (out_a_plus_c[0], out_c_minus_a[0]) = (out_a[0], -out_a[0]);
        }
    }
}

/// Zero entries after the last degree of every [`RecCoeffs`] array: the forward kernel
/// runs its last block of degrees in full (see the `dwt` module's `forward`), stepping up to
/// `REC_PAD - 1` degrees past the end.
pub(crate) const REC_PAD: usize = 8;

/// Recurrence coefficients of one cluster (see [`RecTables::coeffs`]), index `i = l - l0`,
/// for `len()` degrees; each array holds [`REC_PAD`] zeros after them. In element type `E`:
/// [`RecTables::coeffs`] fills the f64 form, [`RecCoeffs::narrow_from`] the f32 one.
#[derive(Default)]
pub struct RecCoeffs<E: Elem = f64> {
    /// `A'_i`
    pub a: Vec<E>,
    /// `-A'_i`
    pub neg_a: Vec<E>,
    /// `A'_i + C'_i`
    pub a_plus_c: Vec<E>,
    /// `C'_i - A'_i`
    pub c_minus_a: Vec<E>,
    /// The scale `S_i` of the values (see [`RecTables::coeffs`]).
    pub s: Vec<E>,
    n: usize,
}

impl<E: Elem> RecCoeffs<E> {
    /// Arrays for `n` degrees.
    pub fn new(n: usize) -> RecCoeffs<E> {
        let mut r = RecCoeffs::default();
        r.resize(n);
        r
    }

    /// Number of degrees.
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    /// Shorten (or lengthen) every array to `n` degrees (and the zero padding).
    pub fn resize(&mut self, n: usize) {
        for v in [
            &mut self.a,
            &mut self.neg_a,
            &mut self.a_plus_c,
            &mut self.c_minus_a,
            &mut self.s,
        ] {
            v.resize(n + REC_PAD, E::ZERO);
            v[n..].fill(E::ZERO);
        }
        self.n = n;
    }
}

impl RecCoeffs<f32> {
    /// `src` with every entry (the padding's zeros included) rounded to the nearest `f32`,
    /// in this value's arrays (no allocation once they are long enough): the coefficients
    /// of the f32 kernels, `O(n)` per cluster. The coefficients are far from the f32 range's
    /// ends (`|A'|`, `|C'|` below a few times the degree, `S_i` near 1), so all stay finite
    /// and normal or zero.
    pub fn narrow_from(&mut self, src: &RecCoeffs<f64>) {
        for (dst, src) in [
            (&mut self.a, &src.a),
            (&mut self.neg_a, &src.neg_a),
            (&mut self.a_plus_c, &src.a_plus_c),
            (&mut self.c_minus_a, &src.c_minus_a),
            (&mut self.s, &src.s),
        ] {
            dst.clear();
            dst.extend(src.iter().map(|&x| x as f32));
        }
        self.n = src.n;
    }
}

#[cfg(test)]
mod tests {
    use super::{RecCoeffs, RecTables, REC_PAD};
    use crate::numeric::exact::is_rounded_sqrt;

    /// The first coefficients of each base pair (where the scale is 1) against their
    /// exact values: `A` and both argument forms of `A + C` are the nearest doubles.
    #[test]
    fn first_coefficients_are_correctly_rounded() {
        let rt = RecTables::new(40);
        let mut checked = [0; 3];
        for m in 0..=24u128 {
            for mp in 0..=m {
                let mut r = RecCoeffs::new(3);
                rt.coeffs(m as usize, mp as usize, &mut r);
                let l = m;
                // A^2 = (l+1)^2 (2l+3)(2l+1) / (((l+1)^2 - m^2)((l+1)^2 - m'^2)).
                let n = (l + 1) * (l + 1) * (2 * l + 3) * (2 * l + 1);
                let d = ((l + 1) * (l + 1) - m * m) * ((l + 1) * (l + 1) - mp * mp);
                assert_eq!(r.s[0], 1.0);
                assert_eq!(r.neg_a[0], -r.a[0]);
                if let Some(ok) = is_rounded_sqrt(r.a[0], n, d) {
                    assert!(ok, "A at m={m} mp={mp}: {:e}", r.a[0]);
                    checked[0] += 1;
                }
                let (ll, mm) = (l * (l + 1), m * mp);
                if mm == 0 {
                    assert_eq!(
                        (r.a_plus_c[0], r.c_minus_a[0]),
                        (r.a[0], -r.a[0]),
                        "m={m} mp={mp}"
                    );
                    continue;
                }
                // (A + C)^2 = A^2 ((ll - mm) / ll)^2, (C - A)^2 = A^2 ((ll + mm) / ll)^2.
                let dd = d * ll * ll;
                if let Some(ok) = is_rounded_sqrt(r.a_plus_c[0], n * (ll - mm) * (ll - mm), dd) {
                    assert!(ok, "A + C at m={m} mp={mp}: {:e}", r.a_plus_c[0]);
                    checked[1] += 1;
                }
                if let Some(ok) = is_rounded_sqrt(-r.c_minus_a[0], n * (ll + mm) * (ll + mm), dd) {
                    assert!(ok, "C - A at m={m} mp={mp}: {:e}", r.c_minus_a[0]);
                    checked[2] += 1;
                }
            }
        }
        assert!(
            checked.iter().all(|&c| c >= 20),
            "too few exact checks: {checked:?}"
        );
    }

    /// `narrow_from` rounds every entry, padding included, to the nearest f32, keeps the
    /// length, and reuses its arrays when shrinking.
    #[test]
    fn narrowing_rounds_each_entry() {
        let rt = RecTables::new(200);
        let mut r32 = RecCoeffs::<f32>::new(3);
        for (m, mp, n) in [(0, 0, 200), (7, 3, 150), (120, 120, 80), (199, 0, 1)] {
            let mut r = RecCoeffs::new(n);
            rt.coeffs(m, mp, &mut r);
            let ptr = r32.a.as_ptr();
            let grows = r32.a.capacity() < n + REC_PAD;
            r32.narrow_from(&r);
            assert!(grows || r32.a.as_ptr() == ptr, "reallocated");
            assert_eq!(r32.len(), n);
            for (wide, narrow) in [
                (&r.a, &r32.a),
                (&r.neg_a, &r32.neg_a),
                (&r.a_plus_c, &r32.a_plus_c),
                (&r.c_minus_a, &r32.c_minus_a),
                (&r.s, &r32.s),
            ] {
                assert_eq!(narrow.len(), n + REC_PAD);
                for (i, (&x, &y)) in wide.iter().zip(narrow).enumerate() {
                    // Nearest: no f32 lies strictly closer to x than y.
                    let err = (y as f64 - x).abs();
                    let (up, down) = (
                        f32::from_bits(y.to_bits() + 1),
                        f32::from_bits(y.to_bits() - 1),
                    );
                    assert!(y.is_finite() && (i < n || y == 0.0), "m={m} mp={mp} i={i}");
                    if y != 0.0 {
                        assert!(err <= (up as f64 - x).abs() && err <= (down as f64 - x).abs());
                    } else {
                        assert_eq!(x, 0.0);
                    }
                }
            }
        }
    }

    /// The scaled coefficients undo their scales: `A'_i S_{i+1} / S_i = A_i` and
    /// `S_{i+1} / S_{i-1} = Bc_i`, against the closed forms evaluated directly.
    #[test]
    fn scaled_coefficients_match_the_closed_forms() {
        let lmax = 300;
        let rt = RecTables::new(lmax);
        for (m, mp) in [
            (0, 0),
            (1, 0),
            (5, 3),
            (40, 40),
            (100, 7),
            (150, 149),
            (299, 0),
        ] {
            let n = lmax - m;
            let mut r = RecCoeffs::new(n);
            rt.coeffs(m, mp, &mut r);
            let q = |l: f64| {
                let (m, mp) = (m as f64, mp as f64);
                ((l * l - m * m) * (l * l - mp * mp)).sqrt()
            };
            let close = |x: f64, want: f64, what: &str, i: usize| {
                assert!(
                    (x - want).abs() <= 4e-15 * want.abs(),
                    "{what} m={m} mp={mp} i={i}: {x:e} against {want:e}"
                );
            };
            for i in 0..n - 1 {
                let l = (m + i) as f64;
                let a = (l + 1.0) * ((2.0 * l + 3.0) * (2.0 * l + 1.0)).sqrt() / q(l + 1.0);
                // A + C = A (ll - mm) / ll: exact integers, no cancellation.
                let (ll, mm) = (l * (l + 1.0), (m * mp) as f64);
                let (apc, cma) = if l == 0.0 {
                    (a, -a)
                } else {
                    (a * (ll - mm) / ll, -a * (ll + mm) / ll)
                };
                let f = r.s[i + 1] / r.s[i];
                close(r.a[i] * f, a, "A", i);
                close(r.a_plus_c[i] * f, apc, "A + C", i);
                close(r.c_minus_a[i] * f, cma, "C - A", i);
                if i >= 1 {
                    let bc = ((2.0 * l + 3.0) / (2.0 * l - 1.0)).sqrt() * (l + 1.0) / l * q(l)
                        / q(l + 1.0);
                    close(r.s[i + 1] / r.s[i - 1], bc, "Bc", i);
                }
                assert!(
                    r.s[i] > 0.05 && r.s[i] < 1.2,
                    "scale {} at m={m} mp={mp}",
                    r.s[i]
                );
            }
        }
    }
}
