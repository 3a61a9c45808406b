//! Instruction-mix ceilings of this machine for the DWT kernels (test only).
//!
//! Hand-written AVX-512 loops, data in L1, no dependencies beyond what the mix itself
//! needs: each gives the fraction of the FMA peak that a kernel built from that mix could
//! reach at best. They are the evidence behind the DWT targets in `notes/next-steps.md`:
//! `cargo test --release --lib instruction_ceilings -- --ignored --nocapture`.

use std::arch::asm;
use std::time::Instant;

/// One timed loop: `iters` iterations of `fmas` useful FMAs each.
type Loop = unsafe fn(usize, *mut f64) -> ();

/// Expands to an `asm!` loop of `$body` run `$n` times, `{b}` the data pointer (L1
/// resident), with every vector register clobbered.
macro_rules! asm_loop {
    ($n:expr, $b:expr, $($body:expr),+ $(,)?) => {
        asm!(
            // Every register starts finite (a clobbered register may hold anything).
            "vbroadcastsd zmm0, qword ptr [{b}]",
            "vbroadcastsd zmm1, qword ptr [{b}]",
            "vbroadcastsd zmm2, qword ptr [{b}]",
            "vbroadcastsd zmm3, qword ptr [{b}]",
            "vbroadcastsd zmm4, qword ptr [{b}]",
            "vbroadcastsd zmm5, qword ptr [{b}]",
            "vbroadcastsd zmm6, qword ptr [{b}]",
            "vbroadcastsd zmm7, qword ptr [{b}]",
            "vbroadcastsd zmm8, qword ptr [{b}]",
            "vbroadcastsd zmm9, qword ptr [{b}]",
            "vbroadcastsd zmm10, qword ptr [{b}]",
            "vbroadcastsd zmm11, qword ptr [{b}]",
            "vbroadcastsd zmm12, qword ptr [{b}]",
            "vbroadcastsd zmm13, qword ptr [{b}]",
            "vbroadcastsd zmm14, qword ptr [{b}]",
            "vbroadcastsd zmm15, qword ptr [{b}]",
            "vbroadcastsd zmm16, qword ptr [{b}]",
            "vbroadcastsd zmm17, qword ptr [{b}]",
            "vbroadcastsd zmm18, qword ptr [{b}]",
            "vbroadcastsd zmm19, qword ptr [{b}]",
            "vbroadcastsd zmm20, qword ptr [{b}]",
            "vbroadcastsd zmm21, qword ptr [{b}]",
            "vbroadcastsd zmm22, qword ptr [{b}]",
            "vbroadcastsd zmm23, qword ptr [{b}]",
            "vbroadcastsd zmm24, qword ptr [{b}]",
            "vbroadcastsd zmm25, qword ptr [{b}]",
            "vbroadcastsd zmm26, qword ptr [{b}]",
            "vbroadcastsd zmm27, qword ptr [{b}]",
            "vbroadcastsd zmm28, qword ptr [{b}]",
            "vbroadcastsd zmm29, qword ptr [{b}]",
            "vbroadcastsd zmm30, qword ptr [{b}]",
            "vbroadcastsd zmm31, qword ptr [{b}]",
            "2:",
            $($body,)+
            "dec {n}",
            "jnz 2b",
            n = inout(reg) $n => _,
            b = in(reg) $b,
            out("zmm0") _, out("zmm1") _, out("zmm2") _, out("zmm3") _,
            out("zmm4") _, out("zmm5") _, out("zmm6") _, out("zmm7") _,
            out("zmm8") _, out("zmm9") _, out("zmm10") _, out("zmm11") _,
            out("zmm12") _, out("zmm13") _, out("zmm14") _, out("zmm15") _,
            out("zmm16") _, out("zmm17") _, out("zmm18") _, out("zmm19") _,
            out("zmm20") _, out("zmm21") _, out("zmm22") _, out("zmm23") _,
            out("zmm24") _, out("zmm25") _, out("zmm26") _, out("zmm27") _,
            out("zmm28") _, out("zmm29") _, out("zmm30") _, out("zmm31") _,
            options(nostack),
        )
    };
}

