//! Tests of the plan's schedule, lifetime and block layouts.

use super::schedule::{Chunk, ChunkGroups, ChunkPlace, Spare, SpareBuf};

/// The chunk groups of an inverse with its output as room: in order, covering every
/// chunk once; every spare buffer 64-byte aligned, inside the output, clear of the
/// other buffers and of the output slices of its own and all earlier groups (which the
/// FFT stage writes before the buffer is read); fewer groups than chunks.
#[test]
fn chunk_groups_keep_clear_of_written_slices() {
    // B = 36 with a 1-byte cap (the smallest chunk, 8 pairs) is the C test's `capped_workspace`.
    for (b, real, cap) in [
        (64usize, false, 1usize << 20),
        (64, true, 1 << 20),
        (40, false, 1 << 20),
        (37, true, 1 << 20),
        (36, false, 1),
        (36, true, 1),
        // Real, two chunks, the second short enough to fit in the first's slices.
        (20, true, 500_000),
    ] {
        let opts = super::Options {
            max_workspace_bytes: Some(cap),
            real,
            ..Default::default()
        };
        let mut plan = super::Plan::new(b, &opts).unwrap();
        // Blocks that would stay in the cache: no chain (ordinary stores, cluster-major).
        plan.schedule.plain_store_limit = usize::MAX;
        let t = if real {
            plan.blocks_real.as_ref().unwrap()
        } else {
            &plan.blocks
        };
        let slice_bytes = 4 * b * b * if real { 8 } else { 16 };
        let total = 2 * b * slice_bytes;
        let out = vec![0u8; total + 64];
        let spare = Spare {
            base: out.as_ptr().wrapping_add(8) as *mut u8,
            slice_bytes,
        };
        let chunks: Vec<_> = plan.schedule.chunks(t).map(|c| (c.lo, c.h)).collect();
        // A chain's buffer halves `(a, gap)` of `half` bytes each: 64-byte aligned,
        // in the low-beta and the mirror slices of chunk `host`.
        let in_slices = |host: Chunk, buf: SpareBuf, half: usize| {
            let (a, gap) = (buf.low, buf.gap);
            let a = a as usize - spare.base as usize;
            let m = a + 8 * gap;
            assert_eq!((spare.base as usize + a) % 64, 0);
            assert_eq!((spare.base as usize + m) % 64, 0);
            assert!(a >= host.lo * slice_bytes);
            let low_end = (host.lo + host.h) * slice_bytes;
            assert!(a + half <= low_end, "B={b}: low half");
            assert!(m >= (2 * b - host.lo - host.h) * slice_bytes);
            let mirror_end = (2 * b - host.lo) * slice_bytes;
            assert!(m + half <= mirror_end, "B={b}: mirror half");
        };
        // The complex forward's chain: one group in the chunks' order, chunk 0 in the
        // plan's buffer, each other buffer's halves in the slices of the chunk before
        // it (read by then). The real layout's do not fit in real slices.
        let ChunkGroups {
            groups: chain,
            chained,
        } = plan.schedule.chunk_groups(t, true, Some(&spare));
        assert_eq!(chained, !real, "B={b} real={real}: forward chain");
        if chained {
            assert_eq!(chain.len(), 1);
            let g = &chain[0];
            let order: Vec<_> = g.iter().map(|p| (p.chunk.lo, p.chunk.h)).collect();
            assert_eq!(order, chunks);
            assert!(g[0].spare.is_none());
            for k in 1..g.len() {
                in_slices(g[k - 1].chunk, g[k].spare.unwrap(), 8 * (t.total() / 2));
            }
        }
        // Otherwise: buffers in the slices of earlier groups only.
        let groups = plan.schedule.chunk_groups_whole(t, true, Some(&spare));
        let flat: Vec<_> = groups
            .iter()
            .flatten()
            .map(|p| (p.chunk.lo, p.chunk.h))
            .collect();
        assert_eq!(
            flat,
            plan.schedule
                .chunks(t)
                .map(|c| (c.lo, c.h))
                .collect::<Vec<_>>()
        );
        assert!(
            groups.len() < flat.len() || flat.len() < 3,
            "B={b} real={real}: no forward group"
        );
        let bytes = t.total() * 8;
        // The spare buffers of a group (all but its first chunk's): offsets into the
        // array, each 64-byte aligned and clear of the group's other buffers.
        let offsets = |g: &[ChunkPlace]| -> Vec<usize> {
            let mut ranges: Vec<(usize, usize)> = Vec::new();
            for p in &g[1..] {
                let a = (p.spare.unwrap().low as usize) - (spare.base as usize);
                assert_eq!((spare.base as usize + a) % 64, 0);
                assert!(ranges.iter().all(|&(x, y)| a + bytes <= x || a >= y));
                ranges.push((a, a + bytes));
            }
            ranges.iter().map(|r| r.0).collect()
        };
        for g in &groups {
            let lo = g[0].chunk.lo;
            for a in offsets(g) {
                let low = a + bytes <= lo * slice_bytes;
                let high = a >= (2 * b - lo) * slice_bytes && a + bytes <= total;
                assert!(low || high, "B={b}: forward buffer outside the read slices");
            }
        }
        assert!(!plan.schedule.chunk_groups(t, false, Some(&spare)).chained);
        // Blocks too large for the cache (every limit below theirs): the complex
        // inverse runs as one group, equator first, each buffer's halves in the
        // low-beta and the mirror slices of the next chunk (written after its own FFT
        // stage read the buffer), the last one in the plan's buffer. The real one's
        // full buffers do not fit there: only two chunks, the first one short.
        let mut plan = plan;
        plan.schedule.plain_store_limit = 0;
        let t = if real {
            plan.blocks_real.as_ref().unwrap()
        } else {
            &plan.blocks
        };
        let ChunkGroups {
            groups: chain,
            chained,
        } = plan.schedule.chunk_groups(t, false, Some(&spare));
        let short_pair = chunks.len() == 2 && chunks[1].1 * 2 <= chunks[0].1;
        assert_eq!(chained, !real || short_pair, "B={b} real={real}");
        if chained {
            assert_eq!(chain.len(), 1);
            let g = &chain[0];
            let order: Vec<_> = g.iter().map(|p| (p.chunk.lo, p.chunk.h)).collect();
            assert_eq!(order, chunks.iter().rev().copied().collect::<Vec<_>>());
            assert!(g.last().unwrap().spare.is_none());
            for (i, p) in g[..g.len() - 1].iter().enumerate() {
                in_slices(g[i + 1].chunk, p.spare.unwrap(), 8 * t.half_len(p.chunk.hp));
            }
            continue;
        }
        let groups = plan.schedule.chunk_groups_whole(t, false, Some(&spare));
        let flat: Vec<_> = groups
            .iter()
            .flatten()
            .map(|p| (p.chunk.lo, p.chunk.h))
            .collect();
        assert_eq!(flat, chunks, "B={b} real={real}");
        assert!(groups.len() < chunks.len(), "B={b} real={real}: no group");
        for g in &groups {
            assert!(g[0].spare.is_none());
            let written = g.last().map(|p| p.chunk.lo + p.chunk.h).unwrap();
            for a in offsets(g) {
                assert!(
                    a >= written * slice_bytes,
                    "B={b}: buffer below the free slices"
                );
                assert!(a + bytes <= (2 * b - written) * slice_bytes, "B={b}: above");
            }
        }
    }
}

