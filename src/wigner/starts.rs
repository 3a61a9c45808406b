//! Starting values of the Wigner-d recurrence and the constants of their scaled form.
//!
//! The starting value `dt^m_{m,m'}(beta)` (see the `wigner` module) over- and underflows
//! doubles for large orders, so it is built in an extended format (mantissa, integer power
//! of two) and handed to the kernels as a scaled value `start` with a scale index
//! `scale_index <= 0`: the true value is `start * 2^(SCALE_STEP * scale_index)`. A lane whose
//! `scale_index < 0` is below the skip threshold `2^-bits` and contributes nothing; the
//! kernels rescale it by `2^-SCALE_STEP` whenever it grows past `big(bits)` until it reaches
//! `scale_index = 0`, after which the recurrence continues in plain doubles.
//!
//! The form exists per element type `E` (`crate::real::Elem`): `SCALE_STEP` is
//! `E::SCALE_STEP` (600 for f64, 96 for f32) and `bits` at most `E::MAX_SKIP_BITS`, so that
//! every scaled value stays a normal number of `E`. The f32 form is computed in f64 and
//! rounded once, the scale index being a small integer.

use crate::numeric::{frexp, ldexp, sin_cos_dd, Dd, Ext, ExtDd, PI_DD};
use crate::real::Elem;
use crate::simd::Isa;
use std::any::TypeId;
use std::ops::RangeInclusive;

/// Exponent step of one rescaling of the f64 form (`Elem::SCALE_STEP` of `f64`).
pub(crate) const SCALE_STEP: i64 = <f64 as Elem>::SCALE_STEP;
/// Default skip threshold: lanes whose true value is below `2^-DEFAULT_SKIP_BITS` are
/// treated as zero (see `Options::skip_bits`). Valid for both element types.
pub(crate) const DEFAULT_SKIP_BITS: u32 = 64;
/// Accepted range of skip thresholds (`2^-bits`) of the f64 form: [`skip_bits_range`].
pub(crate) const SKIP_BITS_RANGE: RangeInclusive<u32> = skip_bits_range::<f64>();

/// Accepted range of skip thresholds (`2^-bits`) for element type `E`: the scaled values
/// `[2^(-bits-1), 2^(E::SCALE_STEP - bits))` stay normal numbers of `E`.
pub(crate) const fn skip_bits_range<E: Elem>() -> RangeInclusive<u32> {
    24..=E::MAX_SKIP_BITS
}

/// Rescale threshold of the scaled values for skip threshold `2^-bits`:
/// `2^(E::SCALE_STEP - bits)`.
pub(crate) fn big<E: Elem>(bits: u32) -> E {
    E::from_f64(ldexp(1.0, E::SCALE_STEP - bits as i64))
}

/// Rescaling factor `2^-E::SCALE_STEP` (a normal number of `E`).
pub(crate) fn tiny<E: Elem>() -> E {
    E::from_f64(ldexp(1.0, -E::SCALE_STEP))
}

/// Rescaling factor `2^-SCALE_STEP` of the f64 form ([`tiny`] of `f64`).
pub(crate) const TINY: f64 = f64::from_bits(((1023 - SCALE_STEP) as u64) << 52);

/// `value` in the kernels' scaled form `(start, scale_index)` of element type `E` for skip
/// threshold `2^-bits` (`bits` in [`skip_bits_range`] of `E`): true value
/// `= start * 2^(E::SCALE_STEP * scale_index)`, `scale_index = 0` if the value is at least
/// `2^-bits`, else `start` in `[2^(-bits-1), big(bits)]`. Computed in f64 and rounded
/// once to `E` (for `f32`, a normal number: the rounding is that of the value itself; it
/// may round up to `big(bits)`, which the kernels rescale at the next step).
#[inline]
pub(crate) fn to_scaled<E: Elem>(value: Ext, bits: u32) -> (E, E) {
    debug_assert!(bits <= E::MAX_SKIP_BITS, "skip bits {bits} for {}", E::NAME);
    let step = E::SCALE_STEP;
    let active_bits = bits as i64;
    if value.mant == 0.0 {
        return (E::ZERO, E::ZERO);
    }
    let e = value.exp; // |value| in [2^(e-1), 2^e)
    if e > -active_bits {
        return (E::from_f64(ldexp(value.mant, e)), E::ZERO);
    }
    let j = (-active_bits - e + step) / step; // ceil((-T - e)/S) for -T-e >= 0, >= 1
    (
        E::from_f64(ldexp(value.mant, e + step * j)),
        E::from_f64(-(j as f64)),
    )
}