/// 16 independent FMAs on registers: the peak.
#[target_feature(enable = "avx512f")]
unsafe fn regs(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        "vfmadd231pd zmm0, zmm24, zmm16",
        "vfmadd231pd zmm1, zmm24, zmm17",
        "vfmadd231pd zmm2, zmm24, zmm18",
        "vfmadd231pd zmm3, zmm24, zmm19",
        "vfmadd231pd zmm4, zmm24, zmm20",
        "vfmadd231pd zmm5, zmm24, zmm21",
        "vfmadd231pd zmm6, zmm24, zmm22",
        "vfmadd231pd zmm7, zmm24, zmm23",
        "vfmadd231pd zmm8, zmm25, zmm16",
        "vfmadd231pd zmm9, zmm25, zmm17",
        "vfmadd231pd zmm10, zmm25, zmm18",
        "vfmadd231pd zmm11, zmm25, zmm19",
        "vfmadd231pd zmm12, zmm25, zmm20",
        "vfmadd231pd zmm13, zmm25, zmm21",
        "vfmadd231pd zmm14, zmm25, zmm22",
        "vfmadd231pd zmm15, zmm25, zmm23",
    )
}

/// One broadcast load feeding two FMAs (the forward kernel's multiply-adds of one d
/// value with a 16-column data row in registers), 16 FMAs per iteration.
#[target_feature(enable = "avx512f")]
unsafe fn bcast_two(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        "vbroadcastsd zmm16, qword ptr [{b}]",
        "vfmadd231pd zmm0, zmm16, zmm24",
        "vfmadd231pd zmm1, zmm16, zmm25",
        "vbroadcastsd zmm17, qword ptr [{b}+8]",
        "vfmadd231pd zmm2, zmm17, zmm24",
        "vfmadd231pd zmm3, zmm17, zmm25",
        "vbroadcastsd zmm18, qword ptr [{b}+16]",
        "vfmadd231pd zmm4, zmm18, zmm24",
        "vfmadd231pd zmm5, zmm18, zmm25",
        "vbroadcastsd zmm19, qword ptr [{b}+24]",
        "vfmadd231pd zmm6, zmm19, zmm24",
        "vfmadd231pd zmm7, zmm19, zmm25",
        "vbroadcastsd zmm20, qword ptr [{b}+32]",
        "vfmadd231pd zmm8, zmm20, zmm24",
        "vfmadd231pd zmm9, zmm20, zmm25",
        "vbroadcastsd zmm21, qword ptr [{b}+40]",
        "vfmadd231pd zmm10, zmm21, zmm24",
        "vfmadd231pd zmm11, zmm21, zmm25",
        "vbroadcastsd zmm22, qword ptr [{b}+48]",
        "vfmadd231pd zmm12, zmm22, zmm24",
        "vfmadd231pd zmm13, zmm22, zmm25",
        "vbroadcastsd zmm23, qword ptr [{b}+56]",
        "vfmadd231pd zmm14, zmm23, zmm24",
        "vfmadd231pd zmm15, zmm23, zmm25",
    )
}

/// 16 FMAs whose second operand is an embedded `{1to8}` broadcast from memory (the inverse
/// kernel's multiply-adds: one d vector times each coefficient of a row).
#[target_feature(enable = "avx512f")]
unsafe fn embedded(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        "vfmadd231pd zmm0, zmm24, qword ptr [{b}]{{1to8}}",
        "vfmadd231pd zmm1, zmm24, qword ptr [{b}+8]{{1to8}}",
        "vfmadd231pd zmm2, zmm24, qword ptr [{b}+16]{{1to8}}",
        "vfmadd231pd zmm3, zmm24, qword ptr [{b}+24]{{1to8}}",
        "vfmadd231pd zmm4, zmm24, qword ptr [{b}+32]{{1to8}}",
        "vfmadd231pd zmm5, zmm24, qword ptr [{b}+40]{{1to8}}",
        "vfmadd231pd zmm6, zmm24, qword ptr [{b}+48]{{1to8}}",
        "vfmadd231pd zmm7, zmm24, qword ptr [{b}+56]{{1to8}}",
        "vfmadd231pd zmm8, zmm24, qword ptr [{b}+64]{{1to8}}",
        "vfmadd231pd zmm9, zmm24, qword ptr [{b}+72]{{1to8}}",
        "vfmadd231pd zmm10, zmm24, qword ptr [{b}+80]{{1to8}}",
        "vfmadd231pd zmm11, zmm24, qword ptr [{b}+88]{{1to8}}",
        "vfmadd231pd zmm12, zmm24, qword ptr [{b}+96]{{1to8}}",
        "vfmadd231pd zmm13, zmm24, qword ptr [{b}+104]{{1to8}}",
        "vfmadd231pd zmm14, zmm24, qword ptr [{b}+112]{{1to8}}",
        "vfmadd231pd zmm15, zmm24, qword ptr [{b}+120]{{1to8}}",
    )
}

