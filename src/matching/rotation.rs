//! Rotations in SOFT's Euler convention, `g = Rz(alpha) Ry(beta) Rz(gamma)`, and the
//! rotation of functions on the sphere, `(Lambda(g) f)(x) = f(g^-1 x)`.

use crate::error::{Error, Result};
use crate::s2::s2_coef_index;
use crate::wigner::wigner_d_column;
use num_complex::Complex64;

/// A rotation `Rz(alpha) Ry(beta) Rz(gamma)` (z-y-z Euler angles, radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rotation {
    /// First angle (about z, applied last to a vector).
    pub alpha: f64,
    /// Second angle (about y).
    pub beta: f64,
    /// Third angle (about z, applied first).
    pub gamma: f64,
}

/// Hamilton product of quaternions `(w, x, y, z)`.
pub(crate) fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

impl Rotation {
    /// The rotation with Euler angles `alpha, beta, gamma`.
    pub fn new(alpha: f64, beta: f64, gamma: f64) -> Rotation {
        Rotation { alpha, beta, gamma }
    }

    /// The same rotation with `beta` in `[0, pi]` and `alpha`, `gamma` in `[0, 2 pi)`
    /// (`(alpha, -beta, gamma)` is `(alpha + pi, beta, gamma - pi)`; angles are 2 pi
    /// periodic).
    pub fn normalized(&self) -> Rotation {
        use std::f64::consts::{PI, TAU};
        let mut beta = self.beta.rem_euclid(TAU);
        let (mut alpha, mut gamma) = (self.alpha, self.gamma);
        if beta > PI {
            beta = TAU - beta;
            alpha += PI;
            gamma -= PI;
        }
        Rotation::new(alpha.rem_euclid(TAU), beta, gamma.rem_euclid(TAU))
    }

    /// The rotation of unit quaternion `q = (w, x, y, z)` (`q` and `-q` are the same), its
    /// angles as [`Rotation::normalized`] gives them; at `beta = 0` or `pi`, where only
    /// `alpha + gamma` or `alpha - gamma` is defined, `gamma = 0`.
    pub fn from_quaternion(q: [f64; 4]) -> Rotation {
        use std::f64::consts::TAU;
        let [w, x, y, z] = q;
        // q = (cos(b/2) cos(s), -sin(b/2) sin(d), sin(b/2) cos(d), cos(b/2) sin(s)) with
        // s = (alpha + gamma) / 2, d = (alpha - gamma) / 2.
        let (c, s) = ((w * w + z * z).sqrt(), (x * x + y * y).sqrt());
        let beta = 2.0 * s.atan2(c);
        let (sum, diff) = (2.0 * z.atan2(w), 2.0 * (-x).atan2(y));
        let (alpha, gamma) = if s == 0.0 {
            (sum, 0.0)
        } else if c == 0.0 {
            (diff, 0.0)
        } else {
            (0.5 * (sum + diff), 0.5 * (sum - diff))
        };
        Rotation::new(alpha.rem_euclid(TAU), beta, gamma.rem_euclid(TAU))
    }

    /// The unit quaternion `(w, x, y, z)` of the rotation (`w >= 0`).
    pub fn quaternion(&self) -> [f64; 4] {
        let z = |a: f64| [(a / 2.0).cos(), 0.0, 0.0, (a / 2.0).sin()];
        let y = [(self.beta / 2.0).cos(), 0.0, (self.beta / 2.0).sin(), 0.0];
        let q = qmul(qmul(z(self.alpha), y), z(self.gamma));
        if q[0] < 0.0 {
            q.map(|v| -v)
        } else {
            q
        }
    }

    /// The rotation matrix (row-major), acting on column vectors.
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        let [w, x, y, z] = self.quaternion();
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }

    /// The angle of the rotation that takes `self` to `other` (geodesic distance on SO(3),
    /// radians, accurate for small angles).
    pub fn angle_to(&self, other: &Rotation) -> f64 {
        quaternion_angle(self.quaternion(), other.quaternion())
    }

    /// Whether all three angles are finite.
    pub fn is_finite(&self) -> bool {
        self.alpha.is_finite() && self.beta.is_finite() && self.gamma.is_finite()
    }
}

/// The angle of the rotation between the rotations of unit quaternions `a` and `b`
/// (see [`Rotation::angle_to`]).
pub(crate) fn quaternion_angle(a: [f64; 4], b: [f64; 4]) -> f64 {
    let conj = [a[0], -a[1], -a[2], -a[3]];
    let d = qmul(conj, b);
    let v = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
    2.0 * v.atan2(d[0].abs())
}

/// The S^2 coefficients (bandwidth `b`, `seanindex` order) of `Lambda(g) f`,
/// `(Lambda(g) f)(x) = f(g^-1 x)`: `fhat'(l, m) = sum_m' D^l_{m,m'}(g) fhat(l, m')` with
/// `D^l_{m,m'}(alpha, beta, gamma) = e^{-i m alpha} d^l_{m,m'}(beta) e^{-i m' gamma}`.
/// `O(b^3)` operations; any bandwidth.
pub fn rotate_s2_coeffs(b: usize, coeffs: &[Complex64], g: &Rotation) -> Result<Vec<Complex64>> {
    rotate_s2_coeffs_to(b, coeffs, g, (b, b.saturating_sub(1)))
}

/// [`rotate_s2_coeffs`] from bandwidth `b_in` to `b_out`: degrees up to
/// `min(deg_out, b_in - 1)` rotated, all others zero (`deg_out < b_out`; SOFT's
/// `rotateCoefAll`).
pub fn rotate_s2_coeffs_to(
    b_in: usize,
    coeffs: &[Complex64],
    g: &Rotation,
    (b_out, deg_out): (usize, usize),
) -> Result<Vec<Complex64>> {
    if coeffs.len() != b_in * b_in {
        return Err(Error::LengthMismatch {
            what: "S^2 coefficients",
            expected: b_in * b_in,
            got: coeffs.len(),
        });
    }
    if b_in == 0 || deg_out >= b_out {
        return Err(Error::InvalidArgument(format!(
            "rotation from bandwidth {b_in} to {b_out} with degree limit {deg_out}: need \
             bandwidths >= 1 and degree limit < {b_out}"
        )));
    }
    let mut out = vec![Complex64::default(); b_out * b_out];
    let lmax = deg_out.min(b_in - 1);
    let top = lmax as isize;
    for m in -top..=top {
        let em = Complex64::from_polar(1.0, -(m as f64) * g.alpha);
        for mp in -top..=top {
            let phase = em * Complex64::from_polar(1.0, -(mp as f64) * g.gamma);
            let d = wigner_d_column(m, mp, lmax, g.beta);
            let l0 = m.unsigned_abs().max(mp.unsigned_abs());
            for (i, dl) in d.iter().enumerate() {
                let l = l0 + i;
                out[s2_coef_index(b_out, l, m)] += phase * *dl * coeffs[s2_coef_index(b_in, l, mp)];
            }
        }
    }
    Ok(out)
}
