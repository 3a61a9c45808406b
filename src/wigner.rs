//! Wigner-d generation: recurrence coefficients and overflow/underflow-free starting values.
//!
//! The DWT kernels (`dwt.rs`) run the three-term recurrence in `l` for the normalised
//! `dt^l = sqrt((2l+1)/2) d^l` of a base pair `(m, m')`, `m >= m' >= 0`:
//!
//! `dt^{l+1} = (A_l cos(beta) + C_l) dt^l - Bc_l dt^{l-1}`, starting at `l0 = m` with
//! `dt^{m}_{m,m'} = (-1)^(m-m') sqrt((2m+1)/2) sqrt(binom(2m, m-m')) cos(beta/2)^(m+m') sin(beta/2)^(m-m')`.
//!
//! The starting value over- and underflows doubles for large orders, so it is built in an
//! extended format (mantissa, integer power of two) and handed to the kernels as a scaled
//! value `p` with a scale index `sc <= 0`: the true value is `p * 2^(SCALE_STEP * sc)`.
//! A lane whose `sc < 0` is below the skip threshold `2^-bits` and contributes nothing; the
//! kernels rescale it by `2^-SCALE_STEP` whenever it grows past `big(bits)` until it reaches `sc = 0`,
//! after which the recurrence continues in plain doubles.

use crate::simd::Isa;

/// Exponent step of one rescaling.
pub(crate) const SCALE_STEP: i64 = 600;
/// Default skip threshold: lanes whose true value is below `2^-DEFAULT_SKIP_BITS` are
/// treated as zero (see `PlanOptions::skip_bits`).
pub(crate) const DEFAULT_SKIP_BITS: u32 = 64;
/// Accepted range of skip thresholds (`2^-bits`): the scaled values stay normal doubles.
pub(crate) const SKIP_BITS_RANGE: std::ops::RangeInclusive<u32> = 24..=560;

/// Rescale threshold of the scaled values for skip threshold `2^-bits`: `2^(SCALE_STEP - bits)`.
pub(crate) fn big(bits: u32) -> f64 {
    ldexp(1.0, SCALE_STEP - bits as i64)
}
/// Rescaling factor `2^-SCALE_STEP`.
pub(crate) const TINY: f64 = f64::from_bits(((1023 - SCALE_STEP) as u64) << 52);

/// A number `mant * 2^exp` with `mant` in `[0.5, 1)` (or zero): no overflow, no underflow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ext {
    pub mant: f64,
    pub exp: i64,
}

/// `x = m * 2^e` with `m` in `[0.5, 1)`; `(0, 0)` for zero. `x` must be finite.
#[inline]
fn frexp(x: f64) -> (f64, i64) {
    if x == 0.0 {
        return (0.0, 0);
    }
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64;
    if e == 0 {
        // Subnormal: scale up first.
        let (m, e2) = frexp(x * f64::from_bits((1023 + 64) << 52));
        return (m, e2 - 64);
    }
    let m = f64::from_bits((bits & !(0x7ffu64 << 52)) | (1022u64 << 52));
    (m, e - 1022)
}

/// `x * 2^n` for any `n` (results outside the double range saturate as IEEE does).
#[inline]
pub(crate) fn ldexp(mut x: f64, mut n: i64) -> f64 {
    while n > 1000 {
        x *= f64::from_bits((1023 + 1000) << 52);
        n -= 1000;
    }
    while n < -1000 {
        x *= f64::from_bits((1023 - 1000) << 52);
        n += 1000;
    }
    x * f64::from_bits(((1023 + n) as u64) << 52)
}

impl Ext {
    pub const ONE: Ext = Ext { mant: 0.5, exp: 1 };

    /// The kernels' scaled form `(p, sc)` for skip threshold `2^-bits`: true value
    /// `= p * 2^(SCALE_STEP * sc)`, `sc = 0` if the value is at least `2^-bits`, else `p` in
    /// `[2^(-bits-1), big(bits))`.
    #[inline]
    pub fn to_scaled(self, bits: u32) -> (f64, f64) {
        let active_bits = bits as i64;
        if self.mant == 0.0 {
            return (0.0, 0.0);
        }
        let e = self.exp; // |value| in [2^(e-1), 2^e)
        if e > -active_bits {
            return (ldexp(self.mant, e), 0.0);
        }
        let j = (-active_bits - e + SCALE_STEP) / SCALE_STEP; // ceil((-T - e)/S) for -T-e >= 0, >= 1
        (ldexp(self.mant, e + SCALE_STEP * j), -(j as f64))
    }
}

/// `sqrt((2m+1)/2 * binom(2m, m-m'))` for every `0 <= m' <= m < b`, index `m(m+1)/2 + m'`,
/// each the nearest double (times a power of two): the binomials are built in
/// double-double arithmetic, whose rounding errors over the `m` steps stay far below one
/// double ulp.
pub(crate) fn start_norms(b: usize) -> Vec<Ext> {
    let mut out = vec![Ext::ONE; b * (b + 1) / 2];
    for m in 0..b {
        let mut bin = Xd::ONE;
        for j in 0..=m {
            if j > 0 {
                bin = binom_step(bin, m, j);
            }
            out[m * (m + 1) / 2 + m - j] = norm_from_binom(bin, m);
        }
    }
    out
}

/// One entry of [`start_norms`]: `sqrt((2m+1)/2 * binom(2m, m-m'))` for `m' <= m`.
pub(crate) fn start_norm(m: usize, mp: usize) -> Ext {
    assert!(mp <= m);
    let bin = (1..=m - mp).fold(Xd::ONE, |bin, j| binom_step(bin, m, j));
    norm_from_binom(bin, m)
}

/// `binom(2m, j)` from `binom(2m, j - 1)`: times `(2m - j + 1) / j`.
fn binom_step(bin: Xd, m: usize, j: usize) -> Xd {
    Xd::from_dd(bin.m.mul_f((2 * m - j + 1) as f64).div(Dd::new(j as f64))).shift(bin.e)
}

