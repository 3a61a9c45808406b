//! Real-signal path against the complex path: time per direction and round-trip error.
//!
//! `cargo run --release --example real_timing [-- B1,B2,...]` (default 64,128,256)

use so3fft::{Complex64, Plan, PlanOptions, Rigor};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bws: Vec<usize> = match std::env::args().nth(1) {
        Some(s) => s
            .split(',')
            .map(|x| x.trim().parse())
            .collect::<Result<_, _>>()?,
        None => vec![64, 128, 256],
    };
    println!(
        "{:>5} {:>11} {:>11} {:>11} {:>11} {:>9} {:>9} {:>11}",
        "B",
        "cplx fwd s",
        "real fwd s",
        "cplx inv s",
        "real inv s",
        "fwd x",
        "inv x",
        "real rt err"
    );
    for b in bws {
        let opts = PlanOptions {
            rigor: Rigor::Measure,
            real: true,
            ..Default::default()
        };
        let plan = Plan::new(b, &opts)?;
        // Real-symmetric coefficients: fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M')).
        let mut s = 0x1234_5678_u64 + b as u64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut c = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        for l in 0..b {
            let li = l as isize;
            for m in -li..=li {
                for mp in -li..=li {
                    if (m, mp) < (-m, -mp) {
                        let v = Complex64::new(next(), next());
                        let sg = if (m - mp).rem_euclid(2) == 0 {
                            1.0
                        } else {
                            -1.0
                        };
                        c[so3fft::coef_index(b, l, m, mp)] = v;
                        c[so3fft::coef_index(b, l, -m, -mp)] = v.conj() * sg;
                    } else if m == 0 && mp == 0 {
                        c[so3fft::coef_index(b, l, 0, 0)] = Complex64::new(next(), 0.0);
                    }
                }
            }
        }
        let runs = if b >= 256 { 3 } else { 5 };
        let mut fc = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        let mut fr = vec![0.0; plan.num_samples()];
        let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        let mut t = [vec![], vec![], vec![], vec![]];
        for _ in 0..runs {
            t[2].push(plan.inverse_timed(&c, &mut fc)?.total);
            t[3].push(plan.inverse_real_timed(&c, &mut fr)?.total);
            t[0].push(plan.forward_timed(&fc, &mut back)?.total);
            t[1].push(plan.forward_real_timed(&fr, &mut back)?.total);
        }
        let err = back
            .iter()
            .zip(&c)
            .fold(0.0f64, |e, (a, b)| e.max((a - b).norm()));
        let [cf, rf, ci, ri] = t.map(median);
        println!(
            "{b:>5} {cf:>11.4} {rf:>11.4} {ci:>11.4} {ri:>11.4} {:>9.2} {:>9.2} {err:>11.2e}",
            cf / rf,
            ci / ri
        );
    }
    Ok(())
}
