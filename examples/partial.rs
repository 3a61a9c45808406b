//! Partial plans: an order-limited transform at a bandwidth whose full grid would not fit in
//! memory, and a correlation-style inverse evaluated on a finer grid than its bandwidth.
//!
//! `cargo run --release --example partial`

use so3fft::{Complex64, Options, PartialPlan, Shape};

fn main() -> so3fft::Result<()> {
    // |M|, |M'| <= 8 at B = 1024: a 2048 x 17 x 17 grid instead of 2048^3 samples.
    let shape = Shape::new(1024).with_orders(8, 8);
    let plan = PartialPlan::new(&shape, &Options::default())?;
    let mut coeffs = vec![Complex64::default(); plan.num_coeffs()];
    let at = shape.coef_index(1000, -3, 8).expect("held by the shape");
    coeffs[at] = Complex64::new(1.0, -0.5);
    let mut samples = vec![Complex64::default(); plan.num_samples()];
    plan.inverse(&coeffs, &mut samples)?;
    let mut back = vec![Complex64::default(); plan.num_coeffs()];
    plan.forward(&samples, &mut back)?;
    let err = back
        .iter()
        .zip(&coeffs)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    println!(
        "order-limited B = 1024: {} coefficients, {} samples, round trip error {err:.1e}",
        plan.num_coeffs(),
        plan.num_samples()
    );

    // Bandwidth 32 evaluated on the grid of bandwidth 64 (zero padding, twice as fine).
    let fine = Shape::new(32).with_grid(64, 128, 128);
    let plan = PartialPlan::new(
        &fine,
        &Options::default().with_direction(so3fft::Direction::Inverse),
    )?;
    let coeffs = vec![Complex64::new(1e-3, 0.0); plan.num_coeffs()];
    let mut samples = vec![Complex64::default(); plan.num_samples()];
    plan.inverse(&coeffs, &mut samples)?;
    println!(
        "L = 32 on the B = 64 grid: {} samples (f at beta_0 = {:.3e})",
        plan.num_samples(),
        samples[0].re
    );
    Ok(())
}