/// 16 FMAs each reading a whole 64-byte vector from memory (a forward vectorised over the
/// betas with the data transposed: one load per multiply-add).
#[target_feature(enable = "avx512f")]
unsafe fn full_loads(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        "vfmadd231pd zmm0, zmm24, zmmword ptr [{b}]",
        "vfmadd231pd zmm1, zmm24, zmmword ptr [{b}+64]",
        "vfmadd231pd zmm2, zmm24, zmmword ptr [{b}+128]",
        "vfmadd231pd zmm3, zmm24, zmmword ptr [{b}+192]",
        "vfmadd231pd zmm4, zmm24, zmmword ptr [{b}+256]",
        "vfmadd231pd zmm5, zmm24, zmmword ptr [{b}+320]",
        "vfmadd231pd zmm6, zmm24, zmmword ptr [{b}+384]",
        "vfmadd231pd zmm7, zmm24, zmmword ptr [{b}+448]",
        "vfmadd231pd zmm8, zmm24, zmmword ptr [{b}+512]",
        "vfmadd231pd zmm9, zmm24, zmmword ptr [{b}+576]",
        "vfmadd231pd zmm10, zmm24, zmmword ptr [{b}+640]",
        "vfmadd231pd zmm11, zmm24, zmmword ptr [{b}+704]",
        "vfmadd231pd zmm12, zmm24, zmmword ptr [{b}+768]",
        "vfmadd231pd zmm13, zmm24, zmmword ptr [{b}+832]",
        "vfmadd231pd zmm14, zmm24, zmmword ptr [{b}+896]",
        "vfmadd231pd zmm15, zmm24, zmmword ptr [{b}+960]",
    )
}

/// The multiply-adds of one beta lane of the forward kernel's 8 x 8 block: its 16-column
/// data row loaded (two vectors), then 8 d values (one per degree, 64 bytes apart in the
/// block buffer at `{b} + 1024`) broadcast, each feeding two FMAs into the 16 sums.
macro_rules! fwd_lane {
    ($w:literal) => {
        fwd_lane!($w, "1024")
    };
    ($w:literal, $d:literal) => {
        concat!(
            "vmovupd zmm24, zmmword ptr [{b}+",
            $w,
            "*128]\n",
            "vmovupd zmm25, zmmword ptr [{b}+",
            $w,
            "*128+64]\n",
            "vbroadcastsd zmm16, qword ptr [{b}+",
            $d,
            "+0+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm0, zmm16, zmm24\n",
            "vfmadd231pd zmm1, zmm16, zmm25\n",
            "vbroadcastsd zmm17, qword ptr [{b}+",
            $d,
            "+64+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm2, zmm17, zmm24\n",
            "vfmadd231pd zmm3, zmm17, zmm25\n",
            "vbroadcastsd zmm18, qword ptr [{b}+",
            $d,
            "+128+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm4, zmm18, zmm24\n",
            "vfmadd231pd zmm5, zmm18, zmm25\n",
            "vbroadcastsd zmm19, qword ptr [{b}+",
            $d,
            "+192+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm6, zmm19, zmm24\n",
            "vfmadd231pd zmm7, zmm19, zmm25\n",
            "vbroadcastsd zmm20, qword ptr [{b}+",
            $d,
            "+256+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm8, zmm20, zmm24\n",
            "vfmadd231pd zmm9, zmm20, zmm25\n",
            "vbroadcastsd zmm21, qword ptr [{b}+",
            $d,
            "+320+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm10, zmm21, zmm24\n",
            "vfmadd231pd zmm11, zmm21, zmm25\n",
            "vbroadcastsd zmm22, qword ptr [{b}+",
            $d,
            "+384+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm12, zmm22, zmm24\n",
            "vfmadd231pd zmm13, zmm22, zmm25\n",
            "vbroadcastsd zmm23, qword ptr [{b}+",
            $d,
            "+448+",
            $w,
            "*8]\n",
            "vfmadd231pd zmm14, zmm23, zmm24\n",
            "vfmadd231pd zmm15, zmm23, zmm25\n",
        )
    };
}

