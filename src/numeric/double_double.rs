//! Double-double arithmetic: about 106 bits from a pair of doubles, enough to round
//! products of table values, square roots and trigonometric values to the nearest double.

/// Double-double number `hi + lo` (`|lo| <= ulp(hi) / 2`): about 106 bits, enough to
/// round the recurrence coefficients to the nearest double.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dd {
    /// The leading part, the double nearest to the value.
    pub hi: f64,
    /// The remainder, `|lo| <= ulp(hi) / 2`.
    pub lo: f64,
}

impl Dd {
    /// The double `x`.
    #[inline(always)]
    pub fn new(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    /// `hi + lo` renormalised (`|hi| >= |lo|`).
    #[inline(always)]
    pub(crate) fn fast_sum(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd {
            hi: s,
            lo: lo - (s - hi),
        }
    }

    /// The exact product of two doubles.
    #[inline(always)]
    pub(crate) fn prod(a: f64, b: f64) -> Dd {
        let p = a * b;
        Dd {
            hi: p,
            lo: a.mul_add(b, -p),
        }
    }

    /// `a / b` of two doubles (the remainder `a - q b` is exact).
    #[inline(always)]
    pub(crate) fn quot(a: f64, b: f64) -> Dd {
        let q = a / b;
        let rem = (-q).mul_add(b, a);
        Dd::fast_sum(q, rem / b)
    }

    /// `self * b`.
    #[inline(always)]
    pub fn mul_f(self, b: f64) -> Dd {
        let p = Dd::prod(self.hi, b);
        Dd::fast_sum(p.hi, self.lo.mul_add(b, p.lo))
    }

    /// `self * b`.
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

    /// `self / b`.
    #[inline(always)]
    pub fn div(self, b: Dd) -> Dd {
        let q1 = self.hi / b.hi;
        // The remainder `self - q1 b`; its high part cancels exactly.
        let p = b.mul_f(q1);
        let rem = (self.hi - p.hi) - p.lo + self.lo;
        Dd::fast_sum(q1, rem / b.hi)
    }

    /// `sqrt(self)` (0 for `self <= 0`).
    #[inline(always)]
    pub(crate) fn sqrt(self) -> Dd {
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

#[cfg(test)]
mod tests {
    use super::{sin_cos_dd, Dd, PI_DD};

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
}