/// `sqrt((2m+1)/2 * bin)`, rounded once.
fn norm_from_binom(bin: Xd, m: usize) -> Ext {
    Xd::from_dd(bin.m.mul_f((2 * m + 1) as f64))
        .shift(bin.e - 1)
        .sqrt()
        .to_ext()
}

/// A double-double mantissa with an extended exponent, `(m.hi + m.lo) 2^e`, `m.hi` in
/// `[0.5, 1)` (or zero): products of hundreds of factors without overflow and with
/// rounding errors far below one double ulp.
#[derive(Clone, Copy, Debug)]
struct Xd {
    m: Dd,
    e: i64,
}

impl Xd {
    const ONE: Xd = Xd {
        m: Dd { hi: 0.5, lo: 0.0 },
        e: 1,
    };

    fn from_dd(d: Dd) -> Xd {
        let (hi, e) = frexp(d.hi);
        Xd {
            m: Dd {
                hi,
                lo: ldexp(d.lo, -e),
            },
            e,
        }
    }

    /// Times `2^k`.
    fn shift(self, k: i64) -> Xd {
        Xd {
            m: self.m,
            e: self.e + k,
        }
    }

    fn mul(self, o: Xd) -> Xd {
        Xd::from_dd(self.m.mul(o.m)).shift(self.e + o.e)
    }

    fn sqrt(self) -> Xd {
        // An even exponent: sqrt(m 2^(2k)) = sqrt(m) 2^k.
        let (m, e) = if self.e % 2 == 0 {
            (self.m, self.e)
        } else {
            (self.m.mul_f(2.0), self.e - 1)
        };
        Xd::from_dd(m.sqrt()).shift(e / 2)
    }

    /// The nearest double, as an [`Ext`].
    fn to_ext(self) -> Ext {
        let (mant, e) = frexp(self.m.to_f64());
        Ext {
            mant,
            exp: e + self.e,
        }
    }
}

/// `(sin x, cos x)` in double-double for `0 <= x <= pi/2` (Taylor series in `x^2`).
pub(crate) fn sin_cos_dd(x: Dd) -> (Dd, Dd) {
    let x2 = x.mul(x);
    // Horner from the term of x^40 (below 1e-38 of the sum here) down.
    let (mut s, mut c) = (Dd::new(1.0), Dd::new(1.0));
    for n in (1..=20).rev() {
        let k = (2 * n) as f64;
        s = Dd::new(1.0).sub(x2.mul(s).div(Dd::new(k * (k + 1.0))));
        c = Dd::new(1.0).sub(x2.mul(c).div(Dd::new((k - 1.0) * k)));
    }
    (x.mul(s), c)
}

/// `pi` in double-double.
pub(crate) const PI_DD: Dd = Dd {
    hi: std::f64::consts::PI,
    lo: 1.2246467991473532e-16,
};

/// Powers `base^a`, `0 <= a <= maxpow`, for a list of bases, stored in two levels
/// (`a mod 64` and `64 * (a div 64)`) so one power costs one multiplication. Mantissas
/// and exponents are kept in separate arrays (exponents as exact small integers in `f64`),
/// with the bases contiguous, so that the starting values of consecutive betas load as
/// vectors.
pub(crate) struct PowTable {
    nb: usize,
    lo_m: Vec<f64>,
    lo_e: Vec<f64>,
    hi_m: Vec<f64>,
    hi_e: Vec<f64>,
}

impl PowTable {
    /// Tables for the given bases (in double-double): every power is built in
    /// double-double arithmetic and rounded once, so that its error does not grow with the
    /// exponent (rounding the base alone to a double would give `base^a` a relative error
    /// of up to `a/2` ulps).
    fn new(bases: &[Dd], maxpow: usize) -> PowTable {
        let nb = bases.len();
        let nhi = maxpow / 64 + 1;
        let mut lo = vec![Ext::ONE; 64 * nb];
        let mut hi = vec![Ext::ONE; nhi * nb];
        for (k, &c) in bases.iter().enumerate() {
            let ce = Xd::from_dd(c);
            let mut p = Xd::ONE;
            for j in 1..64 {
                p = p.mul(ce);
                lo[j * nb + k] = p.to_ext();
            }
            let c64 = p.mul(ce);
            let mut p = Xd::ONE;
            for j in 1..nhi {
                p = p.mul(c64);
                hi[j * nb + k] = p.to_ext();
            }
        }
        PowTable {
            nb,
            lo_m: lo.iter().map(|x| x.mant).collect(),
            lo_e: lo.iter().map(|x| x.exp as f64).collect(),
            hi_m: hi.iter().map(|x| x.mant).collect(),
            hi_e: hi.iter().map(|x| x.exp as f64).collect(),
        }
    }

    /// Mantissas and exponents of `base_k^a` from `k = k0` on: low level, then high level.
    fn rows(&self, a: usize, k0: usize) -> [&[f64]; 4] {
        let (l, h) = ((a % 64) * self.nb + k0, (a / 64) * self.nb + k0);
        [
            &self.lo_m[l..],
            &self.lo_e[l..],
            &self.hi_m[h..],
            &self.hi_e[h..],
        ]
    }
}

/// Per-beta tables: the recurrence argument and powers of `cos(beta/2)`, `sin(beta/2)`.
///
/// The recurrence never sees `cos(beta)` itself: near the poles a rounded `cos(beta)` is a
/// systematic shift of beta, which moves `d^l` by up to `l^2 eps`. Instead each point keeps
/// `tau_lo = 1 - cos(beta) = 2 sin^2(beta/2)` and `tau_hi = 1 + cos(beta) = 2 cos^2(beta/2)`,
/// both accurate to a few ulps, and the kernels use the one that is small (see `dwt.rs`).
pub(crate) struct BetaTables {
    /// `2 sin^2(beta/2)`
    pub tau_lo: Vec<f64>,
    /// `2 cos^2(beta/2)`
    pub tau_hi: Vec<f64>,
    cpow: PowTable,
    spow: PowTable,
}