/// `sqrt((2m+1)/2 * binom(2m, m-m'))` for every `0 <= m' <= m < b`, index `m(m+1)/2 + m'`,
/// each the nearest double (times a power of two): the binomials are built in
/// double-double arithmetic, whose rounding errors over the `m` steps stay far below one
/// double ulp.
pub fn start_norms(b: usize) -> Vec<Ext> {
    let mut out = vec![Ext::ONE; b * (b + 1) / 2];
    for m in 0..b {
        let mut bin = ExtDd::ONE;
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
    let bin = (1..=m - mp).fold(ExtDd::ONE, |bin, j| binom_step(bin, m, j));
    norm_from_binom(bin, m)
}

/// `binom(2m, j)` from `binom(2m, j - 1)`: times `(2m - j + 1) / j`.
fn binom_step(bin: ExtDd, m: usize, j: usize) -> ExtDd {
    ExtDd::from_dd(bin.m.mul_f((2 * m - j + 1) as f64).div(Dd::new(j as f64))).shift(bin.e)
}

/// `sqrt((2m+1)/2 * bin)`, rounded once.
fn norm_from_binom(bin: ExtDd, m: usize) -> Ext {
    ExtDd::from_dd(bin.m.mul_f((2 * m + 1) as f64))
        .shift(bin.e - 1)
        .sqrt()
        .to_ext()
}

/// Powers `base^a`, `0 <= a <= maxpow`, for a list of bases, stored in two levels
/// (`a mod 64` and `64 * (a div 64)`) so one power costs one multiplication. Mantissas
/// and exponents are kept in separate arrays (exponents as exact small integers in `f64`),
/// with the bases contiguous, so that the starting values of consecutive betas load as
/// vectors.
pub(crate) struct PowTable {
    /// Number of bases (the stride between powers).
    bases: usize,
    /// Mantissas of `base^(a mod 64)`, at `(a mod 64) * bases + k`.
    low_mant: Vec<f64>,
    /// Exponents of `base^(a mod 64)`.
    low_exp: Vec<f64>,
    /// Mantissas of `base^(64 (a div 64))`, at `(a div 64) * bases + k`.
    high_mant: Vec<f64>,
    /// Exponents of `base^(64 (a div 64))`.
    high_exp: Vec<f64>,
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
            let base = ExtDd::from_dd(c);
            let mut power = ExtDd::ONE;
            for j in 1..64 {
                power = power.mul(base);
                lo[j * nb + k] = power.to_ext();
            }
            let base64 = power.mul(base);
            let mut power = ExtDd::ONE;
            for j in 1..nhi {
                power = power.mul(base64);
                hi[j * nb + k] = power.to_ext();
            }
        }
        PowTable {
            bases: nb,
            low_mant: lo.iter().map(|x| x.mant).collect(),
            low_exp: lo.iter().map(|x| x.exp as f64).collect(),
            high_mant: hi.iter().map(|x| x.mant).collect(),
            high_exp: hi.iter().map(|x| x.exp as f64).collect(),
        }
    }

    /// Mantissas and exponents of `base_k^a` from `k = k0` on: low level, then high level.
    fn rows(&self, a: usize, k0: usize) -> [&[f64]; 4] {
        let (l, h) = ((a % 64) * self.bases + k0, (a / 64) * self.bases + k0);
        [
            &self.low_mant[l..],
            &self.low_exp[l..],
            &self.high_mant[h..],
            &self.high_exp[h..],
        ]
    }
}

/// What a base pair's starting values need besides the point: the orders, the norm from
/// [`start_norms`] and the skip threshold `2^-skip_bits` of the scaled form.
#[derive(Clone, Copy, Debug)]
pub struct BaseStart {
    /// Base order `m` (`m >= mp`), the starting degree.
    pub m: usize,
    /// Base order `m'`.
    pub mp: usize,
    /// `sqrt((2m+1)/2 * binom(2m, m-m'))` (see [`start_norm`]).
    pub norm: Ext,
    /// Skip threshold exponent (see [`to_scaled`]).
    pub skip_bits: u32,
}

impl BaseStart {
    /// The starting values of `(m, mp)` at skip threshold `2^-skip_bits`.
    pub fn new(m: usize, mp: usize, norm: Ext, skip_bits: u32) -> BaseStart {
        BaseStart {
            m,
            mp,
            norm,
            skip_bits,
        }
    }
}

/// Per-beta tables: the recurrence argument and powers of `cos(beta/2)`, `sin(beta/2)`.
///
/// The recurrence never sees `cos(beta)` itself: near the poles a rounded `cos(beta)` is a
/// systematic shift of beta, which moves `d^l` by up to `l^2 eps`. Instead each point keeps
/// `tau_lo = 1 - cos(beta) = 2 sin^2(beta/2)` and `tau_hi = 1 + cos(beta) = 2 cos^2(beta/2)`,
/// both accurate to a few ulps, and the kernels use the one that is small (see `dwt`).
pub struct BetaTables {
    /// `2 sin^2(beta/2)`
    pub tau_lo: Vec<f64>,
    /// `2 cos^2(beta/2)`
    pub tau_hi: Vec<f64>,
    cos_powers: PowTable,
    sin_powers: PowTable,
}

