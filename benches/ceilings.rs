//! Instruction-mix ceilings of this machine for the DWT kernels.
//!
//! Hand-written AVX-512 loops, data in L1, no dependencies beyond what the mix itself
//! needs: each gives the fraction of the FMA peak that a kernel built from that mix could
//! reach at best. They are the evidence behind the DWT targets in `notes/next-steps.md`.
//!
//! `cargo bench --features internals --bench ceilings` (x86_64 with AVX-512F; elsewhere it
//! prints a message and exits).

#![warn(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]

fn main() {
    #[cfg(target_arch = "x86_64")]
    x86::instruction_ceilings();
    #[cfg(not(target_arch = "x86_64"))]
    println!("ceilings: hand-written x86_64 AVX-512 loops; nothing to measure on this target");
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

    /// Runs every loop and prints its rate against the FMA peak.
    pub fn instruction_ceilings() {
        if !std::is_x86_feature_detected!("avx512f") {
            println!("no AVX-512 on this machine: nothing to measure");
            return;
        }
        // L1-resident data: rows (bytes 0..1024), two block buffers (..2048), recurrence
        // coefficients `a = 0`, `c = 1` (..2176): the steps `p2 = p1 - p0` cycle with period 6,
        // so no value overflows or turns subnormal; a second vector's two blocks (..3200).
        let mut mem = vec![1.0e-3f64; BUFFER_BYTES / 8 + 8];
        let base = mem.as_mut_ptr();
        let off = (64 - (base as usize % 64)) / 8 % 8;
        mem[off + 256..off + 264].fill(0.0);
        mem[off + 264..off + 272].fill(1.0);
        // SAFETY: `off < 8`, so the pointer stays inside `mem` (and `BUFFER_BYTES` bytes from it).
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
                    // SAFETY: AVX-512F was detected above; `b` is 64-byte aligned with
                    // `BUFFER_BYTES` bytes of `mem` behind it, used by nothing else.
                    unsafe { f(iters * 16 / fmas, b) };
                    (iters * 16 * 16) as f64 / t.elapsed().as_secs_f64() / 1e9
                })
                .fold(0.0, f64::max)
        };
        // The same peak as `kernel_gflops` reports against; the first row (the same loop in
        // assembly) checks this harness against it.
        let peak = so3fft::internals::fma_peak(so3fft::Isa::Avx512);
        println!("FMA peak {peak:.1} GFLOP/s (one core)");
        for (name, f, fmas) in loops {
            let g = rate(f, fmas);
            println!(
                "{name:<42} {g:6.1} GFLOP/s {:5.1}% of the peak",
                100.0 * g / peak
            );
        }
    }
}
