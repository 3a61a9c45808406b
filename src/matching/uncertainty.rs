//! How sure a refined peak is: the covariance of its error from the curvature of the
//! correlation at the peak and the noise the inputs' spectra show (`docs/matching-noise.md`).

use super::refine::So3Series;
use super::rotation::Rotation;
use super::weights::Spectra;

/// The uncertainty of a refined rotation `g`: the true rotation is taken to be `g exp(xi)`,
/// `xi` a small rotation vector in `g`'s frame with mean 0 and covariance
/// [`Uncertainty::covariance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uncertainty {
    /// Covariance of `xi`, radians squared (row-major, symmetric).
    pub covariance: [[f64; 3]; 3],
    /// `sqrt(trace(covariance))`, radians: the root-mean-square angle of the error (about
    /// 60% of errors are smaller when the error is isotropic and Gaussian). Infinite when
    /// the rotation is not at a maximum of `|C|`.
    pub sigma: f64,
}

impl Uncertainty {
    /// No maximum: covariance and `sigma` infinite.
    fn unbounded() -> Uncertainty {
        Uncertainty {
            covariance: [[f64::INFINITY; 3]; 3],
            sigma: f64::INFINITY,
        }
    }
}

/// What the estimate needs to know of the correlation besides its series.
pub(crate) struct NoiseModel<'a> {
    pub spectra: &'a Spectra,
    /// Real inputs (the noise in each coefficient is then not circular: twice the variance
    /// of the correlation's real part).
    pub real: bool,
    /// Degrees `1..` normalised by the weighted norms (see `CorrelationOptions`).
    pub normalized: bool,
}

/// `g exp(xi)`, `xi` a rotation vector in `g`'s frame.
pub(crate) fn perturbed(g: &Rotation, xi: [f64; 3]) -> Rotation {
    let angle = (xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]).sqrt();
    let (s, c) = (0.5 * angle).sin_cos();
    let k = if angle > 0.0 { s / angle } else { 0.5 };
    let q = super::rotation::qmul(g.quaternion(), [c, k * xi[0], k * xi[1], k * xi[2]]);
    Rotation::from_quaternion(q)
}