impl BetaTables {
    /// Tables for points given as `(cos(beta/2), sin(beta/2))` in double-double, powers up
    /// to `maxpow`. Each table value is the double nearest to its exact value.
    pub(crate) fn new(points: &[(Dd, Dd)], maxpow: usize) -> BetaTables {
        let c: Vec<Dd> = points.iter().map(|p| p.0).collect();
        let s: Vec<Dd> = points.iter().map(|p| p.1).collect();
        let tau = |x: &Dd| x.mul(*x).mul_f(2.0).to_f64();
        BetaTables {
            tau_lo: s.iter().map(tau).collect(),
            tau_hi: c.iter().map(tau).collect(),
            cos_powers: PowTable::new(&c, maxpow),
            sin_powers: PowTable::new(&s, maxpow),
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

    /// Scaled starting value `weight * dt^m_{m,m'}` at point `k` in the form of element
    /// type `E` (see [`to_scaled`]). (A per-lane weight scales every degree of the
    /// recurrence alike.)
    #[inline]
    pub fn start<E: Elem>(&self, k: usize, base: &BaseStart, weight: f64) -> (E, E) {
        let (a, b) = (base.m + base.mp, base.m - base.mp);
        let [c1m, c1e, c2m, c2e] = self.cos_powers.rows(a, k);
        let [s1m, s1e, s2m, s2e] = self.sin_powers.rows(b, k);
        // Five mantissas in [0.5, 1) and a weight: no intermediate renormalisation needed.
        let (mant, e) = frexp(base.norm.mant * c1m[0] * c2m[0] * s1m[0] * s2m[0] * weight);
        let v = Ext {
            mant: if b % 2 == 1 { -mant } else { mant },
            exp: e + base.norm.exp + (c1e[0] + c2e[0] + s1e[0] + s2e[0]) as i64,
        };
        to_scaled(v, base.skip_bits)
    }

    /// [`BetaTables::start`] (weight 1, base pair `(m, mp)` with `norm`, skip threshold
    /// `2^-bits`, `bits` at most `E::MAX_SKIP_BITS`) for the consecutive points
    /// `k0 .. k0 + values.len()`, into `values` and `scale_indices`: with AVX-512 eight
    /// points at a time (`getexp`, `getmant` and `scalef` do the exponent arithmetic
    /// exactly), with AVX2 four at a time (the same on the bits of the doubles), else one at
    /// a time. The vector paths compute in f64 lanes and round to `E` once, as the scalar
    /// one does. All give the same bits.
    #[allow(clippy::too_many_arguments)]
    pub fn starts<E: Elem>(
        &self,
        isa: Isa,
        k0: usize,
        m: usize,
        mp: usize,
        norm: Ext,
        bits: u32,
        values: &mut [E],
        scale_indices: &mut [E],
    ) {
        let base = &BaseStart::new(m, mp, norm, bits);
        let len = values.len();
        assert!(scale_indices.len() == len && k0 + len <= self.tau_lo.len());
        assert!(bits <= E::MAX_SKIP_BITS, "skip bits {bits} for {}", E::NAME);
        #[cfg(target_arch = "x86_64")]
        if isa == Isa::Avx512 && isa.is_supported() {
            let rows = [
                self.cos_powers.rows(base.m + base.mp, k0),
                self.sin_powers.rows(base.m - base.mp, k0),
            ];
            // SAFETY: AVX-512F is supported (checked just above); every row has at least
            // `len` entries from k0 on (k0 + len <= number of points), as do `values` and
            // `scale_indices` (asserted above).
            unsafe { starts_avx512(rows, base, values, scale_indices) };
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if isa == Isa::Avx2 && isa.is_supported() {
            let rows = [
                self.cos_powers.rows(base.m + base.mp, k0),
                self.sin_powers.rows(base.m - base.mp, k0),
            ];
            // SAFETY: AVX2 and FMA are supported (checked just above); every row has at
            // least `len` entries from k0 on (k0 + len <= number of points), as do `values`
            // and `scale_indices` (asserted above).
            if unsafe { starts_avx2(rows, base, values, scale_indices) } {
                return;
            }
        }
        let _ = isa;
        for (i, (v, s)) in values.iter_mut().zip(scale_indices.iter_mut()).enumerate() {
            (*v, *s) = self.start(k0 + i, base, 1.0);
        }
    }
}

/// Whether `E` is `T` (a constant after monomorphisation).
fn is<E: 'static, T: 'static>() -> bool {
    TypeId::of::<E>() == TypeId::of::<T>()
}

/// Eight starting values at a time, with the arithmetic of [`BetaTables::start`] and
/// [`to_scaled`] (with `E`'s step `S`): the product of the five mantissas is split by
/// `getexp`/`getmant` into `frexp` form, and the scaled value is built by `scalef` (an
/// exact power-of-two scaling) with the scale index `j = floor((S - bits - e) / S)` where
/// the value is below `2^-bits`; for `f32` both are then rounded by `cvtpd2ps`, as `as
/// f32` rounds. `rows` holds the rows of the cosine and of the sine powers
/// ([`PowTable::rows`]).
///
/// # Safety
/// The CPU supports AVX-512F, and every row of `rows` and `scale_indices` holds at least
/// `values.len()` entries.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn starts_avx512<E: Elem>(
    rows: [[&[f64]; 4]; 2],
    base: &BaseStart,
    values: &mut [E],
    scale_indices: &mut [E],
) {
    use std::arch::x86_64::*;
    // `E` is one of the two (`Elem` is sealed): the stores below depend on it.
    let wide = is::<E, f64>();
    assert!(wide || is::<E, f32>());
    let [c, s] = rows;
    let len = values.len();
    let nm = _mm512_set1_pd(base.norm.mant);
    let ne = _mm512_set1_pd(base.norm.exp as f64);
    let neg_t = _mm512_set1_pd(-(base.skip_bits as f64));
    let floor_offset = _mm512_set1_pd(E::SCALE_STEP as f64 + 0.5 - base.skip_bits as f64);
    let step = _mm512_set1_pd(E::SCALE_STEP as f64);
    let inv_step = _mm512_set1_pd(1.0 / E::SCALE_STEP as f64);
    let zero = _mm512_setzero_pd();
    let one = _mm512_set1_pd(1.0);
    let negative = (base.m - base.mp) % 2 == 1;
    let sign = _mm512_set1_pd(if negative { -1.0 } else { 1.0 });
    let mut i = 0;
    while i < len {
        let mask: __mmask8 = if len - i >= 8 {
            0xff
        } else {
            (1u8 << (len - i)) - 1
        };
        // SAFETY: the masked lanes `i .. min(i + 8, len)` lie inside every row (at least
        // `len` entries, the caller's contract); masked-off lanes are not read.
        let ld = |a: &[f64]| unsafe { _mm512_maskz_loadu_pd(mask, a.as_ptr().add(i)) };
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
        // (x + S + 1/2) / S for x = -bits - e: its floor is j whatever the rounding of
        // 1/S (see `starts_avx2`).
        let q = _mm512_mul_pd(_mm512_sub_pd(floor_offset, e), inv_step);
        let j = _mm512_maskz_roundscale_pd::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(low, q);
        let pv = _mm512_scalef_pd(fm, _mm512_fmadd_pd(j, step, e));
        let pv = _mm512_maskz_mul_pd(nonzero, pv, sign);
        let scv = _mm512_maskz_sub_pd(nonzero, zero, j);
        // SAFETY: as the loads: the masked lanes lie inside `values` and `scale_indices`,
        // whose element type is f64 if `wide`, else f32 (asserted above).
        unsafe {
            let (pv_out, scv_out) = (
                values.as_mut_ptr().add(i),
                scale_indices.as_mut_ptr().add(i),
            );
            if wide {
                _mm512_mask_storeu_pd(pv_out.cast::<f64>(), mask, pv);
                _mm512_mask_storeu_pd(scv_out.cast::<f64>(), mask, scv);
            } else {
                // Eight floats in the low half; the mask's bits select among them.
                let narrow = |v| _mm512_castps256_ps512(_mm512_cvtpd_ps(v));
                _mm512_mask_storeu_ps(pv_out.cast::<f32>(), mask as __mmask16, narrow(pv));
                _mm512_mask_storeu_ps(scv_out.cast::<f32>(), mask as __mmask16, narrow(scv));
            }
        }
        i += 8;
    }
}

/// Four starting values at a time, for CPUs without AVX-512: the arithmetic of
/// [`starts_avx512`], with `frexp` and the power-of-two scaling done on the bits of the
/// doubles (AVX2 has no `getexp`, `getmant` or `scalef`), and for `f32` the rounding by
/// `cvtpd2ps`. Returns false, with `values` and
/// `scale_indices` unspecified, if some value lies outside the range where this arithmetic
/// is that of the scalar code (valid norms and tables never give one); the caller then
/// uses the scalar code.
///
/// # Safety
/// The CPU supports AVX2 and FMA, and every row of `rows` and `scale_indices` holds at
/// least `values.len()` entries.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn starts_avx2<E: Elem>(
    rows: [[&[f64]; 4]; 2],
    base: &BaseStart,
    values: &mut [E],
    scale_indices: &mut [E],
) -> bool {
    use std::arch::x86_64::*;
    // `E` is one of the two (`Elem` is sealed): the stores below depend on it.
    let wide = is::<E, f64>();
    assert!(wide || is::<E, f32>());
    // Why the bits are those of `start` and `to_scaled` (S = E::SCALE_STEP, T = bits):
    // - Exponents: all sums are integers below 2^53 in magnitude, so exact in doubles (the
    //   table exponents are at most 1075 times the highest power, the norm's is checked).
    // - frexp: where the product `mant` of the mantissas is a normal double (checked; five
    //   factors in [0.5, 1) give one, or zero), `mant = fm * 2^(E - 1022)` with E its
    //   exponent field and `fm` its bits with the field of 0.5, as `frexp` computes it.
    // - Scaling: the result is `fm * 2^k`, `k = e + S j`; for |k| <= 1000 `ldexp` does one
    //   multiplication by the double of bits `(k + 1023) << 52`, built here the same way
    //   (a normal double: 23 <= k + 1023 <= 2023). Below the threshold (e <= -T), with
    //   x = -T - e >= 0: j = floor(x / S) + 1 and k = S - T - (x mod S), in [1 - T, S - T],
    //   within [-559, 576] for T in `skip_bits_range::<E>()` (either element). Elsewhere
    //   j = 0 and k = e > -T >= -560, and e <= 1000 as a valid starting value is at most
    //   sqrt((2m + 1) / 2). |k| <= 1000 is checked all the same (any norm, any T).
    // - f32: the f64 results rounded by `cvtpd2ps` (to nearest, as `as f32`).
    // - Floor: (x + S + 1/2) / S (x + S + 1/2 exact) lies at least 1/(2S) above j and
    //   below j + 1, far beyond the relative rounding errors of 1/S and of the product
    //   (x far below 2^40), so its floor is j, as the integer division gives.
    if base.norm.exp.unsigned_abs() >= 1 << 40 {
        return false;
    }
    let [c, s] = rows;
    let len = values.len();
    let nm = _mm256_set1_pd(base.norm.mant);
    let ne = _mm256_set1_pd(base.norm.exp as f64);
    let neg_t = _mm256_set1_pd(-(base.skip_bits as f64));
    let floor_offset = _mm256_set1_pd(E::SCALE_STEP as f64 + 0.5 - base.skip_bits as f64);
    let step = _mm256_set1_pd(E::SCALE_STEP as f64);
    let inv_step = _mm256_set1_pd(1.0 / E::SCALE_STEP as f64);
    let max_k = _mm256_set1_pd(1000.0);
    let zero = _mm256_setzero_pd();
    let neg_zero = _mm256_set1_pd(-0.0);
    let negative = (base.m - base.mp) % 2 == 1;
    let sign = _mm256_set1_pd(if negative { -1.0 } else { 1.0 });
    // Integer <-> double without AVX-512: for an integer 0 <= n < 2^52, the double
    // `2^52 + n` holds `n` in its low bits.
    const TWO52: f64 = (1u64 << 52) as f64;
    let two52 = _mm256_set1_epi64x(TWO52.to_bits() as i64);
    let two52_1022 = _mm256_set1_pd(TWO52 + 1022.0);
    let two52_1023 = _mm256_set1_pd(TWO52 + 1023.0);
    let exp_field = _mm256_set1_epi64x(0x7ff << 52);
    let half_field = _mm256_set1_epi64x(1022 << 52);
    // The scaled values and scale indices of four points from their loaded rows, and a mask
    // of the lanes outside the range argued above.
    let block = |[c1m, c1e, c2m, c2e, s1m, s1e, s2m, s2e]: [__m256d; 8]| {
        // Same order of multiplication as the scalar code (its weight is 1 here).
        let mant = _mm256_mul_pd(
            _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(nm, c1m), c2m), s1m),
            s2m,
        );
        let exps = _mm256_add_pd(
            _mm256_add_pd(_mm256_add_pd(c1e, c2e), _mm256_add_pd(s1e, s2e)),
            ne,
        );
        // Unordered: a NaN product counts as nonzero (and is caught below).
        let nonzero = _mm256_cmp_pd::<_CMP_NEQ_UQ>(mant, zero);
        // frexp: mant = fm * 2^(E - 1022), E the exponent field, fm with the field of 0.5.
        let bits = _mm256_castpd_si256(mant);
        let field = _mm256_and_si256(bits, exp_field);
        let fm = _mm256_castsi256_pd(_mm256_or_si256(
            _mm256_andnot_si256(exp_field, bits),
            half_field,
        ));
        let biased = _mm256_castsi256_pd(_mm256_or_si256(_mm256_srli_epi64::<52>(field), two52));
        let e = _mm256_add_pd(exps, _mm256_sub_pd(biased, two52_1022));
        // Below the threshold (e <= -bits): j = floor((S - bits - e) / S) >= 1, else 0.
        let low = _mm256_cmp_pd::<_CMP_LE_OQ>(e, neg_t);
        let q = _mm256_mul_pd(_mm256_sub_pd(floor_offset, e), inv_step);
        let j = _mm256_and_pd(
            low,
            _mm256_round_pd::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(q),
        );
        let k = _mm256_fmadd_pd(j, step, e);
        // 2^k from the bits (k + 1023) << 52 (the low bits of 2^52 + 1023 + k).
        let pow2 = _mm256_castsi256_pd(_mm256_slli_epi64::<52>(_mm256_castpd_si256(
            _mm256_add_pd(k, two52_1023),
        )));
        let pv = _mm256_and_pd(nonzero, _mm256_mul_pd(_mm256_mul_pd(fm, pow2), sign));
        let scv = _mm256_and_pd(nonzero, _mm256_sub_pd(zero, j));
        // Outside the range: subnormal, infinite or NaN products, |k| > 1000.
        let special = _mm256_or_si256(
            _mm256_cmpeq_epi64(field, _mm256_setzero_si256()),
            _mm256_cmpeq_epi64(field, exp_field),
        );
        let out = _mm256_or_pd(
            _mm256_castsi256_pd(special),
            _mm256_cmp_pd::<_CMP_NLE_UQ>(_mm256_andnot_pd(neg_zero, k), max_k),
        );
        (pv, scv, _mm256_and_pd(nonzero, out))
    };
    let mut outside = zero;
    let mut i = 0;
    while i + 4 <= len {
        // SAFETY: lanes `i .. i + 4` lie inside every row (at least `len` entries, the
        // caller's contract).
        let ld = |a: &[f64]| unsafe { _mm256_loadu_pd(a.as_ptr().add(i)) };
        let (pv, scv, out) = block([
            ld(c[0]),
            ld(c[1]),
            ld(c[2]),
            ld(c[3]),
            ld(s[0]),
            ld(s[1]),
            ld(s[2]),
            ld(s[3]),
        ]);
        outside = _mm256_or_pd(outside, out);
        // SAFETY: as the loads: lanes `i .. i + 4` lie inside `values` and `scale_indices`,
        // whose element type is f64 if `wide`, else f32 (asserted above).
        unsafe {
            let (pv_out, scv_out) = (
                values.as_mut_ptr().add(i),
                scale_indices.as_mut_ptr().add(i),
            );
            if wide {
                _mm256_storeu_pd(pv_out.cast::<f64>(), pv);
                _mm256_storeu_pd(scv_out.cast::<f64>(), scv);
            } else {
                _mm_storeu_ps(pv_out.cast::<f32>(), _mm256_cvtpd_ps(pv));
                _mm_storeu_ps(scv_out.cast::<f32>(), _mm256_cvtpd_ps(scv));
            }
        }
        i += 4;
    }
    if i < len {
        // Lanes `0 .. len - i` (the sign bit set); the others load zeros, giving a zero
        // product that is neither stored nor checked.
        let mask = _mm256_cmpgt_epi64(
            _mm256_set1_epi64x((len - i) as i64),
            _mm256_setr_epi64x(0, 1, 2, 3),
        );
        // SAFETY: the masked lanes `i .. len` lie inside every row (at least `len` entries,
        // the caller's contract); masked-off lanes are not read.
        let ld = |a: &[f64]| unsafe { _mm256_maskload_pd(a.as_ptr().add(i), mask) };
        let (pv, scv, out) = block([
            ld(c[0]),
            ld(c[1]),
            ld(c[2]),
            ld(c[3]),
            ld(s[0]),
            ld(s[1]),
            ld(s[2]),
            ld(s[3]),
        ]);
        outside = _mm256_or_pd(outside, out);
        // SAFETY: as the loads: the masked lanes lie inside `values` and `scale_indices`,
        // whose element type is f64 if `wide`, else f32 (asserted above).
        unsafe {
            let (pv_out, scv_out) = (
                values.as_mut_ptr().add(i),
                scale_indices.as_mut_ptr().add(i),
            );
            if wide {
                _mm256_maskstore_pd(pv_out.cast::<f64>(), mask, pv);
                _mm256_maskstore_pd(scv_out.cast::<f64>(), mask, scv);
            } else {
                // The same lanes as 32-bit elements.
                let mask =
                    _mm_cmpgt_epi32(_mm_set1_epi32((len - i) as i32), _mm_setr_epi32(0, 1, 2, 3));
                _mm_maskstore_ps(pv_out.cast::<f32>(), mask, _mm256_cvtpd_ps(pv));
                _mm_maskstore_ps(scv_out.cast::<f32>(), mask, _mm256_cvtpd_ps(scv));
            }
        }
    }
    _mm256_movemask_pd(outside) == 0
}

