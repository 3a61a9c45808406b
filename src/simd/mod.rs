//! Minimal SIMD abstraction with run-time dispatch (AVX-512, AVX2+FMA, portable scalar).
//!
//! Kernels are written once, generic over [`Simd`], and instantiated inside
//! `#[target_feature]` entry points (see the `dwt` module): every method is
//! `#[inline(always)]`, so after inlining the intrinsics sit in a function that has the
//! features enabled. One file per instruction set: [`scalar`], `avx2`, `avx512`.

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2_f32;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512_f32;
#[cfg(feature = "internals")]
pub(crate) mod peak;
pub(crate) mod scalar;
#[cfg(all(test, target_arch = "x86_64"))]
mod tests;

use crate::numeric::Elem;

/// The environment variable that overrides [`Isa::detect`] (see [`Isa::selected`]).
pub const ISA_VARIABLE: &str = "SO3FFT_ISA";

/// Instruction set chosen for the DWT kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// AVX-512F, 8 doubles per vector.
    Avx512,
    /// AVX2 with FMA, 4 doubles per vector.
    Avx2,
    /// Portable scalar code (one double per "vector", no FMA).
    Scalar,
}

impl Isa {
    /// The instruction set of an `isa` option (`None`: [`Isa::selected`]); an error when
    /// the CPU does not support it.
    pub(crate) fn resolve(isa: Option<Isa>) -> crate::Result<Isa> {
        let isa = match isa {
            Some(isa) => isa,
            None => Isa::selected()?,
        };
        if !isa.is_supported() {
            return Err(crate::Error::InvalidArgument(format!(
                "instruction set {isa:?} not supported by this CPU"
            )));
        }
        Ok(isa)
    }

    /// The instruction set of plans whose options name none: the one the environment
    /// variable `SO3FFT_ISA` names (`avx512`, `avx2` or `scalar`, any case; for measuring
    /// one set's kernels on a CPU that has a wider one), else [`Isa::detect`]. An error
    /// when the variable names no instruction set or one this CPU lacks.
    pub fn selected() -> crate::Result<Isa> {
        let Some(value) = std::env::var_os(ISA_VARIABLE) else {
            return Ok(Isa::detect());
        };
        let isa = match value
            .to_str()
            .map(|v| v.trim().to_ascii_lowercase())
            .as_deref()
        {
            Some("") => return Ok(Isa::detect()),
            Some("avx512") => Isa::Avx512,
            Some("avx2") => Isa::Avx2,
            Some("scalar") => Isa::Scalar,
            _ => {
                return Err(crate::Error::InvalidArgument(format!(
                    "{ISA_VARIABLE}={value:?}: expected avx512, avx2 or scalar"
                )))
            }
        };
        if !isa.is_supported() {
            return Err(crate::Error::InvalidArgument(format!(
                "{ISA_VARIABLE}: instruction set {isa:?} not supported by this CPU"
            )));
        }
        Ok(isa)
    }

