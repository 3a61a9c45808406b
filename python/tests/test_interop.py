"""so3fft.interop: layouts and conventions against ducc0, SciPy and the Wigner-d reference
data (tests/data/wigner_d_reference.csv, mpmath)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import so3fft
from so3fft import interop

WIGNER_CSV = Path(__file__).resolve().parents[2] / "tests" / "data" / "wigner_d_reference.csv"


def random_real_coeffs(B, rng):
    """S^2 coefficients of a real field (via a real forward transform of band-limited
    samples: the symmetry then holds exactly)."""
    plan = so3fft.S2Plan(B, real=True)
    return plan.forward(plan.inverse(rng.standard_normal(B * B) + 1j * rng.standard_normal(B * B)))


def random_coeffs(B, rng, n=None):
    shape = (B * B,) if n is None else (n, B * B)
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


def hand_alm(fhat, B):
    """ducc0's alm of a real field, built from the definitions (no interop code)."""
    lmax = B - 1
    alm = np.zeros((lmax + 1) * (lmax + 2) // 2, complex)
    for l in range(B):
        for m in range(l + 1):
            alm[m * (2 * lmax + 1 - m) // 2 + l] = fhat[so3fft.s2_coef_index(B, l, m)]
    return alm


def rel_err(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(b).max()


# ----------------------------------------------------------------------------------------
# ducc0: normalisation, index, geometry


def test_ducc0_basis_is_scipy_ylm():
    # one unit coefficient a(l, m), m > 0, of a real field synthesises Y_l^m + conj(Y_l^m)
    ducc0 = pytest.importorskip("ducc0")
    sph_harm_y = pytest.importorskip("scipy.special").sph_harm_y
    B = 6
    theta, phi = so3fft.s2_grid_angles(B)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    for l, m in [(0, 0), (3, 0), (3, 1), (5, 2), (5, 5)]:
        alm = np.zeros((1, B * (B + 1) // 2), complex)
        alm[0, interop.ducc0_alm_index(l, m, B - 1)] = 1.0
        got = ducc0.sht.synthesis_2d(alm=alm, **interop.ducc0_synthesis_2d_kwargs(B))[0]
        y = sph_harm_y(l, m, T, P)
        truth = y.real if m == 0 else 2 * y.real
        assert np.abs(got - truth).max() < 1e-13


def test_ducc0_alm_index():
    lmax = 5
    seen = [interop.ducc0_alm_index(l, m, lmax) for m in range(lmax + 1) for l in range(m, lmax + 1)]
    assert seen == list(range((lmax + 1) * (lmax + 2) // 2))
    with pytest.raises(ValueError):
        interop.ducc0_alm_index(2, 3, lmax)
    with pytest.raises(ValueError):
        interop.ducc0_alm_index(6, 0, lmax)
    with pytest.raises(TypeError):
        interop.ducc0_alm_index(1.5, 0, lmax)


@pytest.mark.parametrize("B", [8, 32, 64])
def test_synthesis_agrees_with_ducc0(B):
    ducc0 = pytest.importorskip("ducc0")
    rng = np.random.default_rng(B)
    fhat = random_real_coeffs(B, rng)
    ours = so3fft.S2Plan(B, real=True).inverse(fhat)
    theirs = ducc0.sht.synthesis_2d(
        alm=hand_alm(fhat, B)[None], lmax=B - 1, spin=0, ntheta=2 * B, nphi=2 * B, geometry="F1"
    )[0]
    assert rel_err(ours, theirs) < 1e-12


@pytest.mark.parametrize("B", [8, 32, 64])
def test_analysis_agrees_with_ducc0(B):
    # ducc0's F1 analysis is exact up to degree 2B - 1, order B - 1: on band-limited
    # samples it must give back so3fft's coefficients and vice versa
    ducc0 = pytest.importorskip("ducc0")
    rng = np.random.default_rng(B + 1)
    fhat = random_real_coeffs(B, rng)
    samples = so3fft.S2Plan(B, real=True).inverse(fhat)
    alm = ducc0.sht.analysis_2d(map=samples[None], lmax=B - 1, spin=0, geometry="F1")[0]
    assert rel_err(alm, hand_alm(fhat, B)) < 1e-12
    # the other way: ducc0's map of ducc0's alm, analysed by so3fft
    alm2 = interop.s2_to_ducc0_alm(random_real_coeffs(B, rng))
    m2 = ducc0.sht.synthesis_2d(alm=alm2[None], **interop.ducc0_synthesis_2d_kwargs(B))[0]
    got = so3fft.S2Plan(B, real=True).forward(m2)
    assert rel_err(interop.s2_to_ducc0_alm(got), alm2) < 1e-12


def test_ducc0_geometry_off_grid():
    # the coefficient table summed with SciPy's Y at arbitrary points equals ducc0's
    # synthesis at those points
    ducc0 = pytest.importorskip("ducc0")
    sph_harm_y = pytest.importorskip("scipy.special").sph_harm_y
    B = 8
    rng = np.random.default_rng(4)
    fhat = random_real_coeffs(B, rng)
    loc = np.stack([rng.uniform(0, np.pi, 50), rng.uniform(0, 2 * np.pi, 50)], -1)
    theirs = ducc0.sht.synthesis_general(
        alm=interop.s2_to_ducc0_alm(fhat)[None], spin=0, lmax=B - 1, loc=loc, epsilon=1e-14
    )[0]
    table = interop.s2_coefficient_table(fhat)
    l = np.arange(B)[:, None]
    m = np.arange(-(B - 1), B)[None, :]
    ours = [
        np.sum(np.where(abs(m) <= l, table * sph_harm_y(l, m, t, p), 0)) for t, p in loc
    ]
    assert np.abs(np.imag(ours)).max() < 1e-13
    assert rel_err(np.real(ours), theirs) < 1e-11  # ducc0 evaluates with a NUFFT


def test_ducc0_complex_and_many_fields():
    pytest.importorskip("ducc0")
    B, n = 8, 3
    rng = np.random.default_rng(9)
    c = random_coeffs(B, rng, n)
    plan = so3fft.S2Plan(B)
    f = plan.inverse(c)
    assert rel_err(interop.ducc0_s2_inverse(c), f) < 1e-12
    assert rel_err(interop.ducc0_s2_inverse(c[1]), f[1]) < 1e-12
    assert rel_err(interop.ducc0_s2_forward(f), c) < 1e-12
    # real fields, many at once
    cr = np.stack([random_real_coeffs(B, rng) for _ in range(n)])
    fr = so3fft.S2Plan(B, real=True).inverse(cr)
    dr = interop.ducc0_s2_inverse(cr, real=True)
    assert dr.dtype == np.float64 and rel_err(dr, fr) < 1e-12
    got = interop.ducc0_s2_forward(fr)
    assert got.shape == (n, B * B) and rel_err(got, cr) < 1e-12
    with pytest.raises(ValueError):
        interop.ducc0_s2_forward(np.zeros((4, 5)))


def test_rotation_agrees_with_ducc0():
    ducc0 = pytest.importorskip("ducc0")
    B = 16
    rng = np.random.default_rng(11)
    fhat = random_real_coeffs(B, rng)
    g = so3fft.Rotation(0.7, 1.1, 2.3)
    ours = interop.s2_to_ducc0_alm(so3fft.rotate_s2_coeffs(fhat, g), check=False)
    theirs = ducc0.sht.rotate_alm(
        interop.s2_to_ducc0_alm(fhat), B - 1, *interop.ducc0_rotation_angles(g)
    )
    assert rel_err(ours, theirs) < 1e-12
    assert interop.ducc0_rotation_angles((1.0, 2.0, 3.0)) == (3.0, 2.0, 1.0)
    with pytest.raises(ValueError):
        interop.ducc0_rotation_angles((1.0, 2.0))


# ----------------------------------------------------------------------------------------
# conversions: exact round trips and validation


@pytest.mark.parametrize("B", [1, 2, 9])
def test_alm_round_trips_are_exact(B):
    rng = np.random.default_rng(B)
    fhat = random_real_coeffs(B, rng)
    alm = interop.s2_to_ducc0_alm(fhat)
    assert alm.shape == (B * (B + 1) // 2,)
    np.testing.assert_array_equal(alm, hand_alm(fhat, B))
    np.testing.assert_array_equal(interop.s2_from_ducc0_alm(alm), fhat)
    np.testing.assert_array_equal(interop.s2_from_ducc0_alm(alm, B - 1), fhat)
    # from an arbitrary alm (m = 0 entries real)
    a = rng.standard_normal(alm.size) + 1j * rng.standard_normal(alm.size)
    a[[interop.ducc0_alm_index(l, 0, B - 1) for l in range(B)]] = rng.standard_normal(B)
    np.testing.assert_array_equal(interop.s2_to_ducc0_alm(interop.s2_from_ducc0_alm(a)), a)
    # many fields
    many = np.stack([fhat, 2 * fhat])
    np.testing.assert_array_equal(interop.s2_from_ducc0_alm(interop.s2_to_ducc0_alm(many)), many)


def test_complex_field_as_two_real_alms():
    B = 7
    rng = np.random.default_rng(1)
    c = random_coeffs(B, rng)
    re, im = interop.s2_to_ducc0_alm(c, real=False)
    back = interop.s2_from_ducc0_alm(re, alm_imag=im)
    assert np.abs(back - c).max() < 1e-15 * np.abs(c).max() * 4
    # they are the alms of the real and imaginary parts of the field
    f = so3fft.S2Plan(B).inverse(c)
    plan = so3fft.S2Plan(B, real=True)
    np.testing.assert_allclose(interop.s2_to_ducc0_alm(plan.forward(f.real)), re, atol=1e-13)
    np.testing.assert_allclose(interop.s2_to_ducc0_alm(plan.forward(f.imag)), im, atol=1e-13)
    # a real field: the imaginary part's alm vanishes
    fr = random_real_coeffs(B, rng)
    re, im = interop.s2_to_ducc0_alm(fr, real=False)
    assert np.abs(im).max() < 1e-15 * np.abs(fr).max()
    np.testing.assert_array_equal(re, interop.s2_to_ducc0_alm(fr))


def test_alm_conversion_checks():
    B = 5
    rng = np.random.default_rng(2)
    c = random_coeffs(B, rng)
    with pytest.raises(ValueError, match="real field"):
        interop.s2_to_ducc0_alm(c)
    # without the check: the m >= 0 part, as a real S2Plan reads it
    alm = interop.s2_to_ducc0_alm(c, check=False)
    f = so3fft.S2Plan(B, real=True).inverse(c)
    g = so3fft.S2Plan(B, real=True).inverse(interop.s2_from_ducc0_alm(alm))
    assert np.abs(f - g).max() < 1e-14
    with pytest.raises(ValueError):
        interop.s2_to_ducc0_alm(np.zeros(10, complex))
    with pytest.raises(TypeError):
        interop.s2_to_ducc0_alm(np.array(["a"] * 4))
    with pytest.raises(ValueError):
        interop.s2_from_ducc0_alm(np.zeros(7, complex))
    with pytest.raises(ValueError):
        interop.s2_from_ducc0_alm(np.zeros(15, complex), lmax=5)
    with pytest.raises(ValueError):
        interop.s2_from_ducc0_alm(np.zeros(15, complex), alm_imag=np.zeros(10, complex))
    with pytest.raises(TypeError):
        interop.ducc0_synthesis_2d_kwargs(2.0)
    assert interop.ducc0_synthesis_2d_kwargs(4) == {
        "lmax": 3, "spin": 0, "geometry": "F1", "ntheta": 8, "nphi": 8,
    }
    assert interop.ducc0_analysis_2d_kwargs(4) == {"lmax": 3, "spin": 0, "geometry": "F1"}


def test_coefficient_table():
    B = 6
    rng = np.random.default_rng(3)
    c = random_coeffs(B, rng)
    t = interop.s2_coefficient_table(c)
    assert t.shape == (B, 2 * B - 1)
    for l, m in so3fft.s2_coef_degrees_orders(B):
        assert t[l, m + B - 1] == c[so3fft.s2_coef_index(B, l, m)]
    l = np.arange(B)[:, None]
    m = np.arange(-(B - 1), B)[None, :]
    assert not t[np.abs(m) > l].any()
    np.testing.assert_array_equal(interop.s2_from_table(t), c)
    many = np.stack([c, 3 * c])
    assert interop.s2_coefficient_table(many).shape == (2, B, 2 * B - 1)
    np.testing.assert_array_equal(interop.s2_from_table(interop.s2_coefficient_table(many)), many)
    with pytest.raises(ValueError):
        interop.s2_from_table(np.zeros((3, 4)))
    with pytest.raises(ValueError):
        interop.s2_coefficient_table(np.zeros((2, 2, 4)))


# ----------------------------------------------------------------------------------------
# SO(3): Wigner matrices and coefficients


def test_wigner_d_reference_data():
    if not WIGNER_CSV.exists():
        pytest.skip("wigner_d_reference.csv not present")
    with WIGNER_CSV.open() as fh:
        rows = [r for r in csv.reader(ln for ln in fh if not ln.startswith("#"))][1:]
    cache, worst = {}, 0.0
    for l, M, Mp, beta, d in rows:
        l, M, Mp = int(l), int(M), int(Mp)
        if l > 127:
            continue
        key = (l, beta)
        if key not in cache:
            cache[key] = interop.wigner_d_small(l, float(beta))
        worst = max(worst, abs(cache[key][M + l, Mp + l] - float(d)))
    assert len(cache) > 20
    assert worst < 1e-13


def test_wigner_d_conventions():
    b = 0.83
    d1 = interop.wigner_d_small(1, b)
    assert np.isclose(d1[2, 1], -np.sin(b) / np.sqrt(2), rtol=0, atol=1e-15)  # d^1_{1,0}
    assert np.isclose(d1[2, 2], (1 + np.cos(b)) / 2, rtol=0, atol=1e-15)  # d^1_{1,1}
    for l in (2, 5):
        d = interop.wigner_d_small(l, b)
        np.testing.assert_allclose(d @ d.T, np.eye(2 * l + 1), atol=1e-14)
        m = np.arange(-l, l + 1)
        sign = (-1.0) ** np.abs(m[:, None] - m[None, :])
        np.testing.assert_allclose(d, sign * d.T, atol=1e-15)  # d_{m m'} = (-1)^(m-m') d_{m' m}
    np.testing.assert_allclose(interop.wigner_d_small(3, 0.0), np.eye(7), atol=1e-15)
    with pytest.raises(ValueError):
        interop.wigner_d_small(-1, 0.1)
    with pytest.raises(ValueError):
        interop.wigner_d_small(2, np.nan)


def test_wigner_D_is_a_representation():
    # D(g1) D(g2) = D(g1 g2) with g = Rz(alpha) Ry(beta) Rz(gamma): fixes the pairing of
    # m with alpha and m' with gamma and the signs of the exponents
    g1 = so3fft.Rotation(0.3, 1.2, -0.7)
    g2 = so3fft.Rotation(2.0, 0.4, 1.1)
    g12 = so3fft.Rotation.from_matrix(g1.as_matrix() @ g2.as_matrix())
    for l in (1, 2, 4):
        lhs = interop.wigner_D(l, *g1) @ interop.wigner_D(l, *g2)
        np.testing.assert_allclose(lhs, interop.wigner_D(l, *g12), atol=1e-13)
    # l = 1 in the spherical basis e_{+1} = -(x + iy)/sqrt2, e_0 = z, e_{-1} = (x - iy)/sqrt2
    u = np.array([[-1, -1j, 0], [0, 0, np.sqrt(2)], [1, -1j, 0]]) / np.sqrt(2)
    u = u[::-1]  # rows m = -1, 0, 1
    np.testing.assert_allclose(
        interop.wigner_D(1, *g1), u.conj() @ g1.as_matrix() @ u.T, atol=1e-14
    )


@pytest.mark.parametrize("conjugate", [False, True])
def test_so3_coefficients_against_wigner_D(conjugate):
    B = 4
    rng = np.random.default_rng(6 + conjugate)
    n = so3fft.num_coeffs(B)
    fhat = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    c = interop.so3_to_wigner_coefficients(fhat, conjugate=conjugate)
    assert c.shape == (B, 2 * B - 1, 2 * B - 1)
    rots = rng.uniform([0, 0, 0], [2 * np.pi, np.pi, 2 * np.pi], (6, 3))
    truth = []
    for a, b, g in rots:
        total = 0
        for l in range(B):
            D = interop.wigner_D(l, a, b, g)
            block = c[l, B - 1 - l : B + l, B - 1 - l : B + l]
            total += np.sum(block * (D.conj() if conjugate else D))
        truth.append(total)
    got = so3fft.evaluate(fhat, rots)
    assert rel_err(got, np.array(truth)) < 1e-12
    back = interop.so3_from_wigner_coefficients(c, conjugate=conjugate)
    assert np.abs(back - fhat).max() < 1e-14 * np.abs(fhat).max()
    # the dense form is accepted as well
    np.testing.assert_array_equal(
        interop.so3_to_wigner_coefficients(so3fft.to_dense(fhat), conjugate=conjugate), c
    )


def test_so3_inverse_on_grid_against_wigner_D():
    B = 3
    rng = np.random.default_rng(8)
    n = so3fft.num_coeffs(B)
    fhat = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    f = so3fft.Plan(B).inverse(fhat)
    alpha, beta, gamma = so3fft.grid_angles(B)
    c = interop.so3_to_wigner_coefficients(fhat)
    for k, j, i in [(0, 0, 0), (1, 2, 3), (5, 4, 1), (3, 5, 5)]:
        total = sum(
            np.sum(c[l, B - 1 - l : B + l, B - 1 - l : B + l]
                   * interop.wigner_D(l, alpha[j], beta[k], gamma[i]))
            for l in range(B)
        )
        assert abs(f[k, j, i] - total) < 1e-13 * np.abs(f).max()


def test_so3_coefficient_validation():
    with pytest.raises(ValueError):
        interop.so3_to_wigner_coefficients(np.zeros(11, complex))
    with pytest.raises(ValueError):
        interop.so3_to_wigner_coefficients(np.zeros((2, 3, 4), complex))
    with pytest.raises(ValueError):
        interop.so3_from_wigner_coefficients(np.zeros((2, 2, 2), complex))
    with pytest.raises(ValueError):
        interop.so3_to_wigner_coefficients(np.zeros((2, 3, 3)), B=3)