/// After a plan is dropped none of its worker threads is still doing work: every one
/// has run its exit handler (counted in `live`), which the drop waits for.
#[test]
fn drop_waits_for_workers() {
    for _ in 0..5 {
        let plan = super::Plan::new(
            4,
            &super::Options {
                threads: 3,
                ..Default::default()
            },
        )
        .unwrap();
        let live = plan.workers.live_count();
        drop(plan);
        assert_eq!(*live.0.lock().unwrap(), 0);
    }
}

/// The inverse's two ways of writing the blocks (non-temporal stores into the
/// half-major layout for groups larger than `plain_store_limit`, ordinary ones into
/// cluster-major blocks below) give the same samples, bit for bit,
/// complex and real, with one chunk and with chunk groups, with either FFT threading;
/// the forward brings the coefficients back.
#[test]
fn block_stores_do_not_change_results() {
    use super::FftThreading::{FftwThreads, SlicesAcrossWorkers};
    use num_complex::Complex64;
    for (b, cap, fft_threading) in [
        (24usize, None, SlicesAcrossWorkers),
        (36, Some(1usize), SlicesAcrossWorkers),
        (36, Some(1usize), FftwThreads),
        // Odd: padding lanes in every chunk.
        (37, Some(1usize), SlicesAcrossWorkers),
        // The real layout's chain (two chunks, the second short).
        (20, Some(500_000), SlicesAcrossWorkers),
        (41, None, SlicesAcrossWorkers),
    ] {
        for real in [false, true] {
            let opts = super::Options {
                max_workspace_bytes: cap,
                real,
                threads: 2,
                fft_threading,
                ..Default::default()
            };
            let mut plan = super::Plan::new(b, &opts).unwrap();
            let mut x = 0.5f64;
            let mut coefs: Vec<Complex64> = (0..plan.num_coeffs())
                .map(|_| {
                    x = (x * 3.9 * (1.0 - x)).clamp(1e-3, 1.0 - 1e-3);
                    Complex64::new(x - 0.5, 0.25 - x / 2.0)
                })
                .collect();
            if real {
                // Coefficients of a real signal: fhat(l,-m,-m') = (-1)^(m-m') conj(...).
                for l in 0..b as isize {
                    for m in -l..=l {
                        for mp in -l..=l {
                            let i = crate::grid::coef_index(b, l as usize, m, mp);
                            let j = crate::grid::coef_index(b, l as usize, -m, -mp);
                            if (m, mp) == (0, 0) {
                                coefs[i].im = 0.0;
                            } else if i < j {
                                coefs[j] = coefs[i].conj() * super::members::neg_sign(m, mp);
                            }
                        }
                    }
                }
            }
            let mut runs = Vec::new();
            for limit in [0usize, usize::MAX] {
                plan.schedule.plain_store_limit = limit;
                if real {
                    let mut f = vec![0.0; plan.num_samples()];
                    plan.inverse_real(&coefs, &mut f).unwrap();
                    let mut c = vec![Complex64::new(f64::NAN, 0.0); coefs.len()];
                    plan.forward_real(&f, &mut c).unwrap();
                    runs.push((f.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), c));
                } else {
                    let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
                    plan.inverse(&coefs, &mut f).unwrap();
                    let mut c = vec![Complex64::new(f64::NAN, 0.0); coefs.len()];
                    plan.forward(&f, &mut c).unwrap();
                    let bits = f.iter().flat_map(|v| [v.re.to_bits(), v.im.to_bits()]);
                    runs.push((bits.collect(), c));
                }
            }
            assert!(runs[0].0 == runs[1].0, "B={b} real={real}: samples differ");
            // Chunks, groups and the complex inverse's chain change nothing either:
            // each lane's sums are its own.
            if cap.is_some() {
                let whole = super::Plan::new(
                    b,
                    &super::Options {
                        max_workspace_bytes: None,
                        ..opts
                    },
                )
                .unwrap();
                let bits: Vec<u64> = if real {
                    let mut f = vec![0.0; whole.num_samples()];
                    whole.inverse_real(&coefs, &mut f).unwrap();
                    f.iter().map(|v| v.to_bits()).collect()
                } else {
                    let mut f = vec![Complex64::new(0.0, 0.0); whole.num_samples()];
                    whole.inverse(&coefs, &mut f).unwrap();
                    f.iter()
                        .flat_map(|v| [v.re.to_bits(), v.im.to_bits()])
                        .collect()
                };
                assert!(
                    bits == runs[0].0,
                    "B={b} real={real}: chunked samples differ"
                );
            }
            for (_, c) in &runs {
                let e = c
                    .iter()
                    .zip(&coefs)
                    .map(|(a, z)| (a - z).norm())
                    .fold(0.0f64, f64::max);
                assert!(e < 1e-12, "B={b} real={real}: round trip {e:.2e}");
            }
        }
    }
}