/// One recurrence step, `zmm28 <- (a tau + c) zmm28 - zmm27` and `zmm27 <-` the old
/// `zmm28`, with `a`, `c` broadcast from the coefficient tables at `{b} + 2048` and `tau`
/// in `zmm29`.
macro_rules! rec_step {
    ($k:literal) => {
        concat!(
            "vbroadcastsd zmm26, qword ptr [{b}+2048+",
            $k,
            "*8]\n",
            "vfmadd213pd zmm26, zmm29, qword ptr [{b}+2112+",
            $k,
            "*8]{{1to8}}\n",
            "vfmsub213pd zmm26, zmm28, zmm27\n",
            "vmovapd zmm27, zmm28\n",
            "vmovapd zmm28, zmm26\n",
        )
    };
}

/// The forward kernel's step of the next vector: its current value stored to the other
/// block buffer (`{b} + 1536`), then [`rec_step`].
macro_rules! step {
    ($k:literal) => {
        step!($k, "1536")
    };
    ($k:literal, $s:literal) => {
        concat!(
            "vmovapd zmmword ptr [{b}+",
            $s,
            "+",
            $k,
            "*64], zmm28\n",
            rec_step!($k),
        )
    };
}

/// The forward kernel's 8 x 8 block without the recurrence: 8 lanes of [`fwd_lane`], 128
/// FMAs.
#[target_feature(enable = "avx512f")]
unsafe fn fwd_block(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        fwd_lane!(0),
        fwd_lane!(1),
        fwd_lane!(2),
        fwd_lane!(3),
        fwd_lane!(4),
        fwd_lane!(5),
        fwd_lane!(6),
        fwd_lane!(7),
    )
}

/// The forward kernel's 8 x 8 block as the kernel runs it: before each lane's multiply-adds,
/// one step of the next vector's recurrence (a dependency chain through the block).
#[target_feature(enable = "avx512f")]
unsafe fn fwd_block_steps(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        step!(0),
        fwd_lane!(0),
        step!(1),
        fwd_lane!(1),
        step!(2),
        fwd_lane!(2),
        step!(3),
        fwd_lane!(3),
        step!(4),
        fwd_lane!(4),
        step!(5),
        fwd_lane!(5),
        step!(6),
        fwd_lane!(6),
        step!(7),
        fwd_lane!(7),
    )
}

/// The multiply-adds of lanes `2 $q` and `2 $q + 1` of the 8-column forward block: both
/// 8-column rows (at `{b} + $r`) loaded and split into their even and odd columns, then
/// each degree's two d values (block at `{b} + $d`) broadcast as a pair (`vbroadcastf32x4`,
/// as the kernel does: the same 128 bits with AVX-512F alone), feeding one FMA
/// into the even and one into the odd sums.
macro_rules! fwd_pair8 {
    ($q:literal, $r:literal, $d:literal) => {
        concat!(
            "vmovupd zmm16, zmmword ptr [{b}+",
            $r,
            "+",
            $q,
            "*128]\n",
            "vmovupd zmm17, zmmword ptr [{b}+",
            $r,
            "+",
            $q,
            "*128+64]\n",
            "vunpcklpd zmm18, zmm16, zmm17\n",
            "vunpckhpd zmm19, zmm16, zmm17\n",
            "vbroadcastf32x4 zmm20, xmmword ptr [{b}+",
            $d,
            "+0+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm0, zmm20, zmm18\n",
            "vfmadd231pd zmm1, zmm20, zmm19\n",
            "vbroadcastf32x4 zmm21, xmmword ptr [{b}+",
            $d,
            "+64+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm2, zmm21, zmm18\n",
            "vfmadd231pd zmm3, zmm21, zmm19\n",
            "vbroadcastf32x4 zmm22, xmmword ptr [{b}+",
            $d,
            "+128+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm4, zmm22, zmm18\n",
            "vfmadd231pd zmm5, zmm22, zmm19\n",
            "vbroadcastf32x4 zmm23, xmmword ptr [{b}+",
            $d,
            "+192+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm6, zmm23, zmm18\n",
            "vfmadd231pd zmm7, zmm23, zmm19\n",
            "vbroadcastf32x4 zmm20, xmmword ptr [{b}+",
            $d,
            "+256+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm8, zmm20, zmm18\n",
            "vfmadd231pd zmm9, zmm20, zmm19\n",
            "vbroadcastf32x4 zmm21, xmmword ptr [{b}+",
            $d,
            "+320+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm10, zmm21, zmm18\n",
            "vfmadd231pd zmm11, zmm21, zmm19\n",
            "vbroadcastf32x4 zmm22, xmmword ptr [{b}+",
            $d,
            "+384+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm12, zmm22, zmm18\n",
            "vfmadd231pd zmm13, zmm22, zmm19\n",
            "vbroadcastf32x4 zmm23, xmmword ptr [{b}+",
            $d,
            "+448+",
            $q,
            "*16]\n",
            "vfmadd231pd zmm14, zmm23, zmm18\n",
            "vfmadd231pd zmm15, zmm23, zmm19\n",
        )
    };
}

