//! Plan-time choice of how the FFT stage uses the threads ([`FftThreading::Auto`]).
//!
//! With a measuring rigour (`Rigor::Measure` or stronger), more than one thread and
//! `FftThreading::Auto`, [`Plan::new`] builds the slice plans of both variants and times
//! them on a sample of the real work: the FFT stage, for each direction the plan has, of
//! the first slice groups of a chunk (up to [`SAMPLE_GROUPS`] groups per worker, within
//! [`SAMPLE_BYTES`]), on a scratch array standing in for the sample grid and on the plan's
//! own chunk buffer, so the block copies run with the real stride. FFTW's threads are
//! started by one untimed slice transform first. Rounds alternate between the variants and
//! each keeps its fastest round (interference from other processes only ever adds time);
//! after a round in which slices across workers lead by more than [`CLEAR`], no more are
//! run, else up to [`ROUNDS`]. The faster variant is kept (FFTW's threads need a margin of
//! [`FFTW_MARGIN`]) and the other's FFTW plans are destroyed.

use super::*;

/// Timed rounds per variant, at most (the fastest of them counts).
const ROUNDS: usize = 5;

/// Groups of slice pairs per worker in the timed sample, at most. With one, each worker
/// had a single group: a worker delayed by another process then doubled the time of the
/// slices-across-workers variant, and 3 of 10 plans at B = 256 kept FFTW's threads, whose
/// inverse FFT stage is 15% slower here (forward: equal); none of 14 with four groups.
const SAMPLE_GROUPS: usize = 4;

/// Most bytes of the scratch sample grid (at least one group per worker is timed).
const SAMPLE_BYTES: usize = 64 << 20;

/// Ratio by which FFTW's threads must be slower than slices across workers for no further
/// round to be run.
const CLEAR: f64 = 1.25;

/// FFTW's threads are kept only when faster by at least this fraction: within the noise
/// of the measurement, slices across workers are preferred, as they balance their load
/// dynamically (a core taken by another process delays a worker, not every slice). With
/// a margin of 3%, one of the plans made at B = 256 on the (shared) development machine
/// kept FFTW's threads, whose whole FFT stage is 14% slower there.
const FFTW_MARGIN: f64 = 0.1;

impl Plan {
    /// Resolve [`FftThreading::Auto`] by measurement (see the module documentation). Does
    /// nothing unless the options ask for `Auto` with a measuring rigour and more than one
    /// thread. Never fails: if the other variant cannot be planned, or the scratch array
    /// does not fit comfortably in memory, the plan keeps slices across workers.
    pub(super) fn tune_fft_threading(&mut self, options: &PlanOptions) {
        if options.fft_threading != FftThreading::Auto
            || options.rigor == Rigor::Estimate
            || self.threads < 2
            || self.fftw_threaded
        {
            return;
        }
        let n = 2 * self.b;
        let plan_threaded = |have: bool, sign: i32| -> Result<Option<SliceFft>> {
            if have {
                SliceFft::new(n, sign, options.rigor, self.threads).map(Some)
            } else {
                Ok(None)
            }
        };
        let (Ok(fwd), Ok(inv)) = (
            plan_threaded(self.fwd_fft.is_some(), SIGN_PLUS),
            plan_threaded(self.inv_fft.is_some(), SIGN_MINUS),
        ) else {
            return;
        };
        let Some([workers, fftw]) = self.time_fft_variants(fwd.as_ref(), inv.as_ref()) else {
            return;
        };
        if fftw < (1.0 - FFTW_MARGIN) * workers {
            self.fwd_fft = fwd;
            self.inv_fft = inv;
            self.fftw_threaded = true;
        }
    }

