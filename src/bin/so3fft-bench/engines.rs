//! `so3fft-bench engines`: the full shape on the general engine (the one every partial
//! shape, batch, beta selection and distributed plan runs on) against `Plan`, the gate of
//! the single engine. Complex inverse and forward, the four calls alternated run by run,
//! then the real-signal ones likewise; medians of the stage times.

use crate::cli::Options;
use crate::partial::alternate;
use crate::workload::random_coeffs;
use so3fft::{Batch, Complex64, PartialPlan, Plan, Shape, StageTimes, Transform};

/// Prints one table row per bandwidth, thread count and direction.
pub fn run(opts: &Options) -> so3fft::Result<()> {
    let runs = opts.runs.unwrap_or(7);
    println!("full shape: Plan against the general engine (medians of {runs} alternated runs; ms)");
    println!(
        "{:>5} {:>3} {:>4} | {:>28} | {:>28} | {:>6}",
        "B", "thr", "dir", "Plan total (fft / dwt)", "general total (fft / dwt)", "ratio"
    );
    for &b in &opts.bandwidths {
        for &threads in &opts.threads {
            let o = so3fft::Options::default()
                .with_threads(threads)
                .with_rigor(opts.rigor);
            let plan = Plan::new(b, &o)?;
            let general = PartialPlan::new(&Shape::new(b), &o.clone().with_general_engine(true))?;
            let (nc, ns) = (plan.num_coeffs(), plan.num_samples());
            let c = random_coeffs(nc, 0x5EED_0000 + b as u64);
            // The forwards' input: the samples of `c`.
            let mut xs = vec![Complex64::default(); ns];
            plan.inverse(&c, &mut xs)?;
            let (mut x0, mut x1) = (
                vec![Complex64::default(); ns],
                vec![Complex64::default(); ns],
            );
            let (mut c0, mut c1) = (
                vec![Complex64::default(); nc],
                vec![Complex64::default(); nc],
            );
            let inv = Batch {
                count: 1,
                in_dist: nc,
                out_dist: ns,
            };
            let fwd = Batch {
                count: 1,
                in_dist: ns,
                out_dist: nc,
            };
            let [pi, gi, pf, gf] = alternate(
                runs,
                &mut [
                    &mut || plan.inverse(&c, &mut x0),
                    &mut || general.inverse_many(inv, &c, &mut x1),
                    &mut || plan.forward(&xs, &mut c0),
                    &mut || general.forward_many(fwd, &xs, &mut c1),
                ],
            )?;
            drop((plan, general, xs, x0, x1, c0, c1, c));
            // The real-signal transforms, on plans made for them.
            let o = o.with_real(true);
            let plan = Plan::new(b, &o)?;
            let general = PartialPlan::new(&Shape::new(b), &o.with_general_engine(true))?;
            let mut hc = vec![Complex64::default(); nc];
            crate::seeded::fill_real(0x5EED_0001 + b as u64, b, &mut hc);
            let mut xs = vec![0.0; ns];
            plan.inverse_real(&hc, &mut xs)?;
            let (mut x0, mut x1) = (vec![0.0; ns], vec![0.0; ns]);
            let (mut c0, mut c1) = (
                vec![Complex64::default(); nc],
                vec![Complex64::default(); nc],
            );
            let [rpi, rgi, rpf, rgf] = alternate(
                runs,
                &mut [
                    &mut || Transform::inverse_real(&plan, &hc, &mut x0),
                    &mut || Transform::inverse_real(&general, &hc, &mut x1),
                    &mut || Transform::forward_real(&plan, &xs, &mut c0),
                    &mut || Transform::forward_real(&general, &xs, &mut c1),
                ],
            )?;
            let ms = |t: &StageTimes| {
                format!(
                    "{:8.3} ({:7.3} / {:7.3})",
                    1e3 * t.total,
                    1e3 * t.fft,
                    1e3 * t.dwt
                )
            };
            let rows = [
                ("inv", pi, gi),
                ("fwd", pf, gf),
                ("rinv", rpi, rgi),
                ("rfwd", rpf, rgf),
            ];
            for (dir, p, g) in rows {
                println!(
                    "{b:>5} {threads:>3} {dir:>4} | {:>28} | {:>28} | {:6.3}",
                    ms(&p),
                    ms(&g),
                    g.total / p.total
                );
            }
        }
    }
    Ok(())
}
