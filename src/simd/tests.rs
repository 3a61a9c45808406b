//! The lane-pair operations and transposes of every instruction set against their
//! definitions.

use super::avx2::Avx2;
use super::avx2_f32::Avx2F32;
use super::avx512::Avx512;
use super::avx512_f32::Avx512F32;
use super::{group_of, Isa, Simd, MAX_LANES};
use crate::numeric::Elem;

/// `splat2`, `unpack_even` and `unpack_odd` against their definitions, lane by lane.
fn pair_ops<S: Simd, const W: usize>() {
    let e = |x: f64| S::E::from_f64(x);
    let a: Vec<S::E> = (0..W).map(|k| e(1.0 + k as f64)).collect();
    let b: Vec<S::E> = (0..W).map(|k| e(-10.0 - k as f64)).collect();
    let mut out = [[S::E::ZERO; W]; 3];
    // SAFETY: callers check the instruction set; every pointer covers W elements.
    unsafe {
        let (va, vb) = (S::load(a.as_ptr()), S::load(b.as_ptr()));
        S::store(out[0].as_mut_ptr(), S::splat2(a[2..].as_ptr()));
        S::store(out[1].as_mut_ptr(), S::unpack_even(va, vb));
        S::store(out[2].as_mut_ptr(), S::unpack_odd(va, vb));
    }
    for k in 0..W {
        assert_eq!(out[0][k], a[2 + k % 2]);
        let (src, lane) = (if k % 2 == 0 { &a } else { &b }, k - k % 2);
        assert_eq!(out[1][k], src[lane]);
        assert_eq!(out[2][k], src[lane + 1]);
    }
}

/// `transpose` and `store_transposed` against the definition.
fn transposes<S: Simd, const W: usize>() {
    let x = |r: usize, c: usize| S::E::from_f64((r * 100 + c) as f64);
    let rows: Vec<Vec<S::E>> = (0..W).map(|r| (0..W).map(|c| x(r, c)).collect()).collect();
    let stride = W + 3;
    let mut out = vec![S::E::ZERO; W * stride];
    let mut back = [[S::E::ZERO; W]; W];
    // SAFETY: callers check the instruction set; every pointer covers W elements.
    unsafe {
        let mut v = [S::zero(); MAX_LANES];
        for (r, row) in rows.iter().enumerate() {
            v[r] = S::load(row.as_ptr());
        }
        S::store_transposed::<W>(&v[..W], out.as_mut_ptr(), stride, false);
        S::transpose(&mut v[..W]);
        for (r, b) in back.iter_mut().enumerate() {
            S::store(b.as_mut_ptr(), v[r]);
        }
    }
    for r in 0..W {
        for c in 0..W {
            assert_eq!(back[r][c], x(c, r), "{} W={W} ({r}, {c})", S::E::NAME);
            assert_eq!(out[r * stride + c], x(c, r));
        }
    }
}

/// The grouped forward's operations against the sums they stand for: for two groups of
/// `G` betas (rows of `P` values, `G P = 2 W`), `fold_group` of the products with
/// `splat_group` and `group_rows` gives `sum_b d_b x_b[c]` in lane `c`; and a transposed
/// store of `P < W` vectors writes exactly `P` values a row.
fn group_ops<S: Simd, const W: usize, const P: usize>() {
    let g = group_of::<S>(P);
    assert_eq!(g * P, 2 * W);
    let e = |x: f64| S::E::from_f64(x);
    // Small integers: every sum is exact in either precision.
    let rows: Vec<S::E> = (0..2 * g * P)
        .map(|k| e(((k * 7) % 13) as f64 - 6.0))
        .collect();
    let d: Vec<S::E> = (0..2 * g).map(|k| e(k as f64 - 3.0)).collect();
    let mut out = [S::E::ZERO; MAX_LANES];
    // SAFETY: callers check the instruction set; the rows hold `P` values each, `d` the
    // group's values, `out` a vector.
    unsafe {
        let (mut a, mut b) = (S::zero(), S::zero());
        for grp in 0..2 {
            let [lo, hi] = S::group_rows::<P>(rows[grp * g * P..].as_ptr(), P);
            let x = S::splat_group::<P>(d[grp * g..].as_ptr());
            a = S::fma(x, lo, a);
            b = S::fma(x, hi, b);
        }
        S::store(out.as_mut_ptr(), S::fold_group::<P>(a, b));
    }
    for c in 0..P {
        let want = (0..2 * g).fold(0.0, |s, k| s + d[k].to_f64() * rows[k * P + c].to_f64());
        assert_eq!(
            out[c].to_f64(),
            want,
            "{} W={W} P={P} column {c}",
            S::E::NAME
        );
    }
    if P < W {
        let mut dst = vec![e(-1.0); W * (P + 1)];
        // SAFETY: the instruction set is checked by the callers; `W` rows of `P + 1`.
        unsafe {
            let v = [S::splat(e(2.0)); MAX_LANES];
            S::store_transposed::<W>(&v[..P], dst.as_mut_ptr(), P + 1, false);
        }
        for r in 0..W {
            assert!(dst[r * (P + 1)..][..P].iter().all(|&x| x == e(2.0)));
            assert_eq!(dst[r * (P + 1) + P], e(-1.0));
        }
    }
}

#[test]
fn group_operations() {
    if Isa::Avx512.is_supported() {
        group_ops::<Avx512, 8, 8>();
        group_ops::<Avx512F32, 16, 16>();
        group_ops::<Avx512F32, 16, 8>();
    }
    if Isa::Avx2.is_supported() {
        group_ops::<Avx2F32, 8, 8>();
    }
}

#[test]
fn pair_operations() {
    if Isa::Avx512.is_supported() {
        pair_ops::<Avx512, 8>();
        pair_ops::<Avx512F32, 16>();
    }
    if Isa::Avx2.is_supported() {
        pair_ops::<Avx2, 4>();
        pair_ops::<Avx2F32, 8>();
    }
}

#[test]
fn transpose_operations() {
    if Isa::Avx512.is_supported() {
        transposes::<Avx512, 8>();
        transposes::<Avx512F32, 16>();
    }
    if Isa::Avx2.is_supported() {
        transposes::<Avx2, 4>();
        transposes::<Avx2F32, 8>();
    }
}
