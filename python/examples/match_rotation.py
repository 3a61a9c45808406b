"""Recover a rotation between two functions on the sphere.

A pattern h on S^2 is a sum of a few smooth bumps, exp(kappa_i (x . c_i)), sampled on
so3fft's grid at bandwidth B. The signal is the same function rotated by a known rotation g
that lies between the grid points: f(x) = h(g^-1 x), i.e. the bumps moved to g c_i (the
centres are rotated with SciPy, so the Euler convention is checked on the way). The rotation
is then found again:

1. the correlation C(g) = int f(x) h(g^-1 x) dx on the (2B)^3 grid of SO(3) (one real
   ``so3fft.Correlation``), and its largest value (the grid peak, about pi/B off);
2. the peak refined off the grid by Newton steps on the band-limited C
   (``Correlation.coefficients`` + ``Correlation.refine``), to about 1e-12 rad.

The script prints both errors, cross-checks the signal against ``so3fft.rotate_s2_coeffs``
and the result against SciPy, and draws the correlation around the peak.

    python match_rotation.py [--bandwidth 32] [--seed 1] [--out match_rotation.png]

It exits with status 0 only if the refined rotation is within 1e-8 rad of the true one.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np
from scipy.spatial.transform import Rotation as ScipyRotation

import so3fft

TOLERANCE = 1e-8  # radians


def bumps_on_grid(B, centres, kappas, weights):
    """sum_i w_i exp(kappa_i (x . c_i - 1)) on the S^2 grid of bandwidth B, (2B, 2B)."""
    theta, phi = so3fft.s2_grid_angles(B)
    t, p = np.meshgrid(theta, phi, indexing="ij")  # [theta_j, phi_k], the grid's layout
    x = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
    f = np.zeros(t.shape)
    for c, kappa, w in zip(centres, kappas, weights):
        f += w * np.exp(kappa * (x @ c - 1.0))
    return f


def random_rotation(rng):
    """A rotation well inside the Euler chart and off the grid (uniform angles)."""
    return so3fft.Rotation(
        rng.uniform(0.0, 2.0 * math.pi), rng.uniform(0.2, math.pi - 0.2),
        rng.uniform(0.0, 2.0 * math.pi),
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bandwidth", "-B", type=int, default=32, help="bandwidth B (default 32)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    ap.add_argument("--bumps", type=int, default=5, help="number of bumps (default 5)")
    ap.add_argument("--out", default="match_rotation.png", help="figure file (PNG, PDF, SVG)")
    ap.add_argument("--no-figure", action="store_true", help="skip the figure")
    args = ap.parse_args(argv)
    B = args.bandwidth
    if B < 4:
        ap.error("the bandwidth must be at least 4")
    rng = np.random.default_rng(args.seed)

    # Pattern: bumps of random width and height, kappa <= 0.3 B. Their degree-l part decays
    # like (kappa/2)^l / l!, so at B = 32 the part above the bandwidth is ~1e-14 of the whole
    # (at small B it aliases a little, which the refinement tolerates).
    centres = rng.normal(size=(args.bumps, 3))
    centres /= np.linalg.norm(centres, axis=1, keepdims=True)
    kappas = rng.uniform(0.15, 0.3, args.bumps) * B
    weights = rng.uniform(0.5, 1.5, args.bumps)
    pattern = bumps_on_grid(B, centres, kappas, weights)

    # Signal: the pattern rotated by g, f(x) = h(g^-1 x) = sum_i w_i exp(kappa_i (x . g c_i)).
    g_true = random_rotation(rng)
    R = g_true.to_scipy()  # SciPy's intrinsic "ZYZ" with the same angles
    signal = bumps_on_grid(B, R.apply(centres), kappas, weights)

    # Cross-check: so3fft's own rotation of the pattern's coefficients gives the same signal.
    s2 = so3fft.S2Plan(B, real=True)
    rotated = s2.inverse(so3fft.rotate_s2_coeffs(s2.forward(pattern), g_true))
    rotation_check = np.max(np.abs(rotated - signal)) / np.max(np.abs(signal))

    # 1. The correlation grid and its peak.
    t0 = time.perf_counter()
    corr = so3fft.Correlation(B, real=True)
    t1 = time.perf_counter()
    grid, peak = corr.correlate_argmax(signal, pattern)
    t2 = time.perf_counter()
    g_grid = peak.rotation

    # 2. Refinement off the grid, from the grid peak.
    coeffs = corr.coefficients(signal, pattern)
    [(g_refined, value)] = corr.refine(coeffs, [g_grid])
    t3 = time.perf_counter()

    # The same in one call (k best peaks, each refined).
    [(g_match, _)] = corr.match(signal, pattern, k=1)

    err_grid = g_true.angle_to(g_grid)
    err_refined = g_true.angle_to(g_refined)
    err_match = g_true.angle_to(g_match)
    err_scipy = (R.inv() * g_refined.to_scipy()).magnitude()
    step = math.pi / B

    print(f"so3fft {so3fft.__version__}, bandwidth B = {B}, {args.bumps} bumps, seed {args.seed}")
    print(f"correlation grid: (2B)^3 = {grid.size} rotations, grid step pi/B = {step:.4f} rad")
    print(f"rotate_s2_coeffs vs analytic rotation: max rel. difference {rotation_check:.1e}")
    print()
    print("                 alpha            beta             gamma            error (rad)")
    print(f"true rotation    {g_true.alpha:<16.12f} {g_true.beta:<16.12f} {g_true.gamma:<16.12f}")
    print(f"grid peak        {g_grid.alpha:<16.12f} {g_grid.beta:<16.12f} {g_grid.gamma:<16.12f} "
          f"{err_grid:.3e}")
    print(f"refined          {g_refined.alpha:<16.12f} {g_refined.beta:<16.12f} "
          f"{g_refined.gamma:<16.12f} {err_refined:.3e}")
    print(f"Correlation.match: error {err_match:.3e} rad")
    print(f"SciPy: |R_true^-1 R_refined| = {err_scipy:.3e} rad; refined as SciPy ZYZ "
          f"{np.array2string(g_refined.to_scipy().as_euler('ZYZ'), precision=12)}")
    print(f"peak |C|^2 = {peak.value:.6g} on the grid, {value:.12g} refined")
    print(f"time: plan {1e3 * (t1 - t0):.1f} ms, correlate + argmax {1e3 * (t2 - t1):.1f} ms, "
          f"coefficients + refine {1e3 * (t3 - t2):.1f} ms")

    if not args.no_figure:
        draw(args.out, B, grid, peak, g_true, g_refined, coeffs)
        print(f"figure: {args.out}")

    ok = err_refined < TOLERANCE and err_scipy < TOLERANCE
    print("OK" if ok else f"FAILED: refined error above {TOLERANCE:g} rad")
    return 0 if ok else 1


def draw(path, B, grid, peak, g_true, g_refined, coeffs):
    """|C| over (alpha, gamma) at the peak's beta, and C along beta through the rotations."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = 2 * B
    alpha, beta, gamma = so3fft.grid_angles(B)
    k, rest = divmod(peak.index, n * n)
    j, i = divmod(rest, n)
    # A window of +-w grid steps centred on the peak (the angles are periodic).
    w = min(n // 2 - 1, 10)
    offs = np.arange(-w, w + 1)
    ja, ig = (j + offs) % n, (i + offs) % n
    alpha_c = alpha[j] + offs * (math.pi / B)
    gamma_c = gamma[i] + offs * (math.pi / B)
    slice_ = np.abs(grid[k][np.ix_(ja, ig)])

    def near(angle, centre):  # the representative of a periodic angle nearest `centre`
        return centre + (angle - centre + math.pi) % (2 * math.pi) - math.pi

    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 4.4), gridspec_kw={"width_ratios": [1.1, 1]})
    im = ax0.pcolormesh(gamma_c, alpha_c, slice_, shading="nearest", cmap="viridis")
    fig.colorbar(im, ax=ax0, label="|C|")
    ax0.plot(peak.gamma, peak.alpha, "s", mfc="none", mec="w", ms=9, label="grid peak")
    ax0.plot(near(g_refined.gamma, peak.gamma), near(g_refined.alpha, peak.alpha), "r+", ms=12,
             mew=2, label="refined")
    ax0.plot(near(g_true.gamma, peak.gamma), near(g_true.alpha, peak.alpha), "kx", ms=7,
             label="true")
    ax0.set_xlabel("gamma (rad)")
    ax0.set_ylabel("alpha (rad)")
    ax0.set_title(f"|C| at the grid peak's beta = {peak.beta:.4f} (B = {B})")
    ax0.legend(loc="lower right", fontsize=8)

    # Along beta: the band-limited C through the refined (alpha, gamma), and the grid's
    # column at the grid peak's (alpha, gamma).
    b_fine = np.linspace(0.0, math.pi, 721)
    rows = np.column_stack([np.full_like(b_fine, g_refined.alpha), b_fine,
                            np.full_like(b_fine, g_refined.gamma)])
    line = so3fft.evaluate(coeffs, rows).real
    ax1.plot(b_fine, line, "-", lw=1.2, label="C(alpha*, beta, gamma*), series")
    ax1.plot(beta, grid[:, j, i], ".", ms=5, label="grid column at the grid peak")
    ax1.axvline(g_refined.beta, color="r", lw=0.8, label=f"refined beta = {g_refined.beta:.6f}")
    ax1.set_xlabel("beta (rad)")
    ax1.set_ylabel("C")
    ax1.set_title("C along beta")
    ax1.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