impl BetaTables {
    /// Tables for points given as `(cos(beta/2), sin(beta/2))` in double-double, powers up
    /// to `maxpow`. Each table value is the double nearest to its exact value.
    fn new(points: &[(Dd, Dd)], maxpow: usize) -> BetaTables {
        let c: Vec<Dd> = points.iter().map(|p| p.0).collect();
        let s: Vec<Dd> = points.iter().map(|p| p.1).collect();
        let tau = |x: &Dd| x.mul(*x).mul_f(2.0).to_f64();
        BetaTables {
            tau_lo: s.iter().map(tau).collect(),
            tau_hi: c.iter().map(tau).collect(),
            cpow: PowTable::new(&c, maxpow),
            spow: PowTable::new(&s, maxpow),
        }
    }

    /// Tables for the `2B` grid betas of bandwidth `b`: `beta_k / 2 = pi (2k+1) / (8B)`,
    /// its cosine and sine in double-double.
    pub fn grid(b: usize) -> BetaTables {
        let pts: Vec<(Dd, Dd)> = (0..2 * b)
            .map(|k| {
                let x = PI_DD.mul_f((2 * k + 1) as f64).div(Dd::new((8 * b) as f64));
                let (s, c) = sin_cos_dd(x);
                (c, s)
            })
            .collect();
        BetaTables::new(&pts, 2 * b)
    }

    /// Whether point `k` lies in the upper half (`beta > pi/2`), where the kernels use `tau_hi`.
    pub fn upper(&self, k: usize) -> bool {
        self.tau_hi[k] < self.tau_lo[k]
    }

    /// Scaled starting value `weight * dt^m_{m,m'}` at point `k`, given `norm` from
    /// [`start_norms`]. (A per-lane weight scales every degree of the recurrence alike.)
    #[inline]
    pub fn start(
        &self,
        k: usize,
        m: usize,
        mp: usize,
        norm: Ext,
        weight: f64,
        bits: u32,
    ) -> (f64, f64) {
        let (a, b) = (m + mp, m - mp);
        let [c1m, c1e, c2m, c2e] = self.cpow.rows(a, k);
        let [s1m, s1e, s2m, s2e] = self.spow.rows(b, k);
        // Five mantissas in [0.5, 1) and a weight: no intermediate renormalisation needed.
        let (mant, e) = frexp(norm.mant * c1m[0] * c2m[0] * s1m[0] * s2m[0] * weight);
        let v = Ext {
            mant: if b % 2 == 1 { -mant } else { mant },
            exp: e + norm.exp + (c1e[0] + c2e[0] + s1e[0] + s2e[0]) as i64,
        };
        v.to_scaled(bits)
    }

    /// [`BetaTables::start`] (weight 1) for the consecutive points `k0 .. k0 + p.len()`,
    /// into `p` and `sc`: with AVX-512 eight points at a time (`getexp`, `getmant` and
    /// `scalef` do the exponent arithmetic exactly), else one at a time. Both give the same
    /// bits.
    #[allow(clippy::too_many_arguments)]
    pub fn starts(
        &self,
        isa: Isa,
        k0: usize,
        m: usize,
        mp: usize,
        norm: Ext,
        bits: u32,
        p: &mut [f64],
        sc: &mut [f64],
    ) {
        let len = p.len();
        assert!(sc.len() == len && k0 + len <= self.tau_lo.len());
        #[cfg(target_arch = "x86_64")]
        if isa == Isa::Avx512 && isa.is_supported() {
            let (a, b) = (m + mp, m - mp);
            let c = self.cpow.rows(a, k0);
            let s = self.spow.rows(b, k0);
            // SAFETY: AVX-512F checked; every row has at least `len` entries from k0 on
            // (k0 + len <= number of points), as do `p` and `sc`.
            unsafe { starts_avx512(c, s, norm, b % 2 == 1, bits, p, sc) };
            return;
        }
        let _ = isa;
        for (i, (p, sc)) in p.iter_mut().zip(sc.iter_mut()).enumerate() {
            (*p, *sc) = self.start(k0 + i, m, mp, norm, 1.0, bits);
        }
    }
}