/// Lane `$w` of the 8-column forward block without pairing: its row loaded, then for
/// each degree one FMA with the d value as an embedded broadcast, into the even lanes'
/// sums (`zmm0-7`, `$s = 0`) or the odd lanes' (`zmm8-15`, `$s = 1`), so that no sum
/// waits on the last.
macro_rules! fwd_lane8 {
    ($w:literal, 0) => {
        concat!(
            "vmovupd zmm16, zmmword ptr [{b}+",
            $w,
            "*64]\n",
            "vfmadd231pd zmm0, zmm16, qword ptr [{b}+1024+0+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm1, zmm16, qword ptr [{b}+1024+64+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm2, zmm16, qword ptr [{b}+1024+128+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm3, zmm16, qword ptr [{b}+1024+192+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm4, zmm16, qword ptr [{b}+1024+256+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm5, zmm16, qword ptr [{b}+1024+320+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm6, zmm16, qword ptr [{b}+1024+384+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm7, zmm16, qword ptr [{b}+1024+448+",
            $w,
            "*8]{{1to8}}\n",
        )
    };
    ($w:literal, 1) => {
        concat!(
            "vmovupd zmm16, zmmword ptr [{b}+",
            $w,
            "*64]\n",
            "vfmadd231pd zmm8, zmm16, qword ptr [{b}+1024+0+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm9, zmm16, qword ptr [{b}+1024+64+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm10, zmm16, qword ptr [{b}+1024+128+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm11, zmm16, qword ptr [{b}+1024+192+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm12, zmm16, qword ptr [{b}+1024+256+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm13, zmm16, qword ptr [{b}+1024+320+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm14, zmm16, qword ptr [{b}+1024+384+",
            $w,
            "*8]{{1to8}}\n",
            "vfmadd231pd zmm15, zmm16, qword ptr [{b}+1024+448+",
            $w,
            "*8]{{1to8}}\n",
        )
    };
}

/// A second vector's recurrence step for [`fwd8_two_chains`]: state `p0, p1, tau` in
/// `zmm24, zmm25, zmm30`, its value stored to its next block at `{b} + 2176` (the
/// coefficients are the first vector's; its current block is at `{b} + 2688`).
macro_rules! step_b {
    ($k:literal) => {
        concat!(
            "vmovapd zmmword ptr [{b}+2176+",
            $k,
            "*64], zmm25\n",
            "vbroadcastsd zmm31, qword ptr [{b}+2048+",
            $k,
            "*8]\n",
            "vfmadd213pd zmm31, zmm30, qword ptr [{b}+2112+",
            $k,
            "*8]{{1to8}}\n",
            "vfmsub213pd zmm31, zmm25, zmm24\n",
            "vmovapd zmm24, zmm25\n",
            "vmovapd zmm25, zmm31\n",
        )
    };
}

/// The 8-column forward block as the kernel runs it (paired lanes, 64 FMAs): two steps of
/// the next vector before each pair of lanes.
#[target_feature(enable = "avx512f")]
unsafe fn fwd8_block_steps(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        step!(0),
        step!(1),
        fwd_pair8!(0, 0, 1024),
        step!(2),
        step!(3),
        fwd_pair8!(1, 0, 1024),
        step!(4),
        step!(5),
        fwd_pair8!(2, 0, 1024),
        step!(6),
        step!(7),
        fwd_pair8!(3, 0, 1024),
    )
}

