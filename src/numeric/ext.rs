//! Extended-exponent numbers: a double mantissa (or a double-double one) with an integer
//! power of two, for products of hundreds of factors that would over- or underflow doubles.

use super::double_double::Dd;

/// A number `mant * 2^exp` with `mant` in `[0.5, 1)` (or zero): no overflow, no underflow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ext {
    /// Mantissa in `[0.5, 1)`, or zero.
    pub mant: f64,
    /// Power of two.
    pub exp: i64,
}

/// `x = m * 2^e` with `m` in `[0.5, 1)`; `(0, 0)` for zero. `x` must be finite.
#[inline]
pub(crate) fn frexp(x: f64) -> (f64, i64) {
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
    /// One.
    pub const ONE: Ext = Ext { mant: 0.5, exp: 1 };
}

/// A double-double mantissa with an extended exponent, `(m.hi + m.lo) 2^e`, `m.hi` in
/// `[0.5, 1)` (or zero): products of hundreds of factors without overflow and with
/// rounding errors far below one double ulp.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ExtDd {
    /// The mantissa, `m.hi` in `[0.5, 1)` (or zero).
    pub(crate) m: Dd,
    /// The power of two.
    pub(crate) e: i64,
}

impl ExtDd {
    /// One.
    pub(crate) const ONE: ExtDd = ExtDd {
        m: Dd { hi: 0.5, lo: 0.0 },
        e: 1,
    };

    /// `d` normalised (`d.hi` in `[0.5, 1)` times a power of two).
    pub(crate) fn from_dd(d: Dd) -> ExtDd {
        let (hi, e) = frexp(d.hi);
        ExtDd {
            m: Dd {
                hi,
                lo: ldexp(d.lo, -e),
            },
            e,
        }
    }

    /// Times `2^k`.
    pub(crate) fn shift(self, k: i64) -> ExtDd {
        ExtDd {
            m: self.m,
            e: self.e + k,
        }
    }

    /// `self * o`.
    pub(crate) fn mul(self, o: ExtDd) -> ExtDd {
        ExtDd::from_dd(self.m.mul(o.m)).shift(self.e + o.e)
    }

    /// `sqrt(self)`.
    pub(crate) fn sqrt(self) -> ExtDd {
        // An even exponent: sqrt(m 2^(2k)) = sqrt(m) 2^k.
        let (m, e) = if self.e % 2 == 0 {
            (self.m, self.e)
        } else {
            (self.m.mul_f(2.0), self.e - 1)
        };
        ExtDd::from_dd(m.sqrt()).shift(e / 2)
    }

    /// The nearest double, as an [`Ext`].
    pub(crate) fn to_ext(self) -> Ext {
        let (mant, e) = frexp(self.m.to_f64());
        Ext {
            mant,
            exp: e + self.e,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{frexp, ldexp, Dd, ExtDd};

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
        let a = ExtDd::from_dd(Dd::new(0.5)).shift(-2999);
        let b = ExtDd::from_dd(Dd::new(0.5)).shift(2001);
        let p = a.mul(b).to_ext();
        assert_eq!(ldexp(p.mant, p.exp), ldexp(1.0, -1000));
        let s = ExtDd::from_dd(Dd::new(0.5)).shift(3).sqrt().to_ext(); // sqrt(4) = 2
        assert_eq!(ldexp(s.mant, s.exp), 2.0);
        let s = ExtDd::from_dd(Dd::new(0.5)).shift(4).sqrt().to_ext(); // sqrt(8)
        assert_eq!(ldexp(s.mant, s.exp), 8f64.sqrt());
        let s = ExtDd::from_dd(Dd::new(0.5)).shift(-2001).sqrt().to_ext(); // sqrt(2^-2002)
        assert_eq!((s.mant, s.exp), (0.5, -1000));
    }
}