/// Eight starting values at a time, with the arithmetic of [`BetaTables::start`] and
/// [`Ext::to_scaled`]: the product of the five mantissas is split by `getexp`/`getmant`
/// into `frexp` form, and the scaled value is built by `scalef` (an exact power-of-two
/// scaling) with the scale index `j = floor((S - bits - e) / S)` where the value is below
/// `2^-bits`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn starts_avx512(
    c: [&[f64]; 4],
    s: [&[f64]; 4],
    norm: Ext,
    negative: bool,
    bits: u32,
    p: &mut [f64],
    sc: &mut [f64],
) {
    use std::arch::x86_64::*;
    let len = p.len();
    let nm = _mm512_set1_pd(norm.mant);
    let ne = _mm512_set1_pd(norm.exp as f64);
    let neg_t = _mm512_set1_pd(-(bits as f64));
    let step = _mm512_set1_pd(SCALE_STEP as f64);
    let inv_step = _mm512_set1_pd(1.0 / SCALE_STEP as f64);
    let zero = _mm512_setzero_pd();
    let one = _mm512_set1_pd(1.0);
    let sign = _mm512_set1_pd(if negative { -1.0 } else { 1.0 });
    let mut i = 0;
    while i < len {
        let mask: __mmask8 = if len - i >= 8 {
            0xff
        } else {
            (1u8 << (len - i)) - 1
        };
        let ld = |a: &[f64]| _mm512_maskz_loadu_pd(mask, a.as_ptr().add(i));
        // Same order of multiplication as the scalar code (its weight is 1 here).
        let mut mant = _mm512_mul_pd(nm, ld(c[0]));
        mant = _mm512_mul_pd(mant, ld(c[2]));
        mant = _mm512_mul_pd(mant, ld(s[0]));
        mant = _mm512_mul_pd(mant, ld(s[2]));
        let exps = _mm512_add_pd(
            _mm512_add_pd(
                _mm512_add_pd(ld(c[1]), ld(c[3])),
                _mm512_add_pd(ld(s[1]), ld(s[3])),
            ),
            ne,
        );
        let nonzero = _mm512_cmp_pd_mask::<_CMP_NEQ_OQ>(mant, zero);
        // frexp: mant = fm * 2^(E + 1), fm in [0.5, 1).
        let big_e = _mm512_getexp_pd(mant);
        let fm = _mm512_getmant_pd::<_MM_MANT_NORM_P5_1, _MM_MANT_SIGN_SRC>(mant);
        let e = _mm512_add_pd(_mm512_add_pd(exps, big_e), one);
        // Below the threshold (e <= -bits): j = floor((S - bits - e) / S) >= 1, else 0.
        let low = _mm512_cmp_pd_mask::<_CMP_LE_OQ>(e, neg_t);
        let q = _mm512_mul_pd(_mm512_add_pd(_mm512_sub_pd(neg_t, e), step), inv_step);
        let j = _mm512_maskz_roundscale_pd::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(low, q);
        let pv = _mm512_scalef_pd(fm, _mm512_fmadd_pd(j, step, e));
        let pv = _mm512_maskz_mul_pd(nonzero, pv, sign);
        let scv = _mm512_maskz_sub_pd(nonzero, zero, j);
        _mm512_mask_storeu_pd(p.as_mut_ptr().add(i), mask, pv);
        _mm512_mask_storeu_pd(sc.as_mut_ptr().add(i), mask, scv);
        i += 8;
    }
}

/// Tables from which the recurrence coefficients of any base pair follow by a few
/// double-double multiplications per degree (no square root per cluster), so that every
/// coefficient the kernels use is the double nearest to its exact value (to within a few
/// units in the 30th decimal place). At B = 256 the coefficients of all clusters take
/// about 8 ms per chunk (`coeffs_speed` test; 5 ms for the earlier products of rounded
/// values): about 4% of the forward's DWT stage with its 5 chunks, less for the inverse,
/// which computes them once per group of chunks.
///
/// Correct rounding matters: with the coefficients formed by products of rounded table
/// values (3-5 roundings each), the mean maximum round-trip error over 40 seeds was 74%
/// larger at B = 64 (2.66e-14 against 1.53e-14) and the relative L2 error 17% larger.
pub(crate) struct RecTables {
    stride: usize,
    /// `sqrt((l+1) sqrt((2l+3)(2l+1)) / ((l+1)^2 - m^2))` at `[m * stride + l]` (`l >= m`):
    /// `A_l = ga[m][l] ga[m'][l]`.
    ga: DdVec,
    /// `sqrt(sqrt((2l+3)/(2l-1)) (l+1)/l (l^2 - m^2) / ((l+1)^2 - m^2))` (`l >= m`, 0 at
    /// `l = 0`): `Bc_l = gb[m][l] gb[m'][l]`.
    gb: DdVec,
    /// `1 / (l(l+1))` (0 at `l = 0`).
    k3: DdVec,
    /// `l(l+1)` (a table, so that the coefficient loop converts no integers and vectorises).
    ll: Vec<f64>,
    /// Row of order `m` in `ga` and `gb` (`usize::MAX`: not tabulated).
    row: Vec<usize>,
    /// x86-64 with FMA and AVX2: the coefficients are computed in a function compiled for
    /// them (the double-double products need fused multiply-adds; without the feature
    /// `f64::mul_add` is a library call there, equally exact but slow).
    fma: bool,
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
        let fma = fma_available();
        #[cfg(target_arch = "x86_64")]
        if fma {
            // SAFETY: FMA and AVX2 are available.
            return unsafe { Self::new_fma(lmax, orders) };
        }
        Self::new_body(lmax, orders, fma)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn new_fma(lmax: usize, orders: &[usize]) -> RecTables {
        Self::new_body(lmax, orders, true)
    }

