//! The lane-pair operations of every instruction set against their definitions.

use super::avx2::Avx2;
use super::avx512::Avx512;
use super::{Isa, Simd};

/// `splat2`, `unpack_even` and `unpack_odd` against their definitions, lane by lane.
fn pair_ops<S: Simd, const W: usize>() {
    let a: Vec<f64> = (0..W).map(|k| 1.0 + k as f64).collect();
    let b: Vec<f64> = (0..W).map(|k| -10.0 - k as f64).collect();
    let mut out = [[0.0; W]; 3];
    // SAFETY: callers check the instruction set; every pointer covers W doubles.
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

#[test]
fn pair_operations() {
    if Isa::Avx512.is_supported() {
        pair_ops::<Avx512, 8>();
    }
    if Isa::Avx2.is_supported() {
        pair_ops::<Avx2, 4>();
    }
}