/// The 8-column forward block with one embedded broadcast per FMA ([`fwd_lane8`]) and
/// one step of the next vector per lane.
#[target_feature(enable = "avx512f")]
unsafe fn fwd8_embedded(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        step!(0),
        fwd_lane8!(0, 0),
        step!(1),
        fwd_lane8!(1, 1),
        step!(2),
        fwd_lane8!(2, 0),
        step!(3),
        fwd_lane8!(3, 1),
        step!(4),
        fwd_lane8!(4, 0),
        step!(5),
        fwd_lane8!(5, 1),
        step!(6),
        fwd_lane8!(6, 0),
        step!(7),
        fwd_lane8!(7, 1),
    )
}

/// The 8-column forward block for two vectors at a time (128 FMAs): the next two vectors'
/// steps, two independent chains, interleaved with the current two vectors' lanes.
#[target_feature(enable = "avx512f")]
unsafe fn fwd8_two_chains(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        step!(0),
        step_b!(0),
        step!(1),
        step_b!(1),
        fwd_pair8!(0, 0, 1024),
        fwd_pair8!(0, 512, 2688),
        step!(2),
        step_b!(2),
        step!(3),
        step_b!(3),
        fwd_pair8!(1, 0, 1024),
        fwd_pair8!(1, 512, 2688),
        step!(4),
        step_b!(4),
        step!(5),
        step_b!(5),
        fwd_pair8!(2, 0, 1024),
        fwd_pair8!(2, 512, 2688),
        step!(6),
        step_b!(6),
        step!(7),
        step_b!(7),
        fwd_pair8!(3, 0, 1024),
        fwd_pair8!(3, 512, 2688),
    )
}

/// [`fwd_block_steps`] for two vectors in turn, as the kernel runs them: each vector's d
/// values are stored during the previous vector's lanes and read back as broadcasts (the
/// two block buffers alternate), 256 FMAs.
#[target_feature(enable = "avx512f")]
unsafe fn fwd_block_alternating(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        step!(0, "1536"),
        fwd_lane!(0, "1024"),
        step!(1, "1536"),
        fwd_lane!(1, "1024"),
        step!(2, "1536"),
        fwd_lane!(2, "1024"),
        step!(3, "1536"),
        fwd_lane!(3, "1024"),
        step!(4, "1536"),
        fwd_lane!(4, "1024"),
        step!(5, "1536"),
        fwd_lane!(5, "1024"),
        step!(6, "1536"),
        fwd_lane!(6, "1024"),
        step!(7, "1536"),
        fwd_lane!(7, "1024"),
        step!(0, "1024"),
        fwd_lane!(0, "1536"),
        step!(1, "1024"),
        fwd_lane!(1, "1536"),
        step!(2, "1024"),
        fwd_lane!(2, "1536"),
        step!(3, "1024"),
        fwd_lane!(3, "1536"),
        step!(4, "1024"),
        fwd_lane!(4, "1536"),
        step!(5, "1024"),
        fwd_lane!(5, "1536"),
        step!(6, "1024"),
        fwd_lane!(6, "1536"),
        step!(7, "1024"),
        fwd_lane!(7, "1536"),
    )
}

/// One degree of the inverse kernel (16 columns): the step, then 16 FMAs of the value
/// vector with the embedded broadcasts of the degree's coefficient row (`{b} + 128 k`).
macro_rules! inv_degree {
    ($k:literal) => {
        concat!(
            rec_step!($k),
            "vfmadd231pd zmm0, zmm27, qword ptr [{b}+",
            $k,
            "*128]{{1to8}}\n",
            "vfmadd231pd zmm1, zmm27, qword ptr [{b}+",
            $k,
            "*128+8]{{1to8}}\n",
            "vfmadd231pd zmm2, zmm27, qword ptr [{b}+",
            $k,
            "*128+16]{{1to8}}\n",
            "vfmadd231pd zmm3, zmm27, qword ptr [{b}+",
            $k,
            "*128+24]{{1to8}}\n",
            "vfmadd231pd zmm4, zmm27, qword ptr [{b}+",
            $k,
            "*128+32]{{1to8}}\n",
            "vfmadd231pd zmm5, zmm27, qword ptr [{b}+",
            $k,
            "*128+40]{{1to8}}\n",
            "vfmadd231pd zmm6, zmm27, qword ptr [{b}+",
            $k,
            "*128+48]{{1to8}}\n",
            "vfmadd231pd zmm7, zmm27, qword ptr [{b}+",
            $k,
            "*128+56]{{1to8}}\n",
            "vfmadd231pd zmm8, zmm27, qword ptr [{b}+",
            $k,
            "*128+64]{{1to8}}\n",
            "vfmadd231pd zmm9, zmm27, qword ptr [{b}+",
            $k,
            "*128+72]{{1to8}}\n",
            "vfmadd231pd zmm10, zmm27, qword ptr [{b}+",
            $k,
            "*128+80]{{1to8}}\n",
            "vfmadd231pd zmm11, zmm27, qword ptr [{b}+",
            $k,
            "*128+88]{{1to8}}\n",
            "vfmadd231pd zmm12, zmm27, qword ptr [{b}+",
            $k,
            "*128+96]{{1to8}}\n",
            "vfmadd231pd zmm13, zmm27, qword ptr [{b}+",
            $k,
            "*128+104]{{1to8}}\n",
            "vfmadd231pd zmm14, zmm27, qword ptr [{b}+",
            $k,
            "*128+112]{{1to8}}\n",
            "vfmadd231pd zmm15, zmm27, qword ptr [{b}+",
            $k,
            "*128+120]{{1to8}}\n",
        )
    };
}

