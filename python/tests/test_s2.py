"""S^2 transforms (so3fft.S2Plan) against direct summation with SciPy's spherical harmonics
and against the reference data in tests/data/s2 (computed with mpmath, independently of
so3fft)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import so3fft

DATA = Path(__file__).resolve().parents[2] / "tests" / "data" / "s2"


# ----------------------------------------------------------------------------------------
# independent truths


def grid(B):
    """The documented S^2 grid, from its formula."""
    theta = np.pi * (2 * np.arange(2 * B) + 1) / (4 * B)
    phi = np.pi * np.arange(2 * B) / B
    return theta, phi


def layout(B):
    """``(l, m)`` in seanindex order, from its documented definition (m = 0..B-1 each with
    l = m..B-1, then m = -(B-1)..-1 each with l = |m|..B-1)."""
    orders = list(range(B)) + list(range(-(B - 1), 0))
    return np.array([(l, m) for m in orders for l in range(abs(m), B)])


def ylm_matrix(B, theta, phi):
    """``Y[p, i] = Y_l^m(theta_p, phi_p)`` for the i-th (l, m) of the seanindex order."""
    sph_harm_y = pytest.importorskip("scipy.special").sph_harm_y
    lm = layout(B)
    return sph_harm_y(lm[None, :, 0], lm[None, :, 1], theta[:, None], phi[:, None])


def grid_ylm(B):
    theta, phi = grid(B)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    return ylm_matrix(B, T.ravel(), P.ravel())


def direct_synthesis(fhat, B):
    return (grid_ylm(B) @ fhat).reshape(2 * B, 2 * B)


def random_coeffs(B, rng, real=False):
    c = rng.standard_normal(B * B) + 1j * rng.standard_normal(B * B)
    if real:
        c = real_symmetrize(c, B)
    return c


def real_symmetrize(c, B):
    """Coefficients of a real field: the m >= 0 part of ``c`` with ``fhat(l, -m) = (-1)^m
    conj(fhat(l, m))`` and ``fhat(l, 0)`` real."""
    lm = layout(B)
    where = {(l, m): i for i, (l, m) in enumerate(lm)}
    out = c.copy()
    for i, (l, m) in enumerate(lm):
        if m == 0:
            out[i] = c[i].real
        elif m < 0:
            out[i] = (-1.0) ** abs(m) * np.conj(c[where[(l, -m)]])
    return out


def rel_err(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-300)


# ----------------------------------------------------------------------------------------
# layout and grid


@pytest.mark.parametrize("B", [1, 2, 5, 16])
def test_layout_and_grid(B):
    np.testing.assert_array_equal(so3fft.s2_coef_degrees_orders(B), layout(B))
    for i, (l, m) in enumerate(layout(B)):
        assert so3fft.s2_coef_index(B, l, m) == i
    theta, phi = so3fft.s2_grid_angles(B)
    np.testing.assert_allclose(theta, grid(B)[0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(phi, grid(B)[1], rtol=0, atol=1e-15)
    assert so3fft.s2_num_coeffs(B) == B * B


def test_weights_are_fejer_quadrature():
    # sum_j w_j g(theta_j) integrates g(theta) sin(theta) dtheta exactly for polynomials in
    # cos(theta) of degree < 2B
    B = 6
    theta = grid(B)[0]
    w = so3fft.weights(B)
    for k in range(2 * B):
        exact = (1 - (-1) ** (k + 1)) / (k + 1)
        assert abs(w @ np.cos(theta) ** k - exact) < 1e-14


# ----------------------------------------------------------------------------------------
# against direct summation


@pytest.mark.parametrize("B", [4, 8])
def test_inverse_complex_matches_direct_sum(B):
    rng = np.random.default_rng(B)
    c = random_coeffs(B, rng)
    f = so3fft.S2Plan(B).inverse(c)
    assert f.shape == (2 * B, 2 * B) and f.dtype == np.complex128
    assert rel_err(f, direct_synthesis(c, B)) < 1e-12


@pytest.mark.parametrize("B", [4, 8])
def test_inverse_real_matches_direct_sum(B):
    rng = np.random.default_rng(10 + B)
    c = random_coeffs(B, rng, real=True)
    f = so3fft.S2Plan(B, real=True).inverse(c)
    assert f.dtype == np.float64
    truth = direct_synthesis(c, B)
    assert np.abs(truth.imag).max() < 1e-13 * np.abs(truth).max()
    assert rel_err(f, truth.real) < 1e-12


def test_real_inverse_reads_only_nonnegative_orders():
    B = 6
    rng = np.random.default_rng(3)
    c = random_coeffs(B, rng)  # no symmetry, Im fhat(l, 0) != 0
    f = so3fft.S2Plan(B, real=True).inverse(c)
    # the real part of the synthesis with the negative orders taken from the positive ones
    # (Im fhat(l, 0) only feeds an imaginary part, which a real plan does not return)
    truth = direct_synthesis(real_symmetrize(c, B), B).real
    assert rel_err(f, truth) < 1e-12


@pytest.mark.parametrize("B", [4, 8])
def test_forward_of_band_limited_samples(B):
    rng = np.random.default_rng(20 + B)
    c = random_coeffs(B, rng)
    f = direct_synthesis(c, B)
    assert rel_err(so3fft.S2Plan(B).forward(f), c) < 1e-12
    cr = random_coeffs(B, rng, real=True)
    fr = direct_synthesis(cr, B).real
    got = so3fft.S2Plan(B, real=True).forward(fr)
    assert got.shape == (B * B,) and got.dtype == np.complex128
    assert rel_err(got, cr) < 1e-12


@pytest.mark.parametrize("B", [4, 8])
def test_forward_is_the_quadrature(B):
    # for any samples (not band-limited): fhat(l, m) = (pi / B) sum w_j f conj(Y)
    rng = np.random.default_rng(30 + B)
    f = rng.standard_normal((2 * B, 2 * B)) + 1j * rng.standard_normal((2 * B, 2 * B))
    w = np.repeat(so3fft.weights(B), 2 * B)
    truth = (np.pi / B) * (grid_ylm(B).conj().T @ (w * f.ravel()))
    assert np.abs(so3fft.S2Plan(B).forward(f) - truth).max() < 1e-13


@pytest.mark.parametrize("B", [1, 2, 7, 16])
@pytest.mark.parametrize("real", [False, True])
def test_round_trips(B, real):
    rng = np.random.default_rng(B + 100 * real)
    plan = so3fft.S2Plan(B, real=real)
    c = random_coeffs(B, rng, real=real)
    back = plan.forward(plan.inverse(c))
    assert np.abs(back - c).max() < 1e-13 * max(1.0, np.abs(c).max())


@pytest.mark.parametrize("real", [False, True])
def test_many_fields(real):
    B, n = 8, 5
    rng = np.random.default_rng(7 + real)
    plan = so3fft.S2Plan(B, real=real)
    c = np.stack([random_coeffs(B, rng, real=real) for _ in range(n)])
    f = plan.inverse(c)
    assert f.shape == (n, 2 * B, 2 * B)
    for i in range(n):
        np.testing.assert_array_equal(f[i], plan.inverse(c[i]))
        truth = direct_synthesis(c[i], B)
        assert rel_err(f[i], truth.real if real else truth) < 1e-12
    back = plan.forward(f)
    assert back.shape == (n, B * B)
    for i in range(n):
        np.testing.assert_array_equal(back[i], plan.forward(f[i]))
    assert np.abs(back - c).max() < 1e-13 * np.abs(c).max()
    # zero fields
    assert plan.inverse(np.zeros((0, B * B), complex)).shape == (0, 2 * B, 2 * B)
    assert plan.forward(np.zeros((0, 2 * B, 2 * B))).shape == (0, B * B)


def test_out_arguments_and_validation():
    B = 4
    plan = so3fft.S2Plan(B)
    rplan = so3fft.S2Plan(B, real=True)
    c = random_coeffs(B, np.random.default_rng(0))
    out = np.empty((2 * B, 2 * B), complex)
    assert plan.inverse(c, out=out) is out
    np.testing.assert_array_equal(out, plan.inverse(c))
    with pytest.raises(ValueError):
        plan.inverse(np.zeros(B * B + 1, complex))
    with pytest.raises(ValueError):
        plan.forward(np.zeros((2 * B, 2 * B + 1)))
    with pytest.raises(TypeError):
        rplan.forward(np.zeros((2 * B, 2 * B), complex))
    with pytest.raises(TypeError):
        plan.inverse(c, out=np.empty((2 * B, 2 * B)))
    with pytest.raises(ValueError):
        plan.forward(np.full((2 * B, 2 * B), np.nan))
    with pytest.raises((ValueError, TypeError)):
        so3fft.S2Plan(0)


# ----------------------------------------------------------------------------------------
# reference data (tests/data/s2)


def read_reference(name):
    """Scalars and sections of a reference file: ``section NAME COUNT`` then COUNT lines
    ``j k re im`` (samples) or ``seanindex l m re im`` (coefficients)."""
    path = DATA / name
    if not path.exists():
        pytest.skip(f"reference file {name} not present")
    scalars, sections = {}, {}
    lines = [ln.split() for ln in path.read_text().splitlines() if ln and not ln.startswith("#")]
    i = 0
    while i < len(lines):
        words = lines[i]
        if words[0] == "section":
            count = int(words[2])
            sections[words[1]] = np.array(lines[i + 1 : i + 1 + count], dtype=float)
            i += 1 + count
        else:
            scalars[words[0]] = float(words[1])
            i += 1
    return scalars, sections


def samples_of(table, B):
    j, k = table[:, 0].astype(int), table[:, 1].astype(int)
    f = np.zeros((2 * B, 2 * B), complex)
    f[j, k] = table[:, 2] + 1j * table[:, 3]
    return f


def coefs_of(table, B):
    idx, l, m = (table[:, c].astype(int) for c in range(3))
    for i, ll, mm in zip(idx, l, m):
        assert so3fft.s2_coef_index(B, ll, mm) == i
    c = np.zeros(B * B, complex)
    c[idx] = table[:, 3] + 1j * table[:, 4]
    return c


@pytest.mark.parametrize("name", ["fst_B4_complex.txt", "fst_B8_complex.txt"])
def test_reference_forward_complex(name):
    s, sec = read_reference(name)
    B = int(s["B"])
    got = so3fft.S2Plan(B).forward(samples_of(sec["samples"], B))
    assert np.abs(got - coefs_of(sec["coefs"], B)).max() < 1e-13


def test_reference_forward_real():
    s, sec = read_reference("fst_B8_real.txt")
    B = int(s["B"])
    f = samples_of(sec["samples"], B)
    assert not f.imag.any()
    got = so3fft.S2Plan(B, real=True).forward(f.real)
    assert np.abs(got - coefs_of(sec["coefs"], B)).max() < 1e-13


def test_reference_forward_realmode_complex_input():
    # SOFT's real mode on complex samples: orders m >= 0 as for complex data, negative
    # orders overwritten by the symmetry. A real S2Plan takes real samples only; the
    # complex plan gives the m >= 0 half, and the symmetry gives the rest.
    s, sec = read_reference("fst_B4_realmode_complexinput.txt")
    B = int(s["B"])
    ref = coefs_of(sec["coefs"], B)
    got = so3fft.S2Plan(B).forward(samples_of(sec["samples"], B))
    nonneg = layout(B)[:, 1] >= 0
    assert np.abs(got[nonneg] - ref[nonneg]).max() < 1e-13
    lm = layout(B)
    sym = real_symmetrize(got, B)
    sym[lm[:, 1] == 0] = got[lm[:, 1] == 0]  # SOFT keeps Im fhat(l, 0)
    assert np.abs(sym - ref).max() < 1e-13


@pytest.mark.parametrize("name", ["inv_B4_complex.txt", "inv_B8_complex.txt"])
def test_reference_inverse_complex(name):
    s, sec = read_reference(name)
    B = int(s["B"])
    ref = samples_of(sec["samples"], B)
    got = so3fft.S2Plan(B).inverse(coefs_of(sec["coefs"], B))
    assert rel_err(got, ref) < 1e-13


@pytest.mark.parametrize("name", ["inv_B8_real.txt", "inv_B4_realmode_asymmetric.txt"])
def test_reference_inverse_real(name):
    # a real plan returns the real part (rdata) of SOFT's real-mode inverse
    s, sec = read_reference(name)
    B = int(s["B"])
    ref = samples_of(sec["samples"], B)
    got = so3fft.S2Plan(B, real=True).inverse(coefs_of(sec["coefs"], B))
    assert rel_err(got, ref.real) < 1e-13


@pytest.mark.parametrize("name", ["rot_B8_complex.txt", "rot_B8_real.txt"])
def test_reference_rotation(name):
    s, sec = read_reference(name)
    B = int(s["B"])
    real = bool(s["isReal"])
    g = so3fft.Rotation(s["alpha"], s["beta"], s["gamma"])
    f_in, ref = samples_of(sec["input"], B), samples_of(sec["output"], B)
    plan = so3fft.S2Plan(B, real=real)
    c = plan.forward(f_in.real if real else f_in)
    got = plan.inverse(so3fft.rotate_s2_coeffs(c, g))
    assert rel_err(got, ref.real if real else ref) < 1e-13


def test_rotation_against_direct_evaluation():
    # f(g^-1 x) evaluated directly with SciPy's Y at the rotated points
    B = 6
    rng = np.random.default_rng(5)
    c = random_coeffs(B, rng)
    g = so3fft.Rotation(0.4, 2.1, -1.3)
    theta, phi = grid(B)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    x = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    y = x @ g.as_matrix()  # rows of g^T x = g^-1 x
    ty = np.arccos(np.clip(y[:, 2], -1, 1))
    py = np.arctan2(y[:, 1], y[:, 0])
    truth = (ylm_matrix(B, ty, py) @ c).reshape(2 * B, 2 * B)
    got = so3fft.S2Plan(B).inverse(so3fft.rotate_s2_coeffs(c, g))
    assert rel_err(got, truth) < 1e-12
    assert math.isclose(np.linalg.norm(so3fft.rotate_s2_coeffs(c, g)), np.linalg.norm(c))