    #[inline(always)]
    fn new_body(lmax: usize, orders: &[usize], fma: bool) -> RecTables {
        let stride = lmax + 2;
        let mut row = vec![usize::MAX; lmax + 1];
        let mut ms = Vec::new();
        for &m in orders {
            assert!(m <= lmax, "order {m} above lmax {lmax}");
            if row[m] == usize::MAX {
                row[m] = ms.len();
                ms.push(m);
            }
        }
        // `l^2 - m^2` and `(l+1)^2 - m^2` are exact integers in a double (l < 2^26).
        let sq = |k: usize| (k * k) as f64;
        let k1 = |l: usize| {
            let l = l as f64;
            Dd::prod(2.0 * l + 3.0, 2.0 * l + 1.0).sqrt().mul_f(l + 1.0)
        };
        let k2 = |l: usize| {
            let l = l as f64;
            Dd::new(2.0 * l + 3.0)
                .div(Dd::new(2.0 * l - 1.0))
                .sqrt()
                .mul_f(l + 1.0)
                .div(Dd::new(l))
        };
        let ga = DdVec::from_fn(ms.len() * stride, |k| {
            let (m, l) = (ms[k / stride], k % stride);
            if l >= m && l <= lmax {
                k1(l).div(Dd::new(sq(l + 1) - sq(m))).sqrt()
            } else {
                Dd::new(0.0)
            }
        });
        let gb = DdVec::from_fn(ms.len() * stride, |k| {
            let (m, l) = (ms[k / stride], k % stride);
            if l >= m && l <= lmax && l > 0 {
                k2(l)
                    .mul_f(sq(l) - sq(m))
                    .div(Dd::new(sq(l + 1) - sq(m)))
                    .sqrt()
            } else {
                Dd::new(0.0)
            }
        });
        let k3 = DdVec::from_fn(lmax + 1, |l| {
            let l = l as f64;
            if l == 0.0 {
                Dd::new(0.0)
            } else {
                Dd::new(1.0).div(Dd::new(l * (l + 1.0)))
            }
        });
        RecTables {
            stride,
            ga,
            gb,
            k3,
            ll: (0..=lmax).map(|l| (l * (l + 1)) as f64).collect(),
            row,
            fma,
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
            self.row[m] != usize::MAX && self.row[mp] != usize::MAX,
            "orders ({m}, {mp}) not tabulated"
        );
        #[cfg(target_arch = "x86_64")]
        if self.fma {
            // SAFETY: `new` found FMA and AVX2.
            return unsafe { self.coeffs_fma(m, mp, r) };
        }
        self.coeffs_body(m, mp, r)
    }

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
        let st = self.stride;
        let mm = (m * mp) as f64;
        // Table runs for `l = m .. m + n`, as slices of length `n` so that the loops below
        // have no bounds checks and vectorise.
        let (k3h, k3l) = self.k3.run(m, n);
        let (rm, rp) = (self.row[m] * st, self.row[mp] * st);
        let (amh, aml) = self.ga.run(rm + m, n);
        let (aph, apl) = self.ga.run(rp + m, n);
        let (bmh, bml) = self.gb.run(rm + m, n);
        let (bph, bpl) = self.gb.run(rp + m, n);
        let llv = &self.ll[m..m + n];
        let dd = |h: &[f64], l: &[f64], i: usize| Dd { hi: h[i], lo: l[i] };
        // `Bc` rounded (into `r.e` for now), then the scales `S_i`.
        let bc = &mut r.e[..n];
        for (i, b) in bc.iter_mut().enumerate() {
            *b = dd(bmh, bml, i).mul(dd(bph, bpl, i)).to_f64();
        }
        let sc = &mut r.s[..n];
        let (mut s0, mut s1) = (1.0, 1.0);
        for i in 0..n {
            sc[i] = s1;
            // `S_{i+1}`: `S_1 = 1` (the step from `i = 0` has no `dt^{l-1}` term).
            let s2 = if i == 0 { 1.0 } else { bc[i] * s0 };
            (s0, s1) = (s1, s2);
        }
        let (ra, ran, rd, re) = (&mut r.a[..n], &mut r.an[..n], &mut r.d[..n], &mut r.e[..n]);
        let sc = &r.s[..n];
        // Written out twice (a closure would not be inlined into this `target_feature`
        // function, and would then neither vectorise nor use FMA instructions).
        macro_rules! coeff {
            ($i:expr, $s_next:expr) => {{
                let i = $i;
                // `A' = A S_i / S_{i+1}`.
                let f = Dd::quot(sc[i], $s_next);
                let a = dd(amh, aml, i).mul(dd(aph, apl, i)).mul(f);
                // `A + C = A (ll - mm) / ll`, `C - A = -A (ll + mm) / ll`: exact integers
                // times `1 / ll`, no cancellation.
                let ll = llv[i];
                let d = a.mul(dd(k3h, k3l, i).mul_f(ll - mm));
                ra[i] = a.to_f64();
                ran[i] = -ra[i];
                rd[i] = d.to_f64();
                re[i] = -a.mul(dd(k3h, k3l, i).mul_f(ll + mm)).to_f64();
            }};
        }
        for i in 0..n - 1 {
            coeff!(i, sc[i + 1]);
        }
        // The last degree's coefficient is never used (it would step to degree `m + n`),
        // so any scale does there.
        coeff!(n - 1, sc[n - 1]);
        if m == 0 {
            // `l = 0`: `C = 0` (`1 / ll` is stored as 0).
            (rd[0], re[0]) = (ra[0], -ra[0]);
        }
    }
}

/// Double-double number `hi + lo` (`|lo| <= ulp(hi) / 2`): about 106 bits, enough to
/// round the recurrence coefficients to the nearest double.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dd {
    pub hi: f64,
    pub lo: f64,
}