/// The uncertainty of the peak `at` of the series `c` (see [`Uncertainty`]): the Hessian
/// `H` of `|C|` there by central differences in `at`'s frame, and the variance `V` of each
/// component of the noise's gradient, so that the error `xi = -H^-1 grad` has covariance
/// `V H^-2`. Per degree `l` (weights `w_l`, net signal powers `s` and noise floors `n`
/// per coefficient):
/// `V = k sum_l w_l^2 (2l+1) l(l+1)/3 (n_f s_h + n_h s_f + n_f n_h)`,
/// `k = 1/2` for complex inputs, 1 for real ones; divided by the squared norms when the
/// correlation is normalised.
pub(crate) fn uncertainty(c: &So3Series, at: &Rotation, model: &NoiseModel) -> Uncertainty {
    let sp = model.spectra;
    let deg_lim = sp.weights.len() - 1;
    // A step small against the peak's width (about pi / deg_lim), large against rounding.
    let h = 0.02 * std::f64::consts::PI / (deg_lim + 1) as f64;
    let e = |i: usize, s: f64| {
        let mut v = [0.0; 3];
        v[i] = s;
        v
    };
    let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let mut points = vec![*at];
    for i in 0..3 {
        points.push(perturbed(at, e(i, h)));
        points.push(perturbed(at, e(i, -h)));
    }
    let pairs = [(0, 1), (0, 2), (1, 2)];
    for &(i, j) in &pairs {
        for (si, sj) in [(h, h), (h, -h), (-h, h), (-h, -h)] {
            points.push(perturbed(at, add(e(i, si), e(j, sj))));
        }
    }
    let f: Vec<f64> = c.values(&points).iter().map(|z| z.norm_sqr()).collect();
    let mut hess = [[0.0; 3]; 3];
    for i in 0..3 {
        hess[i][i] = (f[1 + 2 * i] - 2.0 * f[0] + f[2 + 2 * i]) / (h * h);
    }
    for (k, &(i, j)) in pairs.iter().enumerate() {
        let q = &f[7 + 4 * k..][..4];
        let v = (q[0] - q[1] - q[2] + q[3]) / (4.0 * h * h);
        hess[i][j] = v;
        hess[j][i] = v;
    }
    // The Hessian of |C| = sqrt(|C|^2) where the gradient vanishes.
    let scale = 0.5 / f[0].sqrt();
    let hess = hess.map(|row| row.map(|v| v * scale));
    let Some(inv) = inverse_negative_definite(hess) else {
        return Uncertainty::unbounded();
    };
    let mut v = 0.0;
    for (l, &w) in sp.weights.iter().enumerate().skip(1) {
        let (sf, sh) = (sp.signal_net(l), sp.pattern_net(l));
        let (nf, nh) = (sp.signal_noise, sp.pattern_noise);
        let lf = l as f64;
        v += w * w * (2.0 * lf + 1.0) * lf * (lf + 1.0) / 3.0 * (nf * sh + nh * sf + nf * nh);
    }
    if !model.real {
        v *= 0.5;
    }
    if model.normalized {
        let norm = |p: &[f64]| -> f64 { (1..=deg_lim).map(|l| sp.weights[l] * p[l]).sum() };
        let d = norm(&sp.signal_power) * norm(&sp.pattern_power);
        v = if d > 0.0 { v / d } else { f64::INFINITY };
    }
    let mut cov = [[0.0; 3]; 3];
    for (i, row) in cov.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = v * (0..3).map(|k| inv[i][k] * inv[k][j]).sum::<f64>();
        }
    }
    // Rounding bounds how well any peak is found: each axis gets the error of a rotation
    // of about `eps (deg_lim + 1)` radians.
    let rounding = (f64::EPSILON * (deg_lim + 1) as f64).powi(2);
    for (i, row) in cov.iter_mut().enumerate() {
        row[i] += rounding;
    }
    let sigma = (cov[0][0] + cov[1][1] + cov[2][2]).sqrt();
    Uncertainty {
        covariance: cov,
        sigma,
    }
}

/// `a^-1` for a symmetric negative definite `a` (Sylvester's criterion on `-a`), else None.
fn inverse_negative_definite(a: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let n = a.map(|r| r.map(|v| -v));
    let m1 = n[0][0];
    let m2 = n[0][0] * n[1][1] - n[0][1] * n[1][0];
    let cof = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        n[r0][c0] * n[r1][c1] - n[r0][c1] * n[r1][c0]
    };
    let det = (0..3).map(|j| n[0][j] * cof(0, j)).sum::<f64>();
    if !(m1 > 0.0 && m2 > 0.0 && det > 0.0 && det.is_finite()) {
        return None;
    }
    // inverse of n = adjugate / det (cofactors transposed); a^-1 = -n^-1.
    Some(std::array::from_fn(|i| {
        std::array::from_fn(|j| -cof(j, i) / det)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perturbation_composes_in_the_frame_of_g() {
        let g = Rotation::new(0.7, 1.1, -0.4);
        // A rotation about the frame's own z axis adds to gamma.
        let r = perturbed(&g, [0.0, 0.0, 0.3]);
        assert!(r.angle_to(&Rotation::new(0.7, 1.1, -0.1)) < 1e-14);
        assert!(
            (perturbed(&g, [0.01, -0.02, 0.005]).angle_to(&g) - 0.0229128784747792).abs() < 1e-14
        );
    }

    #[test]
    fn inverse_of_negative_definite() {
        let a = [[-4.0, 1.0, 0.5], [1.0, -3.0, 0.2], [0.5, 0.2, -2.0]];
        let inv = inverse_negative_definite(a).unwrap();
        for (i, row) in a.iter().enumerate() {
            for j in 0..3 {
                let p: f64 = row.iter().zip(&inv).map(|(x, r)| x * r[j]).sum();
                assert!((p - f64::from(u8::from(i == j))).abs() < 1e-14);
            }
        }
        assert!(
            inverse_negative_definite([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])
                .is_none()
        );
    }
}