/// A real plan's forward on the real parts of complex samples that may overwrite them
/// (the C API's `SO3FFT_REAL | SO3FFT_DESTROY_INPUT`): its real layout fits in complex
/// slices, so the chunks chain (split buffers in the slices read already); the
/// coefficients match the forward that leaves its input alone.
#[test]
fn real_parts_forward_chains_and_matches() {
    use num_complex::Complex64;
    for (b, cap) in [(36usize, 1usize), (37, 1), (20, 500_000)] {
        let opts = super::Options {
            max_workspace_bytes: Some(cap),
            real: true,
            threads: 2,
            ..Default::default()
        };
        let plan = super::Plan::new(b, &opts).unwrap();
        let t = plan.blocks_real.as_ref().unwrap();
        let mut samples: Vec<Complex64> = (0..plan.num_samples())
            .map(|i| {
                let x = ((i * 7919) % 1009) as f64 / 1009.0 - 0.5;
                Complex64::new(x, 0.25 - x)
            })
            .collect();
        let spare = Spare::over(samples.as_mut_ptr(), b);
        assert!(
            plan.schedule.chunk_groups(t, true, Some(&spare)).chained,
            "B={b}: no chain"
        );
        let mut want = vec![Complex64::new(f64::NAN, 0.0); plan.num_coeffs()];
        plan.forward_real_parts(&samples, &mut want).unwrap();
        let mut got = vec![Complex64::new(f64::NAN, 0.0); plan.num_coeffs()];
        plan.forward_real_parts_destroying_input(&mut samples, &mut got)
            .unwrap();
        let scale = want.iter().map(|z| z.norm()).fold(0.0f64, f64::max);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).norm() <= 1e-13 * scale, "B={b}: {g} against {w}");
        }
    }
}