impl Dd {
    #[inline(always)]
    pub fn new(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    /// `hi + lo` renormalised (`|hi| >= |lo|`).
    #[inline(always)]
    fn fast_sum(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd {
            hi: s,
            lo: lo - (s - hi),
        }
    }

    /// The exact product of two doubles.
    #[inline(always)]
    fn prod(a: f64, b: f64) -> Dd {
        let p = a * b;
        Dd {
            hi: p,
            lo: a.mul_add(b, -p),
        }
    }

    /// `a / b` of two doubles (the remainder `a - q b` is exact).
    #[inline(always)]
    fn quot(a: f64, b: f64) -> Dd {
        let q = a / b;
        let rem = (-q).mul_add(b, a);
        Dd::fast_sum(q, rem / b)
    }

    #[inline(always)]
    pub fn mul_f(self, b: f64) -> Dd {
        let p = Dd::prod(self.hi, b);
        Dd::fast_sum(p.hi, self.lo.mul_add(b, p.lo))
    }

    #[inline(always)]
    pub fn mul(self, b: Dd) -> Dd {
        let p = Dd::prod(self.hi, b.hi);
        Dd::fast_sum(p.hi, self.hi.mul_add(b.lo, self.lo.mul_add(b.hi, p.lo)))
    }

    /// `-self`.
    pub fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    /// `self + b` (two-sum of the high parts, so any order of the magnitudes; where the
    /// high parts cancel, the result keeps the absolute, not the relative, accuracy).
    pub fn add_dd(self, b: Dd) -> Dd {
        self.sub(b.neg())
    }

    /// `self - b` (as [`Dd::add_dd`]).
    #[inline(always)]
    pub fn sub(self, b: Dd) -> Dd {
        let s = self.hi - b.hi;
        let bb = s - self.hi;
        let err = (self.hi - (s - bb)) - (b.hi + bb);
        Dd::fast_sum(s, err + (self.lo - b.lo))
    }

    #[inline(always)]
    pub fn div(self, b: Dd) -> Dd {
        let q1 = self.hi / b.hi;
        // The remainder `self - q1 b`; its high part cancels exactly.
        let p = b.mul_f(q1);
        let rem = (self.hi - p.hi) - p.lo + self.lo;
        Dd::fast_sum(q1, rem / b.hi)
    }

    #[inline(always)]
    fn sqrt(self) -> Dd {
        if self.hi <= 0.0 {
            return Dd::new(0.0);
        }
        let x = self.hi.sqrt();
        let p = Dd::prod(x, x);
        let rem = (self.hi - p.hi) - p.lo + self.lo;
        Dd::fast_sum(x, rem / (2.0 * x))
    }

    /// The nearest double.
    #[inline(always)]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
}

/// Zero entries after the last degree of every [`RecCoeffs`] array: the forward kernel
/// runs its last block of degrees in full (see `dwt::forward`), stepping up to
/// `REC_PAD - 1` degrees past the end.
pub(crate) const REC_PAD: usize = 8;

/// Recurrence coefficients of one cluster (see [`RecTables::coeffs`]), index `i = l - l0`,
/// for `len()` degrees; each array holds [`REC_PAD`] zeros after them.
#[derive(Default)]
pub(crate) struct RecCoeffs {
    pub a: Vec<f64>,
    pub an: Vec<f64>,
    pub d: Vec<f64>,
    pub e: Vec<f64>,
    /// The scale `S_i` of the values (see [`RecTables::coeffs`]).
    pub s: Vec<f64>,
    n: usize,
}

impl RecCoeffs {
    /// Arrays for `n` degrees.
    pub fn new(n: usize) -> RecCoeffs {
        let mut r = RecCoeffs::default();
        r.resize(n);
        r
    }