/// Eight degrees of the inverse kernel ([`inv_degree`]), 128 FMAs.
#[target_feature(enable = "avx512f")]
unsafe fn inv_degrees(n: usize, b: *mut f64) {
    asm_loop!(
        n,
        b,
        inv_degree!(0),
        inv_degree!(1),
        inv_degree!(2),
        inv_degree!(3),
        inv_degree!(4),
        inv_degree!(5),
        inv_degree!(6),
        inv_degree!(7),
    )
}

#[test]
#[ignore]
fn instruction_ceilings() {
    if !std::is_x86_feature_detected!("avx512f") {
        println!("no AVX-512 on this machine: nothing to measure");
        return;
    }
    // L1-resident data: rows (bytes 0..1024), two block buffers (..2048), recurrence
    // coefficients `a = 0`, `c = 1` (..2176): the steps `p2 = p1 - p0` cycle with period 6,
    // so no value overflows or turns subnormal; a second vector's two blocks (..3200).
    let mut mem = vec![1.0e-3f64; 512 + 8];
    let base = mem.as_mut_ptr();
    let off = (64 - (base as usize % 64)) / 8 % 8;
    mem[off + 256..off + 264].fill(0.0);
    mem[off + 264..off + 272].fill(1.0);
    let b = unsafe { mem.as_mut_ptr().add(off) };
    let loops: [(&str, Loop, usize); 12] = [
        ("16 FMAs, register operands (the peak)", regs, 16),
        ("broadcast load + 2 FMAs (forward lane)", bcast_two, 16),
        ("FMAs with {1to8} memory operands", embedded, 16),
        ("FMAs with 64-byte memory operands", full_loads, 16),
        ("forward 8x8 block, no recurrence", fwd_block, 128),
        ("forward 8x8 block with its 8 steps", fwd_block_steps, 128),
        (
            "the same, d blocks read back after storing",
            fwd_block_alternating,
            256,
        ),
        (
            "forward 8-column block with its 8 steps",
            fwd8_block_steps,
            64,
        ),
        (
            "the same, two vectors (two chains) at once",
            fwd8_two_chains,
            128,
        ),
        ("8 columns, embedded broadcasts, 16 sums", fwd8_embedded, 64),
        ("inverse, 8 degrees of step + 16 FMAs", inv_degrees, 128),
        ("16 FMAs, register operands (again)", regs, 16),
    ];
    let iters = 4_000_000;
    let rate = |f: Loop, fmas: usize| {
        (0..7)
            .map(|_| {
                let t = Instant::now();
                // SAFETY: AVX-512 is present; the loops read and write only `mem`.
                unsafe { f(iters * 16 / fmas, b) };
                (iters * 16 * 16) as f64 / t.elapsed().as_secs_f64() / 1e9
            })
            .fold(0.0, f64::max)
    };
    let peak = rate(regs, 16);
    println!("FMA peak {peak:.1} GFLOP/s (one core, best of 7)");
    for (name, f, fmas) in loops {
        let g = rate(f, fmas);
        println!(
            "{name:<42} {g:6.1} GFLOP/s {:5.1}% of the peak",
            100.0 * g / peak
        );
    }
}
