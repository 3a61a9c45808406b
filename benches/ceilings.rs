//! Instruction-mix ceilings of this machine for the DWT kernels.
//!
//! Hand-written AVX-512 loops, data in L1, no dependencies beyond what the mix itself
//! needs: each gives the fraction of the FMA peak that a kernel built from that mix could
//! reach at best. They are the evidence behind the DWT targets in `notes/next-steps.md`.
//! A second table does the same for the AVX2 kernels' mixes (`ymm0-15` only, against the
//! AVX2 peak).
//!
//! `cargo bench --features internals --bench ceilings` (x86_64: the AVX-512 table where
//! AVX-512F is available, the AVX2 table where AVX2 and FMA are; elsewhere it prints a
//! message and exits).

#![warn(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]

fn main() {
    #[cfg(target_arch = "x86_64")]
    x86::instruction_ceilings();
    #[cfg(not(target_arch = "x86_64"))]
    println!(
        "ceilings: hand-written x86_64 AVX-512 and AVX2 loops; nothing to measure on this target"
    );
}

/// The loops and their driver.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::asm;
    use std::time::Instant;

    /// Bytes of the L1-resident buffer every loop reads and writes.
    const BUFFER_BYTES: usize = 4096;

    /// One timed loop: `iters` iterations of `fmas` useful FMAs each.
    type Loop = unsafe fn(usize, *mut f64) -> ();

    /// Expands to an `asm!` loop of `$body` run `$n` times, `{b}` the data pointer (L1
    /// resident), with every vector register clobbered.
    macro_rules! asm_loop {
        ($n:expr, $b:expr, $($body:expr),+ $(,)?) => {
            // SAFETY: the caller of the enclosing `unsafe fn` guarantees AVX-512F and a private
            // buffer of `BUFFER_BYTES` bytes at `{b}`; the loops touch only offsets below 3200
            // bytes of it, use no stack, and every vector register they write is declared
            // clobbered.
            unsafe { asm!(
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
            ) }
        };
    }

    /// 16 independent FMAs on registers: the peak.
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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

    /// Degree `$j64 / 64` of [`fwd_lane`]: the d value of lane `$w` (block at `{b} + $d`)
    /// broadcast into `zmm$e`, times the row (`zmm24`, `zmm25`) into the sums `zmm$a`, `zmm$c`.
    macro_rules! fwd_degree {
        ($d:literal, $w:literal, $j64:literal, $e:literal, $a:literal, $c:literal) => {
            concat!(
                "vbroadcastsd zmm",
                $e,
                ", qword ptr [{b}+",
                $d,
                "+",
                $j64,
                "+",
                $w,
                "*8]\n",
                "vfmadd231pd zmm",
                $a,
                ", zmm",
                $e,
                ", zmm24\n",
                "vfmadd231pd zmm",
                $c,
                ", zmm",
                $e,
                ", zmm25\n",
            )
        };
    }

    /// Degree `$j64 / 64` of [`fwd_pair8`]: the d values of lanes `2 $q`, `2 $q + 1` (block at
    /// `{b} + $d`) broadcast as a pair into `zmm$e`, times the even (`zmm18`) and odd
    /// (`zmm19`) columns into the sums `zmm$a`, `zmm$c`.
    macro_rules! pair_degree {
        ($d:literal, $q:literal, $j64:literal, $e:literal, $a:literal, $c:literal) => {
            concat!(
                "vbroadcastf32x4 zmm",
                $e,
                ", xmmword ptr [{b}+",
                $d,
                "+",
                $j64,
                "+",
                $q,
                "*16]\n",
                "vfmadd231pd zmm",
                $a,
                ", zmm",
                $e,
                ", zmm18\n",
                "vfmadd231pd zmm",
                $c,
                ", zmm",
                $e,
                ", zmm19\n",
            )
        };
    }

    /// `zmm$a += zmm$x * [{b} + $off]{1to8}` (an embedded broadcast).
    macro_rules! emb_fma {
        ($a:literal, $x:literal, $off:expr) => {
            concat!(
                "vfmadd231pd zmm",
                $a,
                ", zmm",
                $x,
                ", qword ptr [{b}+",
                $off,
                "]{{1to8}}\n"
            )
        };
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
                fwd_degree!($d, $w, "0", "16", "0", "1"),
                fwd_degree!($d, $w, "64", "17", "2", "3"),
                fwd_degree!($d, $w, "128", "18", "4", "5"),
                fwd_degree!($d, $w, "192", "19", "6", "7"),
                fwd_degree!($d, $w, "256", "20", "8", "9"),
                fwd_degree!($d, $w, "320", "21", "10", "11"),
                fwd_degree!($d, $w, "384", "22", "12", "13"),
                fwd_degree!($d, $w, "448", "23", "14", "15"),
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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

    /// The forward block as the kernel runs it: before each lane's multiply-adds
    /// ([`fwd_lane`], d block at `{b} + $d`), one step of the next vector ([`step`], stored to
    /// `{b} + $s`).
    macro_rules! stepped_block {
        ($s:literal, $d:literal) => {
            concat!(
                step!(0, $s),
                fwd_lane!(0, $d),
                step!(1, $s),
                fwd_lane!(1, $d),
                step!(2, $s),
                fwd_lane!(2, $d),
                step!(3, $s),
                fwd_lane!(3, $d),
                step!(4, $s),
                fwd_lane!(4, $d),
                step!(5, $s),
                fwd_lane!(5, $d),
                step!(6, $s),
                fwd_lane!(6, $d),
                step!(7, $s),
                fwd_lane!(7, $d),
            )
        };
    }

    /// The forward kernel's 8 x 8 block as the kernel runs it: before each lane's multiply-adds,
    /// one step of the next vector's recurrence (a dependency chain through the block).
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
    #[target_feature(enable = "avx512f")]
    unsafe fn fwd_block_steps(n: usize, b: *mut f64) {
        asm_loop!(n, b, stepped_block!("1536", "1024"))
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
                pair_degree!($d, $q, "0", "20", "0", "1"),
                pair_degree!($d, $q, "64", "21", "2", "3"),
                pair_degree!($d, $q, "128", "22", "4", "5"),
                pair_degree!($d, $q, "192", "23", "6", "7"),
                pair_degree!($d, $q, "256", "20", "8", "9"),
                pair_degree!($d, $q, "320", "21", "10", "11"),
                pair_degree!($d, $q, "384", "22", "12", "13"),
                pair_degree!($d, $q, "448", "23", "14", "15"),
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
                emb_fma!("0", "16", concat!("1024+0+", $w, "*8")),
                emb_fma!("1", "16", concat!("1024+64+", $w, "*8")),
                emb_fma!("2", "16", concat!("1024+128+", $w, "*8")),
                emb_fma!("3", "16", concat!("1024+192+", $w, "*8")),
                emb_fma!("4", "16", concat!("1024+256+", $w, "*8")),
                emb_fma!("5", "16", concat!("1024+320+", $w, "*8")),
                emb_fma!("6", "16", concat!("1024+384+", $w, "*8")),
                emb_fma!("7", "16", concat!("1024+448+", $w, "*8")),
            )
        };
        ($w:literal, 1) => {
            concat!(
                "vmovupd zmm16, zmmword ptr [{b}+",
                $w,
                "*64]\n",
                emb_fma!("8", "16", concat!("1024+0+", $w, "*8")),
                emb_fma!("9", "16", concat!("1024+64+", $w, "*8")),
                emb_fma!("10", "16", concat!("1024+128+", $w, "*8")),
                emb_fma!("11", "16", concat!("1024+192+", $w, "*8")),
                emb_fma!("12", "16", concat!("1024+256+", $w, "*8")),
                emb_fma!("13", "16", concat!("1024+320+", $w, "*8")),
                emb_fma!("14", "16", concat!("1024+384+", $w, "*8")),
                emb_fma!("15", "16", concat!("1024+448+", $w, "*8")),
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
    #[target_feature(enable = "avx512f")]
    unsafe fn fwd_block_alternating(n: usize, b: *mut f64) {
        asm_loop!(
            n,
            b,
            stepped_block!("1536", "1024"),
            stepped_block!("1024", "1536"),
        )
    }

    /// One degree of the inverse kernel (16 columns): the step, then 16 FMAs of the value
    /// vector with the embedded broadcasts of the degree's coefficient row (`{b} + 128 k`).
    macro_rules! inv_degree {
        ($k:literal) => {
            concat!(
                rec_step!($k),
                emb_fma!("0", "27", concat!($k, "*128+0")),
                emb_fma!("1", "27", concat!($k, "*128+8")),
                emb_fma!("2", "27", concat!($k, "*128+16")),
                emb_fma!("3", "27", concat!($k, "*128+24")),
                emb_fma!("4", "27", concat!($k, "*128+32")),
                emb_fma!("5", "27", concat!($k, "*128+40")),
                emb_fma!("6", "27", concat!($k, "*128+48")),
                emb_fma!("7", "27", concat!($k, "*128+56")),
                emb_fma!("8", "27", concat!($k, "*128+64")),
                emb_fma!("9", "27", concat!($k, "*128+72")),
                emb_fma!("10", "27", concat!($k, "*128+80")),
                emb_fma!("11", "27", concat!($k, "*128+88")),
                emb_fma!("12", "27", concat!($k, "*128+96")),
                emb_fma!("13", "27", concat!($k, "*128+104")),
                emb_fma!("14", "27", concat!($k, "*128+112")),
                emb_fma!("15", "27", concat!($k, "*128+120")),
            )
        };
    }

    /// Eight degrees of the inverse kernel ([`inv_degree`]), 128 FMAs.
    ///
    /// # Safety
    /// AVX-512F must be available, and `b` must point to a 64-byte aligned buffer of
    /// [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
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

    /// The AVX2 loops: 4 doubles per vector, only `ymm0-15` (as on a CPU without AVX-512).
    ///
    /// Their buffer (the same as the AVX-512 loops'): coefficient rows or data rows (bytes
    /// 0..1024), the inverse's buffer of d values and the forward's two d blocks (1024..1664),
    /// the recurrence coefficients `a = 0`, `c = 1` (2048..2176), the `tau` vectors of two
    /// chains (3584..3648).
    mod avx2 {
        use super::Loop;
        use std::arch::asm;

        /// Sets every ymm register to the buffer's first value (a clobbered register may hold
        /// anything).
        macro_rules! ymm_init {
            () => {
                concat!(
                    "vbroadcastsd ymm0, qword ptr [{b}]\n",
                    "vbroadcastsd ymm1, qword ptr [{b}]\n",
                    "vbroadcastsd ymm2, qword ptr [{b}]\n",
                    "vbroadcastsd ymm3, qword ptr [{b}]\n",
                    "vbroadcastsd ymm4, qword ptr [{b}]\n",
                    "vbroadcastsd ymm5, qword ptr [{b}]\n",
                    "vbroadcastsd ymm6, qword ptr [{b}]\n",
                    "vbroadcastsd ymm7, qword ptr [{b}]\n",
                    "vbroadcastsd ymm8, qword ptr [{b}]\n",
                    "vbroadcastsd ymm9, qword ptr [{b}]\n",
                    "vbroadcastsd ymm10, qword ptr [{b}]\n",
                    "vbroadcastsd ymm11, qword ptr [{b}]\n",
                    "vbroadcastsd ymm12, qword ptr [{b}]\n",
                    "vbroadcastsd ymm13, qword ptr [{b}]\n",
                    "vbroadcastsd ymm14, qword ptr [{b}]\n",
                    "vbroadcastsd ymm15, qword ptr [{b}]\n",
                )
            };
        }

        /// [`asm_loop`] for AVX2: an `asm!` loop of `$body` run `$n` times, `{b}` the data
        /// pointer (L1 resident), with `ymm0-15` clobbered. With `stack:` first, the loop also
        /// gets 256 bytes of 32-byte aligned stack at `rsp` (below the red zone), its 8 vectors
        /// set to the registers' starting value.
        macro_rules! asm_loop_avx2 {
            (stack: $n:expr, $b:expr, $($body:expr),+ $(,)?) => {
                // SAFETY: as in the first arm; the stack area is below the stack pointer on entry
                // minus the red zone (`rsp` moves down 384 bytes, then to a multiple of 32, before
                // anything is written, and is restored from `{sp}` before the block ends), so it
                // overwrites nothing of the caller's.
                unsafe { asm!(
                    "mov {sp}, rsp",
                    "sub rsp, 384",
                    "and rsp, -32",
                    ymm_init!(),
                    "vmovapd ymmword ptr [rsp], ymm0",
                    "vmovapd ymmword ptr [rsp+32], ymm0",
                    "vmovapd ymmword ptr [rsp+64], ymm0",
                    "vmovapd ymmword ptr [rsp+96], ymm0",
                    "vmovapd ymmword ptr [rsp+128], ymm0",
                    "vmovapd ymmword ptr [rsp+160], ymm0",
                    "vmovapd ymmword ptr [rsp+192], ymm0",
                    "vmovapd ymmword ptr [rsp+224], ymm0",
                    "2:",
                    $($body,)+
                    "dec {n}",
                    "jnz 2b",
                    "mov rsp, {sp}",
                    "vzeroupper",
                    n = inout(reg) $n => _,
                    b = in(reg) $b,
                    sp = out(reg) _,
                    out("ymm0") _, out("ymm1") _, out("ymm2") _, out("ymm3") _,
                    out("ymm4") _, out("ymm5") _, out("ymm6") _, out("ymm7") _,
                    out("ymm8") _, out("ymm9") _, out("ymm10") _, out("ymm11") _,
                    out("ymm12") _, out("ymm13") _, out("ymm14") _, out("ymm15") _,
                ) }
            };
            ($n:expr, $b:expr, $($body:expr),+ $(,)?) => {
                // SAFETY: the caller of the enclosing `unsafe fn` guarantees AVX2 and FMA and a
                // private buffer of `BUFFER_BYTES` bytes at `{b}`; the loops touch only offsets
                // below 3648 bytes of it, use no stack, and every vector register they write is
                // declared clobbered (`vzeroupper` leaves the upper halves clean for SSE code).
                unsafe { asm!(
                    ymm_init!(),
                    "2:",
                    $($body,)+
                    "dec {n}",
                    "jnz 2b",
                    "vzeroupper",
                    n = inout(reg) $n => _,
                    b = in(reg) $b,
                    out("ymm0") _, out("ymm1") _, out("ymm2") _, out("ymm3") _,
                    out("ymm4") _, out("ymm5") _, out("ymm6") _, out("ymm7") _,
                    out("ymm8") _, out("ymm9") _, out("ymm10") _, out("ymm11") _,
                    out("ymm12") _, out("ymm13") _, out("ymm14") _, out("ymm15") _,
                    options(nostack),
                ) }
            };
        }

        /// `ymm$a += ymm$x * ymm$y`.
        macro_rules! fma_y {
            ($a:literal, $x:literal, $y:literal) => {
                concat!("vfmadd231pd ymm", $a, ", ymm", $x, ", ymm", $y, "\n")
            };
        }

        /// `ymm$r <-` the double at `{b} + $off` in every lane.
        macro_rules! bcast_y {
            ($r:literal, $off:expr) => {
                concat!("vbroadcastsd ymm", $r, ", qword ptr [{b}+", $off, "]\n")
            };
        }

        /// `ymm$a += ymm$v * [{b} + $off]` broadcast (through `ymm8`).
        macro_rules! bfma_y {
            ($a:literal, $v:literal, $off:expr) => {
                concat!(bcast_y!("8", $off), fma_y!($a, $v, "8"))
            };
        }

        /// One recurrence step of degree `$k`, `t = a tau + c` with `a`, `c` broadcast from the
        /// coefficient tables (`{b} + 2048`, `+ 2112`; `c` through `ymm$c`) and `tau` the
        /// operand `$tau` (a register, or a vector in memory where the registers run out), then
        /// `ymm$p1 <- t ymm$p1 - ymm$p0` and `ymm$p0 <-` the old `ymm$p1` (the value of the
        /// degree, for the multiply-adds that follow). `ymm15` holds `t`.
        macro_rules! step_y {
            ($k:literal, $p0:literal, $p1:literal, $c:literal, $tau:literal) => {
                concat!(
                    bcast_y!("15", concat!("2048+", $k, "*8")),
                    bcast_y!($c, concat!("2112+", $k, "*8")),
                    "vfmadd132pd ymm15, ymm",
                    $c,
                    ", ",
                    $tau,
                    "\n",
                    "vfmsub213pd ymm15, ymm",
                    $p1,
                    ", ymm",
                    $p0,
                    "\n",
                    "vmovapd ymm",
                    $p0,
                    ", ymm",
                    $p1,
                    "\n",
                    "vmovapd ymm",
                    $p1,
                    ", ymm15\n",
                )
            };
        }

        /// 8 multiply-adds of the value `ymm$v` with a row of 8 coefficients at `{b} + $row`
        /// (broadcast loads) into the sums `ymm0-7`.
        macro_rules! row8 {
            ($v:literal, $row:expr) => {
                concat!(
                    bfma_y!("0", $v, concat!($row, "+0")),
                    bfma_y!("1", $v, concat!($row, "+8")),
                    bfma_y!("2", $v, concat!($row, "+16")),
                    bfma_y!("3", $v, concat!($row, "+24")),
                    bfma_y!("4", $v, concat!($row, "+32")),
                    bfma_y!("5", $v, concat!($row, "+40")),
                    bfma_y!("6", $v, concat!($row, "+48")),
                    bfma_y!("7", $v, concat!($row, "+56")),
                )
            };
        }

        /// 12 independent FMAs on registers: the peak (`fma_peak(Isa::Avx2)`'s 12 chains).
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn regs(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                fma_y!("0", "12", "14"),
                fma_y!("1", "12", "15"),
                fma_y!("2", "13", "14"),
                fma_y!("3", "13", "15"),
                fma_y!("4", "12", "14"),
                fma_y!("5", "12", "15"),
                fma_y!("6", "13", "14"),
                fma_y!("7", "13", "15"),
                fma_y!("8", "12", "14"),
                fma_y!("9", "12", "15"),
                fma_y!("10", "13", "14"),
                fma_y!("11", "13", "15"),
            )
        }

        /// Degree `$k` of the 16-column inverse's first pass: the step (`p0, p1, tau` in
        /// `ymm12, ymm13, ymm14`), the value times columns 0..8 of the degree's row
        /// (`{b} + 128 k`), the value stored to the buffer of d values (`{b} + 1024 + 32 k`).
        macro_rules! pass1 {
            ($k:literal) => {
                concat!(
                    step_y!($k, "12", "13", "9", "ymm14"),
                    row8!("12", concat!($k, "*128")),
                    "vmovapd ymmword ptr [{b}+1024+",
                    $k,
                    "*32], ymm12\n",
                )
            };
        }

        /// Degree `$k` of the 16-column inverse's second pass: the value read back (into
        /// `ymm10`, clear of the first pass's recurrence) times columns 8..16 of the row.
        macro_rules! pass2 {
            ($k:literal) => {
                concat!(
                    "vmovapd ymm10, ymmword ptr [{b}+1024+",
                    $k,
                    "*32]\n",
                    row8!("10", concat!($k, "*128+64")),
                )
            };
        }

        /// The AVX2 inverse kernel's first pass over 16 columns (`two_passes`), 8 degrees:
        /// per degree 2 broadcasts and the step (a chain across degrees), 8 broadcast loads and
        /// FMAs with the previous value, and that value stored. 64 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn inv_pass1(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                pass1!(0),
                pass1!(1),
                pass1!(2),
                pass1!(3),
                pass1!(4),
                pass1!(5),
                pass1!(6),
                pass1!(7),
            )
        }

        /// The AVX2 inverse kernel's second pass over 16 columns, 8 degrees: per degree one
        /// vector load of the stored value and 8 broadcast loads and FMAs. 64 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn inv_pass2(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                pass2!(0),
                pass2!(1),
                pass2!(2),
                pass2!(3),
                pass2!(4),
                pass2!(5),
                pass2!(6),
                pass2!(7),
            )
        }

        /// The whole 16-column AVX2 inverse: 8 degrees of the first pass, then the same 8
        /// degrees of the second (reading back what the first stored), as the kernel runs
        /// blocks of degrees. Both passes add into `ymm0-7` (the kernel keeps each half's sums
        /// in memory between its blocks). 128 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn inv_passes(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                pass1!(0),
                pass1!(1),
                pass1!(2),
                pass1!(3),
                pass1!(4),
                pass1!(5),
                pass1!(6),
                pass1!(7),
                pass2!(0),
                pass2!(1),
                pass2!(2),
                pass2!(3),
                pass2!(4),
                pass2!(5),
                pass2!(6),
                pass2!(7),
            )
        }

        /// Degree `$k` of the 8-column inverse: the step, the value times the degree's row of
        /// 8 (`{b} + 64 k`).
        macro_rules! inv8 {
            ($k:literal) => {
                concat!(
                    step_y!($k, "12", "13", "9", "ymm14"),
                    row8!("12", concat!($k, "*64")),
                )
            };
        }

        /// The AVX2 inverse kernel over 8 columns, one vector of betas, 8 degrees: per degree
        /// 2 broadcasts and the step (a chain), 8 broadcast loads and FMAs. 64 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn inv8(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                inv8!(0),
                inv8!(1),
                inv8!(2),
                inv8!(3),
                inv8!(4),
                inv8!(5),
                inv8!(6),
                inv8!(7),
            )
        }

        /// The forward kernel's step of the next vector of betas: its value (`ymm13`) stored
        /// as row `$j` of the next d block (`{b} + $dn`), then [`step_y`] of degree `$k`.
        macro_rules! store_step {
            ($dn:literal, $j:literal, $k:literal, $c:literal, $tau:literal) => {
                concat!(
                    "vmovapd ymmword ptr [{b}+",
                    $dn,
                    "+",
                    $j,
                    "*32], ymm13\n",
                    step_y!($k, "12", "13", $c, $tau),
                )
            };
        }

        /// Lane `$w` of the 16-column forward block (2 degrees): its data row (`{b} + $row +
        /// 128 w`) loaded as 4 vectors, the lane's d value of each degree (block at `{b} + $d`)
        /// broadcast, each feeding 4 FMAs into the sums `ymm0-7`.
        macro_rules! lane16 {
            ($row:literal, $d:literal, $w:literal) => {
                concat!(
                    "vmovupd ymm8, ymmword ptr [{b}+",
                    $row,
                    "+",
                    $w,
                    "*128]\n",
                    "vmovupd ymm9, ymmword ptr [{b}+",
                    $row,
                    "+",
                    $w,
                    "*128+32]\n",
                    "vmovupd ymm10, ymmword ptr [{b}+",
                    $row,
                    "+",
                    $w,
                    "*128+64]\n",
                    "vmovupd ymm11, ymmword ptr [{b}+",
                    $row,
                    "+",
                    $w,
                    "*128+96]\n",
                    bcast_y!("14", concat!($d, "+", $w, "*8")),
                    fma_y!("0", "14", "8"),
                    fma_y!("1", "14", "9"),
                    fma_y!("2", "14", "10"),
                    fma_y!("3", "14", "11"),
                    bcast_y!("14", concat!($d, "+32+", $w, "*8")),
                    fma_y!("4", "14", "8"),
                    fma_y!("5", "14", "9"),
                    fma_y!("6", "14", "10"),
                    fma_y!("7", "14", "11"),
                )
            };
        }

        /// One vector of betas through the 16-column forward block: 4 lanes of [`lane16`], with
        /// the next vector's 2 steps before lanes 1 and 3 (as the kernel spreads them). With
        /// 16 registers taken by the sums, the row, the broadcast and the recurrence, `tau` is
        /// a memory operand (`{b} + 3584`); `c` goes through the broadcast's register.
        macro_rules! fwd16_vector {
            ($row:literal, $d:literal, $dn:literal, $k0:literal, $k1:literal) => {
                concat!(
                    lane16!($row, $d, 0),
                    store_step!($dn, 0, $k0, "14", "ymmword ptr [{b}+3584]"),
                    lane16!($row, $d, 1),
                    lane16!($row, $d, 2),
                    store_step!($dn, 1, $k1, "14", "ymmword ptr [{b}+3584]"),
                    lane16!($row, $d, 3),
                )
            };
        }

        /// The AVX2 forward kernel over 16 columns (degree block of 2), two vectors of betas in
        /// turn, each reading the d block the previous one's steps stored (the two block
        /// buffers alternate): per lane 4 vector loads, 2 broadcasts and 8 FMAs, per vector
        /// also 2 steps (a chain) and 2 stores. 64 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn fwd16(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                fwd16_vector!("0", "1024", "1536", "0", "1"),
                fwd16_vector!("512", "1536", "1024", "2", "3"),
            )
        }

        /// Degree `$j` of lane `$w` of the 8-column forward block: the d value (block at
        /// `{b} + $d`) broadcast into `ymm14`, times the row (`ymm8`, `ymm9`) into the sums
        /// `ymm$a`, `ymm$c`.
        macro_rules! fwd8_degree {
            ($d:literal, $w:literal, $j:literal, $a:literal, $c:literal) => {
                concat!(
                    bcast_y!("14", concat!($d, "+", $j, "*32+", $w, "*8")),
                    fma_y!($a, "14", "8"),
                    fma_y!($c, "14", "9"),
                )
            };
        }

        /// Lane `$w` of the 8-column forward block (4 degrees), after one step of the next
        /// vector (`tau` in `ymm11`, `c` through `ymm10`): the data row (`{b} + $row + 64 w`)
        /// loaded as 2 vectors, then 4 broadcasts, each feeding 2 FMAs.
        macro_rules! lane8 {
            ($row:literal, $d:literal, $dn:literal, $w:literal, $k:literal) => {
                concat!(
                    store_step!($dn, $w, $k, "10", "ymm11"),
                    "vmovupd ymm8, ymmword ptr [{b}+",
                    $row,
                    "+",
                    $w,
                    "*64]\n",
                    "vmovupd ymm9, ymmword ptr [{b}+",
                    $row,
                    "+",
                    $w,
                    "*64+32]\n",
                    fwd8_degree!($d, $w, 0, "0", "1"),
                    fwd8_degree!($d, $w, 1, "2", "3"),
                    fwd8_degree!($d, $w, 2, "4", "5"),
                    fwd8_degree!($d, $w, 3, "6", "7"),
                )
            };
        }

        /// The AVX2 forward kernel over 8 columns (degree block of 4), two vectors of betas in
        /// turn as in [`fwd16`]: per lane 2 vector loads, 4 broadcasts and 8 FMAs, and one
        /// step (a chain) and store of the next vector. 64 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn fwd8(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                lane8!("0", "1024", "1536", 0, 0),
                lane8!("0", "1024", "1536", 1, 1),
                lane8!("0", "1024", "1536", 2, 2),
                lane8!("0", "1024", "1536", 3, 3),
                lane8!("512", "1536", "1024", 0, 4),
                lane8!("512", "1536", "1024", 1, 5),
                lane8!("512", "1536", "1024", 2, 6),
                lane8!("512", "1536", "1024", 3, 7),
            )
        }

        /// The coefficients of degree `$k` shared by the parity kernel's chains: `a` in
        /// `ymm12`, `c` in `ymm13`.
        macro_rules! coefs {
            ($k:literal) => {
                concat!(
                    bcast_y!("12", concat!("2048+", $k, "*8")),
                    bcast_y!("13", concat!("2112+", $k, "*8")),
                )
            };
        }

        /// One chain's step with the shared coefficients ([`coefs`]): `t = a tau + c` with
        /// `tau` a vector in memory (`{b} + $tau`: two chains' `tau` do not fit the registers
        /// beside their sums), `ymm$p1 <- t ymm$p1 - ymm$p0`, `ymm$p0 <-` the old `ymm$p1`.
        macro_rules! chain_step {
            ($p0:literal, $p1:literal, $tau:literal) => {
                concat!(
                    "vmovapd ymm15, ymm13\n",
                    "vfmadd231pd ymm15, ymm12, ymmword ptr [{b}+",
                    $tau,
                    "]\n",
                    "vfmsub213pd ymm15, ymm",
                    $p1,
                    ", ymm",
                    $p0,
                    "\n",
                    "vmovapd ymm",
                    $p0,
                    ", ymm",
                    $p1,
                    "\n",
                    "vmovapd ymm",
                    $p1,
                    ", ymm15\n",
                )
            };
        }

        /// Degree `$k` of the 2-column parity kernel with 2 chains (`p0, p1` in `ymm8, ymm9`
        /// and `ymm10, ymm11`): the coefficients, both steps, then each column's coefficient
        /// (`{b} + 16 k`) broadcast and multiplied by both chains' values into the sums of the
        /// degree's parity: `ymm$a`, `ymm$c` (chain 0), `ymm$e`, `ymm$f` (chain 1).
        macro_rules! par2 {
            ($k:literal, $a:literal, $c:literal, $e:literal, $f:literal) => {
                concat!(
                    coefs!($k),
                    chain_step!("8", "9", "3584"),
                    chain_step!("10", "11", "3616"),
                    bcast_y!("14", concat!($k, "*16")),
                    fma_y!($a, "8", "14"),
                    fma_y!($e, "10", "14"),
                    bcast_y!("14", concat!($k, "*16+8")),
                    fma_y!($c, "8", "14"),
                    fma_y!($f, "10", "14"),
                )
            };
        }

        /// The AVX2 S^2 parity kernel (`m' = 0`), 2 columns and 2 chains, 8 degrees: per
        /// degree 2 broadcasts of coefficients, per chain a step (a chain across degrees),
        /// 2 broadcasts of data and 4 FMAs into the 8 sums (2 columns x 2 parities x 2 chains).
        /// 32 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn parity2(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                par2!(0, "0", "1", "4", "5"),
                par2!(1, "2", "3", "6", "7"),
                par2!(2, "0", "1", "4", "5"),
                par2!(3, "2", "3", "6", "7"),
                par2!(4, "0", "1", "4", "5"),
                par2!(5, "2", "3", "6", "7"),
                par2!(6, "0", "1", "4", "5"),
                par2!(7, "2", "3", "6", "7"),
            )
        }

        /// `[$base + $off] += ymm$v * ymm14` through `ymm13` (a sum kept in memory: a load and
        /// a store per update).
        macro_rules! mem_fma {
            ($base:literal, $off:expr, $v:literal) => {
                concat!(
                    "vmovapd ymm13, ymmword ptr [",
                    $base,
                    "+",
                    $off,
                    "]\n",
                    fma_y!("13", $v, "14"),
                    "vmovapd ymmword ptr [",
                    $base,
                    "+",
                    $off,
                    "], ymm13\n",
                )
            };
        }

        /// Degree `$k` of the 4-column parity kernel with 2 chains, parity `$par`: as
        /// [`par2`], with 4 columns (`{b} + 32 k`); chain 0's sums in `ymm0-7`, chain 1's in
        /// memory at `$base` (8 vectors).
        macro_rules! par4 {
            ($base:literal, $k:literal, $par:literal, $a:literal, $c:literal, $e:literal, $f:literal) => {
                concat!(
                    coefs!($k),
                    chain_step!("8", "9", "3584"),
                    chain_step!("10", "11", "3616"),
                    bcast_y!("14", concat!($k, "*32")),
                    fma_y!($a, "8", "14"),
                    mem_fma!($base, concat!($par, "*128"), "10"),
                    bcast_y!("14", concat!($k, "*32+8")),
                    fma_y!($c, "8", "14"),
                    mem_fma!($base, concat!($par, "*128+32"), "10"),
                    bcast_y!("14", concat!($k, "*32+16")),
                    fma_y!($e, "8", "14"),
                    mem_fma!($base, concat!($par, "*128+64"), "10"),
                    bcast_y!("14", concat!($k, "*32+24")),
                    fma_y!($f, "8", "14"),
                    mem_fma!($base, concat!($par, "*128+96"), "10"),
                )
            };
        }

        /// The AVX2 S^2 parity kernel, 4 columns and 2 chains, 8 degrees: 16 sums, of which
        /// chain 1's 8 live on the stack (as spilled registers do, `rsp`-relative): per degree
        /// as [`parity2`] with 4 broadcasts of data and 8 FMAs, 4 of them with a load and a
        /// store. 64 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn parity4_stack(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                stack: n,
                b,
                par4!("rsp", 0, 0, "0", "1", "2", "3"),
                par4!("rsp", 1, 1, "4", "5", "6", "7"),
                par4!("rsp", 2, 0, "0", "1", "2", "3"),
                par4!("rsp", 3, 1, "4", "5", "6", "7"),
                par4!("rsp", 4, 0, "0", "1", "2", "3"),
                par4!("rsp", 5, 1, "4", "5", "6", "7"),
                par4!("rsp", 6, 0, "0", "1", "2", "3"),
                par4!("rsp", 7, 1, "4", "5", "6", "7"),
            )
        }

        /// Degree `$k` of the 4-column parity kernel with 1 chain (`p0, p1, tau` in `ymm8`,
        /// `ymm9`, `ymm10`): the step, then 4 broadcasts of data, each feeding one FMA into
        /// the sums of the degree's parity (`ymm$a`, `$c`, `$e`, `$f`).
        macro_rules! par4_one {
            ($k:literal, $a:literal, $c:literal, $e:literal, $f:literal) => {
                concat!(
                    step_y!($k, "8", "9", "13", "ymm10"),
                    bcast_y!("14", concat!($k, "*32")),
                    fma_y!($a, "8", "14"),
                    bcast_y!("14", concat!($k, "*32+8")),
                    fma_y!($c, "8", "14"),
                    bcast_y!("14", concat!($k, "*32+16")),
                    fma_y!($e, "8", "14"),
                    bcast_y!("14", concat!($k, "*32+24")),
                    fma_y!($f, "8", "14"),
                )
            };
        }

        /// The AVX2 S^2 parity kernel, 4 columns and 1 chain, 8 degrees: its 8 sums in
        /// registers; per degree the step (a chain), 4 broadcasts of data and 4 FMAs. 32 FMAs.
        ///
        /// # Safety
        /// AVX2 and FMA must be available, and `b` must point to a 64-byte aligned buffer of
        /// [`BUFFER_BYTES`](super::BUFFER_BYTES) bytes, readable and writable, that nothing else uses meanwhile.
        #[target_feature(enable = "avx2,fma")]
        pub unsafe fn parity4_one(n: usize, b: *mut f64) {
            asm_loop_avx2!(
                n,
                b,
                par4_one!(0, "0", "1", "2", "3"),
                par4_one!(1, "4", "5", "6", "7"),
                par4_one!(2, "0", "1", "2", "3"),
                par4_one!(3, "4", "5", "6", "7"),
                par4_one!(4, "0", "1", "2", "3"),
                par4_one!(5, "4", "5", "6", "7"),
                par4_one!(6, "0", "1", "2", "3"),
                par4_one!(7, "4", "5", "6", "7"),
            )
        }

        /// The AVX2 loops, each with its useful FMAs per iteration.
        pub const LOOPS: [(&str, Loop, usize); 11] = [
            ("12 FMAs, register operands (the peak)", regs, 12),
            ("inverse pass 1: step, 8 bcast+FMA, store", inv_pass1, 64),
            ("inverse pass 2: load, 8 bcast+FMA", inv_pass2, 64),
            ("inverse 16 columns: the two passes", inv_passes, 128),
            ("inverse 8 columns: step, 8 bcast+FMA", inv8, 64),
            ("forward 16 columns, degree block 2", fwd16, 64),
            ("forward 8 columns, degree block 4", fwd8, 64),
            ("S^2 parity, 2 columns, 2 chains", parity2, 32),
            (
                "S^2 parity, 4 cols, 2 chains, 8 sums on stack",
                parity4_stack,
                64,
            ),
            ("S^2 parity, 4 columns, 1 chain", parity4_one, 32),
            ("12 FMAs, register operands (again)", regs, 12),
        ];
    }

    /// Times each loop (the best of 7 runs of `TOTAL_FMAS` FMAs' worth of iterations) and
    /// prints its rate of useful FMAs, `flops` per FMA, against `peak`.
    ///
    /// # Safety
    /// The CPU supports every loop's instruction set, and `b` is a 64-byte aligned buffer
    /// of [`BUFFER_BYTES`] bytes, readable and writable, that nothing else uses meanwhile.
    unsafe fn measure(loops: &[(&str, Loop, usize)], b: *mut f64, flops: usize, peak: f64) {
        const TOTAL_FMAS: usize = 64_000_000;
        let width = loops.iter().map(|l| l.0.len()).max().unwrap_or(0).max(42);
        for &(name, f, fmas) in loops {
            let iters = TOTAL_FMAS / fmas;
            let g = (0..7)
                .map(|_| {
                    let t = Instant::now();
                    // SAFETY: the caller guarantees the instruction set and the buffer.
                    unsafe { f(iters, b) };
                    (iters * fmas * flops) as f64 / t.elapsed().as_secs_f64() / 1e9
                })
                .fold(0.0, f64::max);
            println!(
                "{name:<width$} {g:6.1} GFLOP/s {:5.1}% of the peak",
                100.0 * g / peak
            );
        }
    }

    /// Runs every loop the CPU supports and prints its rate against the FMA peak of its
    /// instruction set.
    pub fn instruction_ceilings() {
        let avx512 = std::is_x86_feature_detected!("avx512f");
        let avx2 = so3fft::Isa::Avx2.is_supported();
        if !avx512 && !avx2 {
            println!("neither AVX-512 nor AVX2 with FMA on this machine: nothing to measure");
            return;
        }
        // L1-resident data: rows (bytes 0..1024), two block buffers (..2048), recurrence
        // coefficients `a = 0`, `c = 1` (..2176): the steps `p2 = p1 - p0` cycle with period 6,
        // so no value overflows or turns subnormal; a second vector's two blocks (..3200); the
        // AVX2 loops' `tau` vectors (3584..3648).
        let mut mem = vec![1.0e-3f64; BUFFER_BYTES / 8 + 8];
        let base = mem.as_mut_ptr();
        let off = (64 - (base as usize % 64)) / 8 % 8;
        mem[off + 256..off + 264].fill(0.0);
        mem[off + 264..off + 272].fill(1.0);
        // SAFETY: `off < 8`, so the pointer stays inside `mem` (and `BUFFER_BYTES` bytes from it).
        let b = unsafe { mem.as_mut_ptr().add(off) };
        if avx512 {
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
            // The same peak as `kernel_gflops` reports against; the first row (the same loop
            // in assembly) checks this harness against it.
            let peak = so3fft::internals::fma_peak(so3fft::Isa::Avx512);
            println!("FMA peak {peak:.1} GFLOP/s (one core)");
            // SAFETY: AVX-512F was detected above; `b` is 64-byte aligned with `BUFFER_BYTES`
            // bytes of `mem` behind it, used by nothing else.
            unsafe { measure(&loops, b, 16, peak) };
        } else {
            println!("no AVX-512 on this machine: AVX2 loops only");
        }
        if avx2 {
            // 12 chains of ymm FMAs, as the first row.
            let peak = so3fft::internals::fma_peak(so3fft::Isa::Avx2);
            println!();
            println!("AVX2 (ymm0-15), FMA peak {peak:.1} GFLOP/s (one core)");
            // SAFETY: AVX2 and FMA were detected above; `b` as for the AVX-512 loops.
            unsafe { measure(&avx2::LOOPS, b, 8, peak) };
        }
    }
}
