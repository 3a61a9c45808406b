//! `so3fft-bench mpi-model` (or `--mpi-model`): what a distributed plan (`DistributedPlan`,
//! docs/distributed.md) would need and take at B = 1024 and 2048 on clusters of nodes, from
//! rates measured here on one core and a stated node and network. A model, not a measurement:
//! see the assumptions printed with the table.

use crate::cli::Options;
use crate::workload::random_coeffs;
use so3fft::{Complex64, Plan};

/// Cores, memory (bytes) and network bandwidth (bytes/s, each way) of the modelled node.
const NODE_CORES: f64 = 64.0;
const NODE_BYTES: f64 = 256e9;
const NODE_NET: f64 = 12.5e9;

/// Wigner terms of a full transform of bandwidth `b`: coefficients times betas.
fn terms(b: f64) -> f64 {
    (4.0 * b * b * b - b) / 3.0 * 2.0 * b
}

/// Runs the model: one-core rates from a B = 128 inverse and forward here, then the table.
pub fn run(opts: &Options) -> so3fft::Result<()> {
    let b = 128usize;
    let plan = Plan::new(
        b,
        &so3fft::Options::default()
            .with_threads(1)
            .with_rigor(opts.rigor),
    )?;
    let c = random_coeffs(plan.num_coeffs(), 1);
    let mut x = vec![Complex64::default(); plan.num_samples()];
    let mut back = vec![Complex64::default(); plan.num_coeffs()];
    let (mut dwt, mut fft) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..3 {
        let i = plan.inverse(&c, &mut x)?;
        let f = plan.forward(&x, &mut back)?;
        dwt = dwt.min(i.dwt + f.dwt);
        fft = fft.min(i.fft + f.fft);
    }
    let bf = b as f64;
    // Per core: seconds per Wigner term (both directions) and per sample (both directions,
    // FFT time per n log n).
    let n = 2.0 * bf;
    let per_term = dwt / terms(bf);
    let per_sample_log = fft / (n * n * n * (n * n).log2());
    println!("Distributed plans, a model (docs/distributed.md):");
    println!(
        "  rates measured here on one core at B = {b}: DWT {:.2} ns per Wigner term, FFT {:.3} ns per sample and log2(slice)",
        per_term * 1e9,
        per_sample_log * 1e9
    );
    println!(
        "  node: {NODE_CORES} cores at this machine's per-core speed, {:.0} GB, {:.1} GB/s network each way;",
        NODE_BYTES / 1e9,
        NODE_NET / 1e9
    );
    println!("  one rank per node; memory per rank = (samples + coefficients) / P + workspace, the larger of");
    println!(
        "  512 MiB and a twentieth of the arrays (the pairs run in as many groups as that needs);"
    );
    println!("  exchange per rank and transform = lane rows / P x (P - 1) / P each way, at the network's speed");
    println!("  (no overlap of computation and exchange); time = inverse + forward.");
    println!(
        "\n  {:>5} {:>5} {:>12} {:>8} {:>14} {:>10} {:>10} {:>10}",
        "B", "P", "mem/rank GB", "fits", "exchange GB", "compute s", "network s", "total s"
    );
    for b in [1024f64, 2048.0] {
        let n = 2.0 * b;
        let samples = n * n * n * 16.0;
        let coeffs = (4.0 * b * b * b - b) / 3.0 * 16.0;
        // In-band values of the lane rows: (2B - 1)^2 per slice, 16 bytes each.
        let rows = (n - 1.0) * (n - 1.0) * n * 16.0;
        let compute = per_term * terms(b) + per_sample_log * n * n * n * (n * n).log2();
        for p in [8f64, 16.0, 32.0, 64.0, 128.0, 256.0] {
            let arrays = (samples + coeffs) / p;
            let mem = arrays + (arrays / 20.0).max(512.0 * 1024.0 * 1024.0);
            let exchange = rows / p * (p - 1.0) / p;
            let t_compute = compute / (p * NODE_CORES);
            let t_net = 2.0 * exchange / NODE_NET;
            println!(
                "  {b:>5} {p:>5} {:>12.1} {:>8} {:>14.2} {:>10.2} {:>10.2} {:>10.2}",
                mem / 1e9,
                if mem <= 0.8 * NODE_BYTES { "yes" } else { "no" },
                exchange / 1e9,
                t_compute,
                t_net,
                t_compute + t_net
            );
        }
    }
    Ok(())
}