#[test]
fn plan_is_send_sync() {
    fn is<T: Send + Sync>() {}
    is::<super::Plan>();
}

/// Plans made without a pool share the process's pool of their thread count: many plans,
/// one set of workers; another thread count, other workers; the plans on one pool give
/// the same samples as a plan alone.
#[test]
fn plans_of_a_thread_count_share_the_process_pool() {
    use crate::workers::WorkerPool;
    let options = |threads| super::Options {
        threads,
        ..Default::default()
    };
    let plans: Vec<super::Plan> = (0..12)
        .map(|i| super::Plan::new(4 + i % 3, &options(2)).unwrap())
        .collect();
    let pool = WorkerPool::process(2).unwrap();
    assert!(plans.iter().all(|p| p.workers.same_as(&pool)));
    let three = super::Plan::new(4, &options(3)).unwrap();
    assert!(!three.workers.same_as(&pool));
    assert!(three.workers.same_as(&WorkerPool::process(3).unwrap()));
    let s2 = crate::s2::S2Plan::new(
        8,
        &crate::options::Options {
            threads: 2,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(s2.workers().same_as(&pool));
    // Executions on the shared workers, one after another and from two threads at once.
    let coeffs: Vec<num_complex::Complex64> = (0..plans[0].num_coeffs())
        .map(|i| num_complex::Complex64::new((i as f64).sin(), (2.0 * i as f64).cos()))
        .collect();
    let mut want = vec![num_complex::Complex64::default(); plans[0].num_samples()];
    three.inverse(&coeffs, &mut want).unwrap();
    std::thread::scope(|s| {
        for p in [&plans[0], &plans[3]] {
            let (coeffs, want) = (&coeffs, &want);
            s.spawn(move || {
                let mut got = vec![num_complex::Complex64::default(); p.num_samples()];
                for _ in 0..5 {
                    p.inverse(coeffs, &mut got).unwrap();
                    assert!(got == *want);
                }
            });
        }
    });
}

/// Plans on one shared pool: the threads run until the last plan on them is dropped (and
/// that drop waits for them); a plan on a pool of another thread count is refused; a plan
/// executed from inside the pool (as a correlation runs its stages) gives the same
/// samples as one on its own workers, bit for bit.
#[test]
fn plans_share_a_pool() {
    use crate::workers::WorkerPool;
    use num_complex::Complex64;
    let options = super::Options {
        threads: 2,
        ..Default::default()
    };
    let pool = WorkerPool::new(2, "so3fft-test").unwrap();
    let live = pool.live_count();
    let a = super::Plan::new_on(6, &options, Some(&pool)).unwrap();
    let b = super::Plan::new_on(6, &options, Some(&pool)).unwrap();
    let three = super::Options {
        threads: 3,
        ..Default::default()
    };
    assert!(super::Plan::new_on(6, &three, Some(&pool)).is_err());
    let own = super::Plan::new(6, &options).unwrap();
    let coeffs: Vec<Complex64> = (0..own.num_coeffs())
        .map(|i| Complex64::new((i as f64 * 0.7).sin(), (i as f64 * 1.3).cos()))
        .collect();
    let mut want = vec![Complex64::default(); own.num_samples()];
    own.inverse(&coeffs, &mut want).unwrap();
    let mut got = want.clone();
    pool.pool()
        .install(|| a.inverse(&coeffs, &mut got))
        .unwrap();
    assert!(got.iter().zip(&want).all(|(x, y)| x == y));
    drop(pool);
    drop(a);
    assert_eq!(*live.0.lock().unwrap(), 2, "b still holds the threads");
    b.inverse(&coeffs, &mut got).unwrap();
    assert!(got.iter().zip(&want).all(|(x, y)| x == y));
    drop(b);
    assert_eq!(*live.0.lock().unwrap(), 0);
}

/// The real inverse into a complex array (the FFT stage writing each slice's reals as
/// `(x, 0)`, its chunk buffers in the complex output's free slices, a schedule of its own)
/// gives the real inverse's samples bit for bit and imaginary parts exactly +0: one chunk,
/// chunk groups and the chain (which fits in complex slices), either store mode, output
/// 16-byte aligned (streamed) or not.
#[test]
fn real_inverse_into_complex_matches_real_samples() {
    use num_complex::Complex64;
    for (b, cap) in [
        (24usize, None),
        (36, Some(1usize)),
        (37, Some(1usize)),
        (20, Some(500_000)),
        (41, None),
    ] {
        let opts = super::Options {
            max_workspace_bytes: cap,
            real: true,
            threads: 2,
            ..Default::default()
        };
        let mut plan = super::Plan::new(b, &opts).unwrap();
        let mut x = 0.3f64;
        // Any coefficients: the real inverse reads one block of each pair.
        let coefs: Vec<Complex64> = (0..plan.num_coeffs())
            .map(|_| {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-3, 1.0 - 1e-3);
                Complex64::new(x - 0.5, 0.25 - x / 2.0)
            })
            .collect();
        let ns = plan.num_samples();
        for limit in [0usize, usize::MAX] {
            plan.schedule.plain_store_limit = limit;
            let mut want = vec![0.0; ns];
            plan.inverse_real(&coefs, &mut want).unwrap();
            for aligned in [true, false] {
                // Doubles from `skip`: 16-byte aligned (streamed stores) or only 8.
                let mut raw = vec![f64::NAN; 2 * ns + 1];
                let skip = (0..2)
                    .find(|&k| {
                        (raw.as_ptr().wrapping_add(k) as usize).is_multiple_of(16) == aligned
                    })
                    .unwrap();
                let ptr = raw[skip..].as_mut_ptr() as *mut Complex64;
                // SAFETY: 2 ns doubles from `skip` lie in `raw`; Complex64 needs 8 bytes.
                let out = unsafe { std::slice::from_raw_parts_mut(ptr, ns) };
                if !aligned && limit == 0 && cap == Some(1) {
                    let t = plan.blocks_real.as_ref().unwrap();
                    let spare = Spare::over(out.as_mut_ptr(), b);
                    assert!(
                        plan.schedule.chunk_groups(t, false, Some(&spare)).chained,
                        "B={b}: no chain in complex slices"
                    );
                }
                plan.inverse_real_to_complex(&coefs, out).unwrap();
                let ok = out.iter().zip(&want).all(|(z, w)| {
                    z.re.to_bits() == w.to_bits() && z.im.to_bits() == 0.0f64.to_bits()
                });
                assert!(ok, "B={b} cap={cap:?} limit={limit} aligned={aligned}");
            }
        }
    }
}

/// An inverse with a watch shows it every beta slice exactly once, with the values the
/// slice holds in the output (complex: rows of the scratch, padded; real: the output
/// slice), complex and real, with one chunk and with several.
#[test]
fn watched_inverse_shows_every_slice_once() {
    use super::fft_stage::SliceRef;
    use num_complex::Complex64;
    use std::sync::Mutex;
    for (b, cap) in [(12usize, None), (36, Some(1usize))] {
        let opts = super::Options {
            threads: 2,
            real: true,
            max_workspace_bytes: cap,
            ..Default::default()
        };
        let plan = super::Plan::new(b, &opts).unwrap();
        let n = 2 * b;
        let coeffs: Vec<Complex64> = (0..plan.num_coeffs())
            .map(|i| Complex64::new((i as f64 * 0.37).sin(), (i as f64 * 0.71).cos()))
            .collect();
        // Complex: each slice's rows as seen.
        let seen: Mutex<Vec<Option<Vec<Complex64>>>> = Mutex::new(vec![None; n]);
        let watch = |k: usize, s: SliceRef| {
            let SliceRef::Complex {
                values,
                row,
                stride,
            } = s
            else {
                panic!("real slice from the complex inverse")
            };
            assert_eq!(row, n);
            let rows: Vec<Complex64> = (0..n)
                .flat_map(|r| values[r * stride..][..n].iter().copied())
                .collect();
            let old = seen.lock().unwrap()[k].replace(rows);
            assert!(old.is_none(), "B={b}: slice {k} twice");
        };
        let mut out = vec![Complex64::default(); plan.num_samples()];
        plan.inverse_watched(&coeffs, &mut out, &watch).unwrap();
        for (k, s) in seen.into_inner().unwrap().into_iter().enumerate() {
            let s = s.unwrap_or_else(|| panic!("B={b}: slice {k} not shown"));
            assert!(
                s == out[k * n * n..][..n * n],
                "B={b} cap={cap:?}: slice {k}"
            );
        }
        // Real.
        let seen: Mutex<Vec<Option<Vec<f64>>>> = Mutex::new(vec![None; n]);
        let watch = |k: usize, s: SliceRef| {
            let SliceRef::Real(v) = s else {
                panic!("complex slice from the real inverse")
            };
            let old = seen.lock().unwrap()[k].replace(v.to_vec());
            assert!(old.is_none(), "B={b}: real slice {k} twice");
        };
        let mut out = vec![0.0; plan.num_samples()];
        plan.inverse_real_watched(&coeffs, &mut out, &watch)
            .unwrap();
        for (k, s) in seen.into_inner().unwrap().into_iter().enumerate() {
            let s = s.unwrap_or_else(|| panic!("B={b}: real slice {k} not shown"));
            let same = s
                .iter()
                .zip(&out[k * n * n..][..n * n])
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "B={b} cap={cap:?}: real slice {k}");
        }
    }
}