    /// Fastest-round time of the sample work (all directions the plan has) with the plan's
    /// own slice plans across workers and with the given FFTW-threaded plans; `None` if the
    /// scratch array cannot be had.
    fn time_fft_variants(
        &self,
        fwd: Option<&SliceFft>,
        inv: Option<&SliceFft>,
    ) -> Option<[f64; 2]> {
        let n = 2 * self.b;
        let nn = n * n;
        // Up to SAMPLE_GROUPS groups of pairs per worker and direction, from the first
        // chunk (always a full one), within SAMPLE_BYTES of sample grid. The sample grid
        // holds the slices the timed pairs write: pair `j` (beta `j` and its mirror
        // `2B-1-j`) uses slices `2j` and `2j+1`, distinct for the pairs timed
        // concurrently. (Mapping fresh memory costs more than the measurement itself when
        // transparent huge pages must be compacted.)
        let per_group = self.threads * self.group;
        let fit = SAMPLE_BYTES / (2 * nn * 16) / per_group;
        let npairs = (per_group * fit.clamp(1, SAMPLE_GROUPS)).min(self.blocks.chunk);
        let slices = 2 * npairs;
        let bytes = slices * nn * 16;
        if mem_available().is_some_and(|a| a / 4 < bytes) {
            return None;
        }
        // (At least one padded slice, for the warm-up below.)
        let grid = AlignedBuf::new((slices * nn).max(n * fft::slice_stride(n))).ok()?;
        let h = self.blocks.chunk;
        let ch = Chunk {
            lo: 0,
            h,
            hp: h.next_multiple_of(self.isa.lanes()),
        };
        let g = SyncPtr(grid.as_mut_ptr());
        let b = self.b;
        let slice = move |k: usize| {
            let (j, mirror) = if k < b { (k, 0) } else { (2 * b - 1 - k, 1) };
            SyncPtr(g.get().wrapping_add((2 * (j % npairs) + mirror) * nn))
        };
        let variants: [(Option<&SliceFft>, Option<&SliceFft>, bool); 2] = [
            (self.fwd_fft.as_ref(), self.inv_fft.as_ref(), false),
            (fwd, inv, true),
        ];
        let mut best = [f64::INFINITY; 2];
        self.with_buf(|buf| {
            self.pool().install(|| {
                // Start FFTW's threads (created on a plan's first execution) untimed.
                if let Some(fft) = fwd.or(inv) {
                    // SAFETY: the sample grid holds at least one padded slice.
                    unsafe { fft.in_place(g.get()) };
                }
                let bp = buf.as_mut_ptr() as *mut f64;
                // The inverse's layout for one chunk (see `plan/blocks.rs`).
                let layout = if self.streams_blocks(1) {
                    BufLayout::HalfMajor(self.blocks.total() / 2)
                } else {
                    BufLayout::Blocks
                };
                for round in 0..ROUNDS {
                    for i in 0..2 {
                        // Alternate which variant goes first.
                        let v = (i + round) % 2;
                        let (f, iv, threaded) = variants[v];
                        let t = Instant::now();
                        for (fft, forward) in [(f, true), (iv, false)] {
                            if let Some(fft) = fft {
                                self.fft_pairs(
                                    &ch, fft, threaded, forward, &slice, bp, layout, npairs,
                                )?;
                            }
                        }
                        best[v] = best[v].min(t.elapsed().as_secs_f64());
                    }
                    // A clear lead of the default needs no more rounds. A lead of FFTW's
                    // threads must survive every round: one round in which another
                    // process delays a worker makes the default look slow (at B = 64,
                    // with bursts of load on the other core, 10 of 90 plans kept FFTW's
                    // threads, 1.5x slower there, when a single such round decided; none
                    // since: `examples/tune_count.rs`).
                    if best[1] > CLEAR * best[0] {
                        break;
                    }
                }
                Ok(())
            })
        })
        .ok()?;
        Some(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Test helper: wait (up to a minute) until both cores have been idle for 300 ms, so that
    /// timings are not taken while another process runs.
    fn wait_idle() {
        fn idle_total() -> (u64, u64) {
            let s = std::fs::read_to_string("/proc/stat").unwrap_or_default();
            let v: Vec<u64> = s
                .lines()
                .next()
                .unwrap_or("")
                .split_whitespace()
                .skip(1)
                .filter_map(|x| x.parse().ok())
                .collect();
            if v.len() < 5 {
                return (0, 0);
            }
            (v[3] + v[4], v.iter().sum())
        }
        let t0 = Instant::now();
        while t0.elapsed().as_secs() < 60 {
            let (i0, a0) = idle_total();
            std::thread::sleep(std::time::Duration::from_millis(300));
            let (i1, a1) = idle_total();
            if a1 == a0 || (i1 - i0) as f64 >= 0.95 * (a1 - a0) as f64 {
                return;
            }
        }
    }

    /// Whole FFT stage (every chunk) of one direction on `grid`, in seconds.
    fn fft_stage(plan: &Plan, forward: bool, grid: &mut [Complex64]) -> f64 {
        let g = SyncPtr(grid.as_mut_ptr());
        let t = Instant::now();
        plan.with_buf(|buf| {
            plan.pool().install(|| {
                let layout = if !forward && plan.streams_blocks(1) {
                    BufLayout::HalfMajor(plan.blocks.total() / 2)
                } else {
                    BufLayout::Blocks
                };
                for ch in plan.chunks(&plan.blocks) {
                    plan.fft_chunk(&ch, forward, g.get(), buf.as_mut_ptr() as *mut f64, layout)?;
                }
                Ok(())
            })
        })
        .unwrap();
        t.elapsed().as_secs_f64()
    }

    fn median(mut v: Vec<f64>) -> f64 {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }

    /// FFT stage alone: one thread, two threads with each variant, two threads with Auto.
    /// `SO3FFT_B=64,128,256 SO3FFT_ROUNDS=5 cargo test --release --lib fft_stage_timing -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn fft_stage_timing() {
        let bs: Vec<usize> = std::env::var("SO3FFT_B")
            .unwrap_or("64,128,256".into())
            .split(',')
            .map(|x| x.trim().parse().unwrap())
            .collect();
        let rounds: usize = std::env::var("SO3FFT_ROUNDS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(5);
        for b in bs {
            let mk = |threads, fft_threading| {
                let t = Instant::now();
                let p = Plan::new(
                    b,
                    &PlanOptions {
                        threads,
                        rigor: Rigor::Measure,
                        fft_threading,
                        ..Default::default()
                    },
                )
                .unwrap();
                (p, t.elapsed().as_secs_f64())
            };
            let plans = [
                ("1 thread", mk(1, FftThreading::Auto)),
                ("2 workers", mk(2, FftThreading::SlicesAcrossWorkers)),
                ("2 fftw", mk(2, FftThreading::FftwThreads)),
                ("2 auto", mk(2, FftThreading::Auto)),
            ];
            let n = 2 * b;
            let mut grid: Vec<Complex64> = (0..n * n * n)
                .map(|i| Complex64::new((i % 7) as f64 - 3.0, (i % 5) as f64))
                .collect();
            let mut times = vec![[Vec::new(), Vec::new()]; plans.len()];
            for _ in 0..rounds {
                for (i, (_, (p, _))) in plans.iter().enumerate() {
                    wait_idle();
                    times[i][0].push(fft_stage(p, true, &mut grid));
                    times[i][1].push(fft_stage(p, false, &mut grid));
                }
            }
            let one = median(times[0][0].clone()) + median(times[0][1].clone());
            for ((name, (p, tp)), t) in plans.iter().zip(&times) {
                let (f, i) = (median(t[0].clone()), median(t[1].clone()));
                println!(
                    "B={b:4} {name:10} ({:?}, plan {tp:.3} s): fwd {f:.4e} inv {i:.4e} (min {:.4e} {:.4e}) speed-up over 1 thread {:.2}x",
                    p.fft_threading(),
                    t[0].iter().cloned().fold(f64::INFINITY, f64::min),
                    t[1].iter().cloned().fold(f64::INFINITY, f64::min),
                    one / (f + i)
                );
            }
        }
    }

    /// Repeated inverse (or forward, SO3FFT_FWD=1) FFT stages, for profiling.
    #[test]
    #[ignore]
    fn fft_stage_loop() {
        let b: usize = std::env::var("SO3FFT_B")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(128);
        let threads: usize = std::env::var("SO3FFT_THREADS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(2);
        let fwd = std::env::var("SO3FFT_FWD").is_ok();
        let plan = Plan::new(
            b,
            &PlanOptions {
                threads,
                rigor: Rigor::Measure,
                fft_threading: FftThreading::SlicesAcrossWorkers,
                ..Default::default()
            },
        )
        .unwrap();
        let n = 2 * b;
        let mut grid = vec![Complex64::new(1.0, 0.5); n * n * n];
        let t = Instant::now();
        let mut k = 0;
        while t.elapsed().as_secs_f64() < 5.0 {
            fft_stage(&plan, fwd, &mut grid);
            k += 1;
        }
        println!(
            "{k} stages, {:.4} s each",
            t.elapsed().as_secs_f64() / k as f64
        );
    }
}