#[cfg(test)]
mod tests {
    use super::{
        big, skip_bits_range, start_norm, start_norms, tiny, to_scaled, BaseStart, BetaTables,
        DEFAULT_SKIP_BITS, SCALE_STEP, SKIP_BITS_RANGE, TINY,
    };
    use crate::numeric::exact::is_rounded_sqrt;
    use crate::numeric::{frexp, ldexp, sin_cos_dd, Dd, Ext, PI_DD};
    use crate::real::Elem;
    use crate::simd::Isa;

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
        for t in [&bt.cos_powers, &bt.sin_powers] {
            let value = |m: f64, e: f64| ldexp(m, e as i64);
            for a in 0..64usize {
                let want = if a % 2 == 0 {
                    ldexp(1.0, -(a as i64 / 2))
                } else {
                    ldexp(half_sqrt2, -(a as i64 / 2))
                };
                assert_eq!(value(t.low_mant[a], t.low_exp[a]), want, "a={a}");
            }
            for j in 0..=maxpow / 64 {
                let want = ldexp(1.0, -32 * j as i64);
                assert_eq!(value(t.high_mant[j], t.high_exp[j]), want, "a={}", 64 * j);
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
                let ok = is_rounded_sqrt(x, (2 * m + 1) * bin, 2);
                assert_eq!(ok, Some(true), "m={m} mp={mp}: {x:e}");
            }
        }
    }

    /// The f64 constants are those of the generic form; the f32 ones are the powers of two.
    #[test]
    fn scale_constants() {
        assert_eq!(tiny::<f64>(), TINY);
        assert_eq!(SCALE_STEP, 600);
        assert_eq!(skip_bits_range::<f64>(), SKIP_BITS_RANGE);
        assert_eq!(skip_bits_range::<f32>(), 24..=100);
        assert_eq!(tiny::<f32>(), 2f32.powi(-96));
        for bits in [24u32, 64, 100] {
            assert_eq!(big::<f32>(bits), 2f32.powi(96 - bits as i32));
            assert_eq!(big::<f64>(bits), 2f64.powi(600 - bits as i32));
        }
    }

    /// `(start, index)` against the extended value `x`: `start * 2^(S index)` is `x` rounded
    /// to `E` (compared in extended form, exactly), `index = 0` exactly when
    /// `|x| >= 2^-bits`, and a scaled-down `start` lies in `[2^(-bits-1), big(bits)]`.
    fn check_scaled<E: Elem>((p, sc): (E, E), x: Ext, bits: u32) {
        let (p, sc) = (p.to_f64(), sc.to_f64());
        let what = format!("{} x={x:?} bits={bits}: ({p:e}, {sc})", E::NAME);
        assert!(sc <= 0.0 && sc == sc.trunc(), "{what}");
        if x.mant == 0.0 {
            assert_eq!((p.to_bits(), sc.to_bits()), (0, 0), "{what}");
            return;
        }
        assert_eq!(sc == 0.0, x.exp > -(bits as i64), "{what}");
        if sc < 0.0 {
            let (lo, hi) = (ldexp(1.0, -(bits as i64) - 1), big::<E>(bits).to_f64());
            assert!(p.abs() >= lo && p.abs() <= hi, "{what}");
        }
        // The mantissa rounded to `E` (scale-free: `p` is a normal number of `E`).
        let (wm, we) = frexp(E::from_f64(x.mant).to_f64());
        let (pm, pe) = frexp(p);
        assert_eq!(
            (pm, pe + E::SCALE_STEP * sc as i64),
            (wm, we + x.exp),
            "{what}"
        );
    }

    #[test]
    fn scaled_form_is_consistent() {
        // A mantissa that rounds up to 1 in f32, one that rounds down, and 0.75 (exact).
        let mants = [0.75, 1.0 - 1e-9, 0.6 + 1e-12, -0.6 - 1e-12];
        for &e in &[
            0i64, -23, -24, -25, -63, -64, -65, -99, -100, -101, -120, -196, -197, -299, -300,
            -301, -899, -900, -901, -5000,
        ] {
            for mant in mants {
                let x = Ext { mant, exp: e };
                for bits in [24, DEFAULT_SKIP_BITS, 100] {
                    check_scaled::<f32>(to_scaled(x, bits), x, bits);
                    check_scaled::<f64>(to_scaled(x, bits), x, bits);
                }
                for bits in [300, 560] {
                    check_scaled::<f64>(to_scaled(x, bits), x, bits);
                }
            }
        }
        let zero = Ext { mant: 0.0, exp: 0 };
        check_scaled::<f32>(to_scaled(zero, 64), zero, 64);
        check_scaled::<f64>(to_scaled(zero, 64), zero, 64);
    }

    /// The f32 starting values are the f64 ones rounded, in the f32 scaled form: at every
    /// grid point of a few clusters, skip thresholds across the f32 range.
    #[test]
    fn f32_starts_round_the_f64_ones() {
        let b = 300;
        let bt = BetaTables::grid(b);
        let norms = start_norms(b);
        for &(m, mp) in &[
            (0usize, 0usize),
            (1, 0),
            (17, 3),
            (150, 150),
            (299, 0),
            (299, 140),
        ] {
            let norm = norms[m * (m + 1) / 2 + mp];
            for bits in [24u32, 64, 100] {
                let base = BaseStart::new(m, mp, norm, bits);
                for k in 0..2 * b {
                    // The value in extended form, from the f64 scaled form (exact).
                    let (p, sc) = bt.start::<f64>(k, &base, 1.0);
                    let (pm, pe) = frexp(p);
                    let x = Ext {
                        mant: pm,
                        exp: pe + SCALE_STEP * sc as i64,
                    };
                    check_scaled::<f32>(bt.start::<f32>(k, &base, 1.0), x, bits);
                }
            }
        }
    }

    /// `starts` of every instruction set this CPU supports against `start`, bit for bit,
    /// for the points `k0 .. k0 + len`, in both element types (`bits` within each one's
    /// range).
    #[allow(clippy::too_many_arguments)]
    fn check_starts(
        bt: &BetaTables,
        k0: usize,
        len: usize,
        m: usize,
        mp: usize,
        norm: Ext,
        bits: u32,
    ) {
        check_starts_of::<f64>(bt, k0, len, m, mp, norm, bits);
        if bits <= f32::MAX_SKIP_BITS {
            check_starts_of::<f32>(bt, k0, len, m, mp, norm, bits);
        }
    }

    /// [`check_starts`] in element type `E`.
    #[allow(clippy::too_many_arguments)]
    fn check_starts_of<E: Elem>(
        bt: &BetaTables,
        k0: usize,
        len: usize,
        m: usize,
        mp: usize,
        norm: Ext,
        bits: u32,
    ) {
        // Bits through f64 (exact for both types: keeps the sign of zero).
        let bits_of = |x: E| x.to_f64().to_bits();
        let base = BaseStart::new(m, mp, norm, bits);
        let want: Vec<(u64, u64)> = (k0..k0 + len)
            .map(|k| {
                let (p, sc) = bt.start::<E>(k, &base, 1.0);
                (bits_of(p), bits_of(sc))
            })
            .collect();
        for isa in [Isa::Avx512, Isa::Avx2, Isa::Scalar] {
            if !isa.is_supported() {
                continue;
            }
            let nan = E::from_f64(f64::NAN);
            let (mut p, mut sc) = (vec![nan; len], vec![nan; len]);
            bt.starts(isa, k0, m, mp, norm, bits, &mut p, &mut sc);
            for i in 0..len {
                assert_eq!(
                    (bits_of(p[i]), bits_of(sc[i])),
                    want[i],
                    "{} {isa:?} m={m} mp={mp} norm={norm:?} bits={bits} k={} ({:e} {})",
                    E::NAME,
                    k0 + i,
                    p[i].to_f64(),
                    sc[i].to_f64()
                );
            }
        }
    }

    /// The vectorised starting values are bitwise those of the scalar code, for every
    /// instruction set of this CPU: values far below the skip threshold (scale indices down
    /// to -5), zero mantissas, partial vectors, norms outside the range of the vector
    /// arithmetic.
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
                for bits in [24u32, 64, 100, 300, 560] {
                    let n = 2 * b;
                    let mut ranges = vec![(0usize, n), (3, b - 1), (b, b)];
                    // Every length up to 9 (not multiples of 4 or 8), ending at the last point.
                    ranges.extend((1..=9.min(n)).map(|len| (n - len, len)));
                    for (k0, len) in ranges {
                        check_starts(&bt, k0, len, m, mp, norm, bits);
                    }
                }
            }
            // Values up to 2^1100 (beyond the vector arithmetic: the scalar fallback) and
            // down to 2^-5000.
            for exp in [1000i64, 1001, 1010, 1100, -600, -5000] {
                let norm = Ext { mant: 0.75, exp };
                check_starts(&bt, 0, 2 * b, 0, 0, norm, 64);
                check_starts(&bt, 1, 2 * b - 1, 1, 0, norm, 100);
                check_starts(&bt, 1, 2 * b - 1, 1, 0, norm, 560);
            }
        }
        // Zero mantissas: beta = 0 (sin = 0) and beta = pi (cos = 0) among the points
        // beta = pi k / 10.
        let pts: Vec<(Dd, Dd)> = (0..=10)
            .map(|k| {
                let (s, c) = sin_cos_dd(PI_DD.mul_f(k as f64).div(Dd::new(20.0)));
                match k {
                    0 => (Dd::new(1.0), Dd::new(0.0)),
                    10 => (Dd::new(0.0), Dd::new(1.0)),
                    _ => (c, s),
                }
            })
            .collect();
        let bt = BetaTables::new(&pts, 80);
        let norms = start_norms(41);
        for &(m, mp) in &[
            (0usize, 0usize),
            (1, 0),
            (7, 3),
            (20, 20),
            (40, 0),
            (40, 39),
        ] {
            let norm = norms[m * (m + 1) / 2 + mp];
            for bits in [24u32, 100, 560] {
                for k0 in 0..pts.len() {
                    for len in 1..=pts.len() - k0 {
                        check_starts(&bt, k0, len, m, mp, norm, bits);
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