    /// Number of degrees.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Shorten (or lengthen) every array to `n` degrees (and the zero padding).
    pub fn resize(&mut self, n: usize) {
        for v in [
            &mut self.a,
            &mut self.an,
            &mut self.d,
            &mut self.e,
            &mut self.s,
        ] {
            v.resize(n + REC_PAD, 0.0);
            v[n..].fill(0.0);
        }
        self.n = n;
    }
}

/// `d^l_{m,mp}(beta)` (standard, not normalised) for `l = max(|m|,|mp|) ..= lmax`.
///
/// Computed by the same starting values, recurrence and forward DWT kernel as the
/// transforms (with the best instruction set of this CPU), so it doubles as a test of them.
pub fn wigner_d_column(m: isize, mp: isize, lmax: usize, beta: f64) -> Vec<f64> {
    wigner_d_column_isa(Isa::detect(), m, mp, lmax, beta)
}

pub(crate) fn wigner_d_column_isa(
    isa: Isa,
    m: isize,
    mp: isize,
    lmax: usize,
    beta: f64,
) -> Vec<f64> {
    let (bm, bmp, mem) = crate::symmetry::locate(m, mp);
    if lmax < bm {
        return Vec::new();
    }
    // pi - beta for reversed members, without rounding: swap the half-angle cos and sin.
    // (`beta / 2` is exact; outside [0, pi] the half-angle functions take their signs.)
    let (s, c) = if (0.0..=std::f64::consts::PI).contains(&beta) {
        sin_cos_dd(Dd::new(beta / 2.0))
    } else {
        (Dd::new((beta / 2.0).sin()), Dd::new((beta / 2.0).cos()))
    };
    let pt = if mem.reversed { (s, c) } else { (c, s) };
    let bt = BetaTables::new(&[pt], 2 * bm);
    let norm = start_norm(bm, bmp);
    let rt = RecTables::for_orders(lmax + 1, &[bm, bmp]);
    let col = crate::dwt::column(isa, &bt, &rt, 0, bm, bmp, norm, lmax + 1);
    col.iter()
        .enumerate()
        .map(|(i, v)| {
            let l = bm + i;
            mem.sign_at(l) * v / ((2 * l + 1) as f64 / 2.0).sqrt()
        })
        .collect()
}

/// Normalised `dt^l_{m,mp}(beta_k)` on the bandwidth-`b` grid: rows `l = max(|m|,|mp|)..b`,
/// each of `2b` values (`k = 0..2b`), row-major. Same code path as the DWT.
pub fn dt_on_grid(b: usize, m: isize, mp: isize) -> Vec<f64> {
    let (bm, bmp, mem) = crate::symmetry::locate(m, mp);
    assert!(bm < b, "order ({m},{mp}) out of range for bandwidth {b}");
    let n = 2 * b;
    let bt = BetaTables::grid(b);
    let norm = start_norm(bm, bmp);
    let rt = RecTables::new(b);
    let isa = Isa::detect();
    let rows = b - bm;
    let mut out = vec![0.0; rows * n];
    for k in 0..n {
        let src = if mem.reversed { n - 1 - k } else { k };
        let col = crate::dwt::column(isa, &bt, &rt, src, bm, bmp, norm, b);
        for (i, v) in col.iter().enumerate() {
            out[i * n + k] = mem.sign_at(bm + i) * v;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `x > 0` is `sqrt(n / d)` rounded to the nearest double (within half an ulp
    /// of `x`, in exact integer arithmetic), or `None` where 128 bits do not suffice.
    fn is_rounded_sqrt(x: f64, n: u128, d: u128) -> Option<bool> {
        let bits = x.to_bits();
        let e = ((bits >> 52) & 0x7ff) as i64 - 1075;
        let m = ((bits & ((1 << 52) - 1)) | (1 << 52)) as u128;
        // x + ulp/2 = (2m + 1) 2^(e-1); squared, times 2^k with k = 2 - 2e. Below a power
        // of two the gap to the next double is half as large: x - ulp/4 = (4m - 1) 2^(e-2).
        let k = u32::try_from(2 - 2 * e).ok()?;
        let mid = n.checked_mul(1u128.checked_shl(k)?)?;
        let hi = (2 * m + 1).checked_pow(2)?.checked_mul(d)?;
        let lo_ok = if m == 1 << 52 {
            let mid4 = n.checked_mul(1u128.checked_shl(k + 2)?)?;
            (4 * m - 1).checked_pow(2)?.checked_mul(d)? <= mid4
        } else {
            (2 * m - 1).checked_pow(2)?.checked_mul(d)? <= mid
        };
        Some(lo_ok && mid <= hi)
    }

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
                assert_eq!(r.an[0], -r.a[0]);
                if let Some(ok) = is_rounded_sqrt(r.a[0], n, d) {
                    assert!(ok, "A at m={m} mp={mp}: {:e}", r.a[0]);
                    checked[0] += 1;
                }
                let (ll, mm) = (l * (l + 1), m * mp);
                if mm == 0 {
                    assert_eq!((r.d[0], r.e[0]), (r.a[0], -r.a[0]), "m={m} mp={mp}");
                    continue;
                }
                // (A + C)^2 = A^2 ((ll - mm) / ll)^2, (C - A)^2 = A^2 ((ll + mm) / ll)^2.
                let dd = d * ll * ll;
                if let Some(ok) = is_rounded_sqrt(r.d[0], n * (ll - mm) * (ll - mm), dd) {
                    assert!(ok, "A + C at m={m} mp={mp}: {:e}", r.d[0]);
                    checked[1] += 1;
                }
                if let Some(ok) = is_rounded_sqrt(-r.e[0], n * (ll + mm) * (ll + mm), dd) {
                    assert!(ok, "C - A at m={m} mp={mp}: {:e}", r.e[0]);
                    checked[2] += 1;
                }
            }
        }
        assert!(
            checked.iter().all(|&c| c >= 20),
            "too few exact checks: {checked:?}"
        );
    }

    /// Time of the plan's tables at large bandwidths.
    #[test]
    #[ignore]
    fn table_build_speed() {
        for b in [512usize, 2048] {
            let t = std::time::Instant::now();
            let n = start_norms(b);
            let t1 = t.elapsed().as_secs_f64();
            let bt = BetaTables::grid(b);
            let t2 = t.elapsed().as_secs_f64();
            let rt = RecTables::new(b);
            let t3 = t.elapsed().as_secs_f64();
            let w = crate::grid::weights(b);
            let t4 = t.elapsed().as_secs_f64();
            std::hint::black_box((&n, &bt, &rt, &w));
            println!(
                "B = {b}: start_norms {t1:.3} s, BetaTables {:.3} s, RecTables {:.3} s, \
                 weights {:.3} s",
                t2 - t1,
                t3 - t2,
                t4 - t3
            );
        }
    }

    /// Time of the coefficients of every cluster at B = 256 (one chunk's worth).
    #[test]
    #[ignore]
    fn coeffs_speed() {
        let b = 256;
        let rt = RecTables::new(b);
        let mut r = RecCoeffs::new(b);
        let mut best = f64::MAX;
        for _ in 0..7 {
            let t = std::time::Instant::now();
            for m in 0..b {
                for mp in 0..=m {
                    r.resize(b - m);
                    rt.coeffs(m, mp, &mut r);
                }
            }
            best = best.min(t.elapsed().as_secs_f64());
            std::hint::black_box(&r);
        }
        println!("coeffs for all clusters of B = {b}: {:.2} ms", best * 1e3);
    }

    /// Time of the starting values of every cluster at B = 256, two halves of 51 points
    /// per cluster and chunk, five chunks (what a plan with the default workspace does).
    #[test]
    #[ignore]
    fn starts_speed() {
        let b = 256;
        let bt = BetaTables::grid(b);
        let norm = Ext { mant: 0.5, exp: 0 };
        let h = 51;
        let (mut p, mut sc) = (vec![0.0; h], vec![0.0; h]);
        let (isa, mut best) = (Isa::detect(), f64::MAX);
        for _ in 0..5 {
            let t = std::time::Instant::now();
            for lo in (0..b).step_by(h) {
                let h = h.min(b - lo);
                for m in 0..b {
                    for mp in 0..=m {
                        for k0 in [lo, 2 * b - lo - h] {
                            bt.starts(isa, k0, m, mp, norm, 64, &mut p[..h], &mut sc[..h]);
                        }
                    }
                }
            }
            best = best.min(t.elapsed().as_secs_f64());
            std::hint::black_box(&p);
        }
        println!(
            "starts for all clusters and chunks of B = {b}: {:.2} ms",
            best * 1e3
        );
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
                close(r.d[i] * f, apc, "A + C", i);
                close(r.e[i] * f, cma, "C - A", i);
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

    #[test]
    fn frexp_ldexp_roundtrip() {
        for &x in &[1.0, 0.75, 3e-310, 1e300, -2.5, 5e-324] {
            let (m, e) = frexp(x);
            assert!(m.abs() >= 0.5 && m.abs() < 1.0);
            assert_eq!(ldexp(m, e), x);
        }
    }

    #[test]
    fn extended_double_double_handles_huge_and_tiny() {
        // 2^-3000 * 2^2000 = 2^-1000
        let a = Xd::from_dd(Dd::new(0.5)).shift(-2999);
        let b = Xd::from_dd(Dd::new(0.5)).shift(2001);
        let p = a.mul(b).to_ext();
        assert_eq!(ldexp(p.mant, p.exp), ldexp(1.0, -1000));
        let s = Xd::from_dd(Dd::new(0.5)).shift(3).sqrt().to_ext(); // sqrt(4) = 2
        assert_eq!(ldexp(s.mant, s.exp), 2.0);
        let s = Xd::from_dd(Dd::new(0.5)).shift(4).sqrt().to_ext(); // sqrt(8)
        assert_eq!(ldexp(s.mant, s.exp), 8f64.sqrt());
        let s = Xd::from_dd(Dd::new(0.5)).shift(-2001).sqrt().to_ext(); // sqrt(2^-2002)
        assert_eq!((s.mant, s.exp), (0.5, -1000));
    }

    /// Double-double sine and cosine at angles with known values, to far below a double
    /// ulp.
    #[test]
    fn sin_cos_dd_known_values() {
        let at = |num: f64, den: f64| sin_cos_dd(PI_DD.mul_f(num).div(Dd::new(den)));
        let close = |x: Dd, want: f64| (x.sub(Dd::new(want)).to_f64()).abs() < 1e-30;
        let (s, c) = at(1.0, 6.0);
        assert!(close(s, 0.5) && close(c.mul(c), 0.75), "pi/6: {s:?} {c:?}");
        let (s, c) = at(1.0, 4.0);
        assert!(close(s.mul(s), 0.5) && close(c.mul(c), 0.5), "pi/4");
        let (s, c) = at(1.0, 2.0);
        assert!(close(s, 1.0) && c.to_f64().abs() < 1e-30, "pi/2: {c:?}");
        let (s, c) = at(0.0, 1.0);
        assert!(close(s, 0.0) && close(c, 1.0));
        for k in 0..50 {
            let (s, c) = at((2 * k + 1) as f64, 200.0);
            assert!(close(s.mul(s).add_dd(c.mul(c)), 1.0), "k={k}");
        }
    }

    /// Power tables at `beta = pi/2`, where `cos(beta/2) = sin(beta/2) = sqrt(2)/2`: even
    /// powers are exact powers of two and odd ones `sqrt(2)/2` (rounded once) times a
    /// power of two, however high the exponent. Powers of the base rounded to a double,
    /// or products that drop the low parts, drift by up to `a/2` ulps.
    #[test]
    fn power_tables_are_correctly_rounded() {
        let (s, c) = sin_cos_dd(PI_DD.div(Dd::new(4.0)));
        let maxpow = 1000;
        let bt = BetaTables::new(&[(c, s)], maxpow);
        let half_sqrt2 = std::f64::consts::FRAC_1_SQRT_2;
        for t in [&bt.cpow, &bt.spow] {
            let value = |m: f64, e: f64| ldexp(m, e as i64);
            for a in 0..64usize {
                let want = if a % 2 == 0 {
                    ldexp(1.0, -(a as i64 / 2))
                } else {
                    ldexp(half_sqrt2, -(a as i64 / 2))
                };
                assert_eq!(value(t.lo_m[a], t.lo_e[a]), want, "a={a}");
            }
            for j in 0..=maxpow / 64 {
                let want = ldexp(1.0, -32 * j as i64);
                assert_eq!(value(t.hi_m[j], t.hi_e[j]), want, "a={}", 64 * j);
            }
        }
    }

    /// The starting-value norms are the nearest doubles to their exact values.
    #[test]
    fn start_norms_are_correctly_rounded() {
        let norms = start_norms(31);
        for m in 0..31u128 {
            for mp in 0..=m {
                // norm^2 = (2m+1) binom(2m, m-m') / 2
                let j = m - mp;
                let bin = (1..=j).fold(1u128, |b, i| b * (2 * m - i + 1) / i);
                let e = norms[(m * (m + 1) / 2 + mp) as usize];
                assert_eq!(e, start_norm(m as usize, mp as usize));
                let x = ldexp(e.mant, e.exp);
                let ok = tests::is_rounded_sqrt(x, (2 * m + 1) * bin, 2);
                assert_eq!(ok, Some(true), "m={m} mp={mp}: {x:e}");
            }
        }
    }

    #[test]
    fn scaled_form_is_consistent() {
        for &e in &[0i64, -100, -299, -300, -301, -899, -900, -901, -5000] {
            let x = Ext { mant: 0.75, exp: e };
            let bits = DEFAULT_SKIP_BITS;
            let (p, sc) = x.to_scaled(bits);
            assert!(sc <= 0.0);
            if sc < 0.0 {
                assert!(p.abs() < big(bits) && p.abs() >= ldexp(1.0, -(bits as i64) - 1));
            }
            // reconstruct in extended form
            let (pm, pe) = frexp(p);
            assert_eq!(pm, 0.75);
            assert_eq!(pe + SCALE_STEP * (sc as i64), e);
        }
    }

    /// The vectorised starting values are bitwise those of the scalar code, including
    /// values far below the skip threshold and partial vectors.
    #[test]
    fn vector_starts_match_scalar() {
        for b in [5usize, 37, 300] {
            let bt = BetaTables::grid(b);
            let norms = start_norms(b);
            for &(m, mp) in &[
                (0usize, 0usize),
                (1, 0),
                (4, 4),
                (b - 1, 0),
                (b - 1, b / 3),
                (b / 2, b / 2 - 1),
            ] {
                let norm = norms[m * (m + 1) / 2 + mp];
                for bits in [24u32, 300, 560] {
                    for (k0, len) in [(0usize, 2 * b), (3, b - 1), (b, b)] {
                        let (mut p, mut sc) = (vec![0.0; len], vec![0.0; len]);
                        bt.starts(Isa::detect(), k0, m, mp, norm, bits, &mut p, &mut sc);
                        for i in 0..len {
                            let (p0, sc0) = bt.start(k0 + i, m, mp, norm, 1.0, bits);
                            assert_eq!(
                                (p[i].to_bits(), sc[i]),
                                (p0.to_bits(), sc0),
                                "b={b} m={m} mp={mp} bits={bits} k={}",
                                k0 + i
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn start_norm_small() {
        // m = 2, m' = 0: sqrt(5/2 * binom(4,2)) = sqrt(15)
        let n = start_norms(3);
        let v = n[3];
        assert!((ldexp(v.mant, v.exp) - 15f64.sqrt()).abs() < 1e-14);
    }
}
