"""Rotations against SciPy, S^2 transforms and rotation against SciPy's spherical harmonics,
and rotational matching: a known rotation recovered, the correlation coefficients against
the combination formula of docs/conventions-s2.md, the correlation at any rotation against
Parseval's sum, evaluation against the inverse transform on the grid, peaks against numpy's
argmax, normalised correlation bounds and the linearity of shells."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation as ScipyRotation
from scipy.special import sph_harm_y

import so3fft
from conftest import random_s2_coeffs

# ---------------------------------------------------------------------------------------
# Helpers (independent of so3fft)


def rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])


def random_angles(rng, n):
    """``n`` random Euler triples, with ``beta`` near 0 and near pi among them."""
    a = rng.uniform(-2 * np.pi, 2 * np.pi, n)
    b = rng.uniform(0, np.pi, n)
    c = rng.uniform(-2 * np.pi, 2 * np.pi, n)
    b[:8] = [0.0, 1e-12, 1e-7, 1e-4, np.pi, np.pi - 1e-12, np.pi - 1e-7, np.pi - 1e-4]
    return np.stack([a, b, c], axis=1)


def sh_values(B, coeffs, theta, phi):
    """``sum fhat(l, m) Y_l^m(theta, phi)`` with SciPy's ``sph_harm_y`` (the convention of
    docs/conventions-s2.md), at points given by arrays ``theta``, ``phi``."""
    total = np.zeros(np.broadcast(theta, phi).shape, complex)
    for l in range(B):
        for m in range(-l, l + 1):
            total += coeffs[so3fft.s2_coef_index(B, l, m)] * sph_harm_y(l, m, theta, phi)
    return total


def unit_vectors(theta, phi):
    return np.stack(
        [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1
    )


def polar(x):
    return np.arccos(np.clip(x[..., 2], -1, 1)), np.arctan2(x[..., 1], x[..., 0])


def combine(B, f, h):
    """The correlation's SO(3) coefficients by docs/conventions-s2.md (``so3CombineCoef``):
    ``2 pi sqrt(2 / (2l + 1)) (-1)^(m1 + m2) fhat(l, -m1) conj(hhat(l, -m2))``, ``b_out = B``,
    ``deg_lim = B - 1``."""
    out = np.zeros(so3fft.num_coeffs(B), complex)
    for l in range(B):
        for m1 in range(-l, l + 1):
            for m2 in range(-l, l + 1):
                out[so3fft.coef_index(B, l, m1, m2)] = (
                    2 * np.pi * math.sqrt(2 / (2 * l + 1)) * (-1) ** (m1 + m2)
                    * f[so3fft.s2_coef_index(B, l, -m1)]
                    * np.conj(h[so3fft.s2_coef_index(B, l, -m2)])
                )
    return out


def make_pair(rng, B, g, real=False):
    """S^2 samples ``(signal, pattern)`` with ``signal(x) = pattern(g^-1 x)``, band-limited,
    and their coefficients."""
    h = random_s2_coeffs(rng, B, real=real)
    f = so3fft.rotate_s2_coeffs(h, g)
    plan = so3fft.S2Plan(B, real=real, threads=1)
    return plan.inverse(f), plan.inverse(h), f, h


# ---------------------------------------------------------------------------------------
# Rotations


def test_rotation_matrix_and_quaternion_agree_with_scipy(rng):
    for a, b, c in random_angles(rng, 200):
        g = so3fft.Rotation(a, b, c)
        ref = ScipyRotation.from_euler("ZYZ", [a, b, c])
        m = g.as_matrix()
        assert m.shape == (3, 3)
        assert np.allclose(m, ref.as_matrix(), rtol=0, atol=1e-14)
        assert np.allclose(m, rz(a) @ ry(b) @ rz(c), rtol=0, atol=1e-14)
        q = g.as_quaternion()
        x, y, z, w = ref.as_quat()  # SciPy's order
        want = np.array([w, x, y, z])
        assert q[0] >= 0
        assert abs(np.linalg.norm(q) - 1) < 1e-15
        # q and -q are the same rotation; so3fft takes w >= 0.
        assert min(np.max(np.abs(q - want)), np.max(np.abs(q + want))) < 1e-14
        if abs(w) > 1e-12:
            assert np.max(np.abs(q - np.sign(w) * want)) < 1e-14


def test_rotation_acts_on_column_vectors():
    # Rz(pi/2) takes x to y.
    g = so3fft.Rotation(np.pi / 2, 0, 0)
    assert np.allclose(g.as_matrix() @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    # Ry(pi/2) takes z to x.
    assert np.allclose(so3fft.Rotation(0, np.pi / 2, 0).as_matrix() @ [0, 0, 1], [1, 0, 0], atol=1e-15)


def test_euler_round_trips(rng):
    for a, b, c in random_angles(rng, 300):
        g = so3fft.Rotation(a, b, c)
        ref = ScipyRotation.from_euler("ZYZ", [a, b, c])
        for back in (
            so3fft.Rotation.from_matrix(g.as_matrix()),
            so3fft.Rotation.from_quaternion(g.as_quaternion()),
            so3fft.Rotation.from_scipy(ref),
        ):
            assert 0 <= back.beta <= np.pi
            assert -np.pi <= back.alpha <= np.pi and -np.pi <= back.gamma <= np.pi
            assert np.allclose(back.as_matrix(), ref.as_matrix(), rtol=0, atol=1e-12)
            # Away from the poles the angles themselves come back (mod 2 pi).
            if 1e-6 < b < np.pi - 1e-6:
                assert abs(back.beta - b) < 1e-9
                for x, y in ((back.alpha, a), (back.gamma, c)):
                    assert abs(np.angle(np.exp(1j * (x - y)))) < 1e-9
        to = g.to_scipy()
        assert isinstance(to, ScipyRotation)
        assert (to.inv() * ref).magnitude() < 1e-7
        assert np.allclose(to.as_matrix(), ref.as_matrix(), rtol=0, atol=1e-14)
        assert tuple(g) == (a, b, c) and np.array_equal(g.as_euler(), [a, b, c])


def test_from_scipy_of_random_scipy_rotations():
    rots = ScipyRotation.random(100, random_state=3)
    for r in rots:
        g = so3fft.Rotation.from_scipy(r)
        assert np.allclose(g.as_matrix(), r.as_matrix(), rtol=0, atol=1e-12)
        x, y, z, w = r.as_quat()
        assert abs(abs(np.dot(g.as_quaternion(), [w, x, y, z])) - 1) < 1e-12


def test_angle_to_agrees_with_scipy(rng):
    angles = random_angles(rng, 100)
    for (a1, b1, c1), (a2, b2, c2) in zip(angles, angles[::-1]):
        g1, g2 = so3fft.Rotation(a1, b1, c1), so3fft.Rotation(a2, b2, c2)
        r1 = ScipyRotation.from_euler("ZYZ", [a1, b1, c1])
        r2 = ScipyRotation.from_euler("ZYZ", [a2, b2, c2])
        want = (r1.inv() * r2).magnitude()
        assert abs(g1.angle_to(g2) - want) < 1e-9
        assert abs(g1.angle_to((a2, b2, c2)) - want) < 1e-9
    # Small angles are accurate (no arccos of a rounded 1).
    g = so3fft.Rotation(0.3, 1.2, -0.4)
    for eps in (1e-6, 1e-9, 1e-12):
        assert abs(g.angle_to(so3fft.Rotation(0.3 + eps, 1.2, -0.4)) - eps) < 1e-3 * eps
    assert g.angle_to(g) == 0.0


# ---------------------------------------------------------------------------------------
# The S^2 side, against SciPy's spherical harmonics


@pytest.mark.parametrize("real", [False, True])
def test_s2_inverse_and_forward_against_scipy(rng, real):
    B = 6
    c = random_s2_coeffs(rng, B, real=real)
    theta, phi = so3fft.s2_grid_angles(B)
    want = sh_values(B, c, theta[:, None], phi[None, :])
    plan = so3fft.S2Plan(B, real=real, threads=1)
    got = plan.inverse(c)
    if real:
        assert np.max(np.abs(want.imag)) < 1e-13
        want = want.real
    assert np.max(np.abs(got - want)) < 1e-13
    assert np.max(np.abs(plan.forward(want) - c)) < 1e-13
    # Many fields at once.
    many = plan.inverse(np.stack([c, 2 * c]))
    assert many.shape == (2, 2 * B, 2 * B)
    assert np.max(np.abs(many[1] - 2 * want)) < 1e-13


def test_rotate_s2_coeffs_against_pointwise_rotation(rng):
    B = 6
    h = random_s2_coeffs(rng, B)
    a, b, c = 0.4, 2.0, -1.1
    f = so3fft.rotate_s2_coeffs(h, so3fft.Rotation(a, b, c))
    assert f.shape == (B * B,)
    # f(x) = h(g^-1 x) at random points, g from SciPy.
    theta, phi = rng.uniform(0, np.pi, 50), rng.uniform(0, 2 * np.pi, 50)
    x = unit_vectors(theta, phi)
    g = ScipyRotation.from_euler("ZYZ", [a, b, c]).as_matrix()
    t2, p2 = polar(x @ g)  # rows of g^-1 x = g^T x
    assert np.max(np.abs(sh_values(B, f, theta, phi) - sh_values(B, h, t2, p2))) < 1e-12
    # Angles as a plain tuple give the same.
    assert np.array_equal(so3fft.rotate_s2_coeffs(h, (a, b, c)), f)


# ---------------------------------------------------------------------------------------
# Matching


G0 = so3fft.Rotation(1.1, 0.7, 2.3)
G1 = so3fft.Rotation(-2.5, 2.2, 0.3)


@pytest.mark.parametrize("real", [False, True])
@pytest.mark.parametrize("B, g0", [(16, G0), (24, G1)])
def test_match_recovers_a_known_rotation(rng, real, B, g0):
    signal, pattern, _, _ = make_pair(rng, B, g0, real=real)
    corr = so3fft.Correlation(B, real=real, threads=2)
    assert corr.grid_shape == (2 * B,) * 3 and corr.deg_lim == B - 1
    found = corr.match(signal, pattern)
    assert len(found) == 1
    g, value = found[0]
    assert g.angle_to(g0) < 1e-8
    # The value is |C|^2 at the maximum; C there is <f, f> = sum |fhat|^2.
    assert value > 0


@pytest.mark.parametrize("real", [False, True])
def test_correlate_peaks_coefficients_refine(rng, real):
    B = 16
    signal, pattern, f, h = make_pair(rng, B, G1, real=real)
    corr = so3fft.Correlation(B, real=real, threads=1)
    grid = corr.correlate(signal, pattern)
    assert grid.dtype == (np.float64 if real else np.complex128)
    peaks = so3fft.top_peaks(grid, k=3)
    assert len(peaks) == 3 and peaks[0].value >= peaks[1].value >= peaks[2].value
    # The first peak is the grid's argmax of |C|^2, with its angles.
    power = np.abs(grid) ** 2
    k = int(np.argmax(power))
    assert peaks[0].index == k
    assert peaks[0].value == pytest.approx(power.ravel()[k], rel=1e-14)
    alpha, beta, gamma = so3fft.grid_angles(B)
    kb, ka, kg = np.unravel_index(k, grid.shape)
    assert (peaks[0].alpha, peaks[0].beta, peaks[0].gamma) == (alpha[ka], beta[kb], gamma[kg])
    # correlate_argmax finds the same.
    grid2, best = corr.correlate_argmax(signal, pattern)
    assert best.index == k and np.array_equal(grid2, grid)
    # The coefficients are the combination formula of the docs.
    coeffs = corr.coefficients(signal, pattern)
    want = combine(B, f, h)
    assert np.max(np.abs(coeffs - want)) < 1e-10 * np.max(np.abs(want))
    # Their inverse transform is the grid.
    inv = so3fft.Plan(B, real=real, threads=1).inverse(coeffs)
    assert np.max(np.abs(inv - grid)) < 1e-10 * np.max(np.abs(grid))
    # Refinement from the grid peak reaches the true rotation; the value is |<f, f>|^2.
    (g, value), = corr.refine(coeffs, [peaks[0].rotation])
    assert g.angle_to(G1) < 1e-8
    assert abs(value - np.sum(np.abs(f) ** 2) ** 2) < 1e-9 * value


@pytest.mark.parametrize("real", [False, True])
def test_module_level_correlate_top_peaks_refine(rng, real):
    B = 16
    signal, pattern, f, _ = make_pair(rng, B, G0, real=real)
    grid = so3fft.correlate(signal, pattern)
    assert grid.dtype == (np.float64 if real else np.complex128)
    peak = so3fft.top_peaks(grid)[0]
    assert peak.index == int(np.argmax(np.abs(grid) ** 2))
    # The correlation's coefficients, here by the forward SO(3) transform of the grid (exact:
    # the grid is band-limited).
    coeffs = so3fft.Plan(B, threads=1).forward(grid.astype(complex))
    (g, value), = so3fft.refine(coeffs, [peak.rotation])
    assert g.angle_to(G0) < 1e-8
    assert abs(value - np.sum(np.abs(f) ** 2) ** 2) < 1e-9 * value
    # Starts as angle rows, several at once.
    found = so3fft.refine(coeffs, np.array([tuple(peak.rotation), tuple(peak.rotation)]))
    assert len(found) == 2 and all(gv[0].angle_to(G0) < 1e-8 for gv in found)


def test_correlation_value_at_any_rotation_is_the_inner_product(rng):
    # C(g) = int f(x) conj(h(g^-1 x)) dx = sum_lm fhat(l,m) conj((Lambda(g) h)hat(l,m)).
    B = 8
    signal, pattern, f, h = make_pair(rng, B, G0)
    coeffs = so3fft.Correlation(B, threads=1).coefficients(signal, pattern)
    rots = random_angles(rng, 12)
    got = so3fft.evaluate(coeffs, rots)
    for value, row in zip(got, rots):
        want = np.vdot(so3fft.rotate_s2_coeffs(h, tuple(row)), f)
        assert abs(value - want) < 1e-11 * np.sum(np.abs(f) ** 2)


@pytest.mark.parametrize("real", [False, True])
def test_evaluate_equals_inverse_transform_on_the_grid(rng, real):
    B = 6
    n = so3fft.num_coeffs(B)
    c = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    if real:
        d = so3fft.to_dense(c, B)
        m = np.arange(-(B - 1), B)
        d = 0.5 * (d + (-1.0) ** (m[:, None] - m[None, :]) * np.conj(d[:, ::-1, ::-1]))
        c = so3fft.from_dense(d)
    samples = so3fft.Plan(B, real=real, threads=1).inverse(c)
    alpha, beta, gamma = so3fft.grid_angles(B)
    idx = rng.integers(0, 2 * B, size=(40, 3))  # [k (beta), j (alpha), i (gamma)]
    rots = np.stack([alpha[idx[:, 1]], beta[idx[:, 0]], gamma[idx[:, 2]]], axis=1)
    got = so3fft.evaluate(c, rots)
    want = samples[idx[:, 0], idx[:, 1], idx[:, 2]]
    assert np.max(np.abs(got - want)) < 1e-12
    # Rotation objects, and a lower degree limit (the series cut at deg_lim).
    got2 = so3fft.evaluate(c, [so3fft.Rotation(*r) for r in rots[:3]])
    assert np.max(np.abs(got2 - want[:3])) < 1e-12
    cut = c.copy()
    lmm = so3fft.coef_degrees_orders(B)
    cut[lmm[:, 0] > 2] = 0
    want3 = so3fft.Plan(B, threads=1).inverse(cut)[idx[:, 0], idx[:, 1], idx[:, 2]]
    assert np.max(np.abs(so3fft.evaluate(c, rots, deg_lim=2) - want3)) < 1e-12


@pytest.mark.parametrize("real", [False, True])
def test_normalized_correlation(rng, real):
    B = 16
    signal, pattern, _, _ = make_pair(rng, B, G1, real=real)
    scale = 3.0 if real else 1.5 - 2.0j
    copy = scale * signal + 2.0  # rotated, scaled and shifted
    for b_out in (16, 24):
        corr = so3fft.Correlation(B, b_out=b_out, normalized=True, real=real, threads=2)
        grid = corr.correlate(copy, pattern - 0.5)
        assert np.max(np.abs(grid)) <= 1 + 1e-12
        (g, value), = corr.match(copy, pattern - 0.5)
        assert g.angle_to(G1) < 1e-8
        assert abs(value - 1) < 1e-10
    # An unrelated pattern stays clearly below 1.
    other = so3fft.S2Plan(B, real=real, threads=1).inverse(random_s2_coeffs(rng, B, real=real))
    grid = so3fft.Correlation(B, normalized=True, real=real).correlate(copy, other)
    assert np.max(np.abs(grid)) < 0.5


@pytest.mark.parametrize("real", [False, True])
def test_correlate_shells_is_the_weighted_sum(rng, real):
    B = 8
    corr = so3fft.Correlation(B, b_out=10, real=real, threads=1)
    s2 = so3fft.S2Plan(B, real=real, threads=1)
    shells = []
    for w in (1.0, -0.5, 2.5):
        s = s2.inverse(random_s2_coeffs(rng, B, real=real))
        p = s2.inverse(random_s2_coeffs(rng, B, real=real))
        shells.append((s, p, w))
    got = corr.correlate_shells(shells)
    want = sum(w * corr.correlate(s, p) for s, p, w in shells)
    assert got.shape == (20, 20, 20)
    assert np.max(np.abs(got - want)) < 1e-12 * np.max(np.abs(want))
    out = np.empty_like(got)
    assert corr.correlate_shells(shells, out=out) is out
    assert np.array_equal(out, got)


def test_top_peaks_separation_and_real_grids(rng):
    B = 8
    grid = rng.standard_normal((2 * B,) * 3)
    power = grid**2
    peaks = so3fft.top_peaks(grid, k=5, min_angle=0.0)
    assert peaks[0].index == int(np.argmax(power))
    assert all(p.value == pytest.approx(power.ravel()[p.index], rel=1e-14) for p in peaks)
    assert [p.value for p in peaks] == sorted((p.value for p in peaks), reverse=True)
    spaced = so3fft.top_peaks(grid, k=5, min_angle=0.5)
    for i, p in enumerate(spaced):
        for q in spaced[:i]:
            assert p.rotation.angle_to(q.rotation) >= 0.5 - 1e-12
    # The complex grid of the same magnitudes gives the same peaks.
    cpeaks = so3fft.top_peaks(grid * np.exp(1j * rng.uniform(0, 6, grid.shape)), k=5)
    assert [p.index for p in cpeaks] == [p.index for p in peaks]