    /// The best instruction set this CPU supports.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("fma")
            {
                return Isa::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
            {
                return Isa::Avx2;
            }
        }
        Isa::Scalar
    }

    /// Whether this CPU can run kernels for `self`.
    pub fn is_supported(self) -> bool {
        match self {
            Isa::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// Number of doubles per vector.
    pub fn lanes(self) -> usize {
        self.lanes_of::<f64>()
    }

    /// Lanes of the kernels' widest vectors of `E` (lane arrays are padded to a multiple
    /// of it).
    pub(crate) fn lanes_of<E: Elem>(self) -> usize {
        let bytes = match self {
            Isa::Avx512 => 64,
            Isa::Avx2 => 32,
            Isa::Scalar => return 1,
        };
        bytes / E::BYTES
    }
}

/// Vector operations used by the kernels, one implementation per instruction set and
/// element type.
///
/// # Safety
/// Every method is unsafe: the caller guarantees that the CPU supports the instruction set
/// of the implementation ([`Isa::is_supported`]) and that every pointer argument is valid
/// for `W` elements (two for [`Simd::splat2`], `G` for [`Simd::splat_group`]), `W` the
/// vector width.
pub(crate) trait Simd: Copy {
    /// The element type.
    type E: Elem;
    /// The vector type.
    type V: Copy;
    /// Vector registers of the instruction set (the kernels' shapes depend on it).
    const REGS: usize;
    /// `x` in every lane.
    unsafe fn splat(x: Self::E) -> Self::V;
    /// `W` elements from `p` (no alignment needed).
    unsafe fn load(p: *const Self::E) -> Self::V;
    /// `v` to the `W` elements at `p` (no alignment needed).
    unsafe fn store(p: *mut Self::E, v: Self::V);
    /// `a + b`
    unsafe fn add(a: Self::V, b: Self::V) -> Self::V;
    /// `a * b`
    unsafe fn mul(a: Self::V, b: Self::V) -> Self::V;
    /// `a * b + c`
    unsafe fn fma(a: Self::V, b: Self::V, c: Self::V) -> Self::V;
    /// `a * b - c`
    unsafe fn fms(a: Self::V, b: Self::V, c: Self::V) -> Self::V;
    /// Whether any lane has `a >= b`.
    unsafe fn any_ge(a: Self::V, b: Self::V) -> bool;
    /// `|v|`
    unsafe fn abs(v: Self::V) -> Self::V;
    /// Lane-wise `if a >= b { x } else { y }`.
    unsafe fn blend_ge(a: Self::V, b: Self::V, x: Self::V, y: Self::V) -> Self::V;
    /// Lane-wise maximum.
    unsafe fn max(a: Self::V, b: Self::V) -> Self::V;
    /// Transpose the `W x W` block `v` (vector `j`, lane `w`) in registers: afterwards
    /// vector `w` holds lane `w` of every former vector.
    unsafe fn transpose(v: &mut [Self::V]);
    /// Betas per group in the forward kernel's grouped mode for rows of 8 values
    /// ([`Simd::splat_group`]; 1: no grouping).
    const GROUP_8: usize = 1;
    /// As [`Simd::GROUP_8`], for rows of 16 values.
    const GROUP_16: usize = 1;
    /// `[p[0], p[1]]` repeated in every pair of lanes (`W >= 2` only).
    unsafe fn splat2(p: *const Self::E) -> Self::V;
    /// The even lanes of `a` and `b` interleaved, `[a0, b0, a2, b2, ...]` (`W >= 2` only).
    unsafe fn unpack_even(a: Self::V, b: Self::V) -> Self::V;
    /// The odd lanes of `a` and `b` interleaved, `[a1, b1, a3, b3, ...]` (`W >= 2` only).
    unsafe fn unpack_odd(a: Self::V, b: Self::V) -> Self::V;
    /// The `G` values `p[0..G]` repeated over the lanes, `G = group_of::<Self>(P)`: the
    /// d values of a group of betas, lane `k` holding beta `k % G`'s.
    #[inline(always)]
    unsafe fn splat_group<const P: usize>(p: *const Self::E) -> Self::V {
        // SAFETY: the trait's contract (groups of 2 unless overridden).
        unsafe { Self::splat2(p) }
    }
    /// The rows of `P` values of the `G` betas of a group (`x + b * stride`, `b < G`) in
    /// two vectors: lane `k` of either holds a value of beta `k % G`'s row, and the two
    /// products with [`Simd::splat_group`], summed over groups, give the column sums
    /// through [`Simd::fold_group`].
    #[inline(always)]
    unsafe fn group_rows<const P: usize>(x: *const Self::E, stride: usize) -> [Self::V; 2] {
        // SAFETY: the trait's contract; the caller guarantees both rows valid for `W`
        // values (groups of 2 unless overridden: `P = W`).
        unsafe {
            let (a, b) = (Self::load(x), Self::load(x.add(stride)));
            [Self::unpack_even(a, b), Self::unpack_odd(a, b)]
        }
    }
    /// The `P` column sums (in the first `P` lanes, in order) from the sums of the
    /// products with the two vectors of [`Simd::group_rows`].
    #[inline(always)]
    unsafe fn fold_group<const P: usize>(a: Self::V, b: Self::V) -> Self::V {
        // SAFETY: the trait's contract (groups of 2 unless overridden).
        unsafe { Self::add(Self::unpack_even(a, b), Self::unpack_odd(a, b)) }
    }
    /// The first `k` lanes of `v` to `p` (valid for `k` values).
    #[inline(always)]
    unsafe fn store_first(p: *mut Self::E, v: Self::V, k: usize) {
        // SAFETY: the trait's contract; `p` valid for `k <= W` values.
        unsafe {
            let mut t = [Self::E::ZERO; MAX_LANES];
            Self::store(t.as_mut_ptr(), v);
            std::ptr::copy_nonoverlapping(t.as_ptr(), p, k);
        }
    }
    /// Store `v` at `p` without reading the cache line first (a non-temporal store) where
    /// `p` is aligned to the vector size, else an ordinary store. Callers end a run of these
    /// with [`sfence`].
    #[inline(always)]
    unsafe fn stream(p: *mut Self::E, v: Self::V) {
        // SAFETY: the trait's contract.
        unsafe { Self::store(p, v) }
    }
    /// Store the `k x W` block `v` (vector `j`, lane `w`; `k = v.len() <= W`) transposed:
    /// lane `w` of every vector goes to the row `dst + w * stride`, vector `j` to its entry
    /// `j` (full rows with [`Simd::stream`] if `stream`, else ordinary stores).
    #[inline(always)]
    unsafe fn store_transposed<const W: usize>(
        v: &[Self::V],
        dst: *mut Self::E,
        stride: usize,
        stream: bool,
    ) {
        // SAFETY: the instruction set by the trait's contract; the caller guarantees the
        // `W` rows `dst + w * stride` (`k` elements each) valid for writes.
        unsafe {
            let mut t = [Self::zero(); MAX_LANES];
            let k = v.len();
            t[..k].copy_from_slice(v);
            Self::transpose(&mut t[..W]);
            for (r, x) in t[..W].iter().enumerate() {
                if k < W {
                    Self::store_first(dst.add(r * stride), *x, k);
                } else if stream {
                    Self::stream(dst.add(r * stride), *x);
                } else {
                    Self::store(dst.add(r * stride), *x);
                }
            }
        }
    }
    /// `v` unchanged, through an empty `asm!` the compiler may not move code across:
    /// pins the program order of what is computed before and after it.
    #[inline(always)]
    unsafe fn fence(v: Self::V) -> Self::V {
        v
    }
    /// Zero in every lane.
    #[inline(always)]
    unsafe fn zero() -> Self::V {
        // SAFETY: the trait's contract.
        unsafe { Self::splat(Self::E::ZERO) }
    }
}

/// The most lanes of any vector type (16 floats with AVX-512).
pub(crate) const MAX_LANES: usize = 16;

/// Betas per group of `S`'s grouped forward mode for rows of `p` values (1: none).
pub(crate) const fn group_of<S: Simd>(p: usize) -> usize {
    if p == 8 {
        S::GROUP_8
    } else {
        S::GROUP_16
    }
}

/// Orders earlier non-temporal stores ([`Simd::stream`]) before everything after it.
#[inline(always)]
pub(crate) fn sfence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a store fence has no operands; SSE is part of x86-64.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}
