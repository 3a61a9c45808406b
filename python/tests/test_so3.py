"""SO(3) transforms, layout helpers, grid and weights against independent truths: round
trips, the repository's 40-digit reference data, direct summation with an explicit Wigner-d
formula, closed forms of docs/conventions.md, quadrature identities, linearity and the real
symmetry."""

import ast
import inspect
import math
from pathlib import Path

import numpy as np
import pytest

import so3fft
from so3fft import _so3fft
from conftest import random_coeffs

# ---------------------------------------------------------------------------------------
# Independent truths


def wigner_d(l, m, mp, beta):
    """``d^l_{m, mp}(beta)`` by the explicit (Wigner) sum with factorials, Varshalovich's and
    Edmonds' convention (``d^1_{1,0} = -sin(beta) / sqrt(2)``); fine for small ``l``."""
    beta = np.asarray(beta, dtype=float)
    f = math.factorial
    pre = math.sqrt(f(l + m) * f(l - m) * f(l + mp) * f(l - mp))
    c, s = np.cos(beta / 2), np.sin(beta / 2)
    total = np.zeros_like(beta)
    for k in range(max(0, mp - m), min(l + mp, l - m) + 1):
        den = f(l + mp - k) * f(k) * f(m - mp + k) * f(l - m - k)
        total = total + (-1) ** (m - mp + k) / den * c ** (2 * l + mp - m - 2 * k) * s ** (
            m - mp + 2 * k
        )
    return pre * total


def basis_function(B, l, m, mp):
    """``sqrt((2l+1)/2) / (2 pi) e^{-i m alpha} d^l_{m mp}(beta) e^{-i mp gamma}`` on the
    grid of docs/conventions.md (``alpha_j = pi j / B``, ``beta_k = pi (2k+1) / (4B)``,
    ``gamma_i = pi i / B``), indexed ``[k, j, i]``; angles computed here, not by so3fft."""
    n = 2 * B
    alpha = np.pi * np.arange(n) / B
    beta = np.pi * (2 * np.arange(n) + 1) / (4 * B)
    gamma = np.pi * np.arange(n) / B
    d = wigner_d(l, m, mp, beta)
    return (
        math.sqrt((2 * l + 1) / 2)
        / (2 * np.pi)
        * d[:, None, None]
        * np.exp(-1j * m * alpha)[None, :, None]
        * np.exp(-1j * mp * gamma)[None, None, :]
    )


def soft_index(B, m, mp, l):
    """SOFT's ``so3CoefLoc(m, mp, l, B)`` by the closed form of docs/conventions.md."""
    T = (4 * B**3 - B) // 3
    a = abs(m)
    if m >= 0:
        row = m * B * B - (m - 1) * m * (2 * m - 1) // 6
    else:
        row = T - (a * B * B - a * (a + 1) * (2 * a + 1) // 6)
    if mp >= 0:
        off = sum(B - max(a, k) for k in range(mp))
    else:
        off = (B * B - m * m) - sum(B - max(a, abs(k)) for k in range(mp, 0))
    return row + off + (l - max(a, abs(mp)))


def read_reference(path):
    """``(B, coefficients, samples)`` of a tests/data/transform_*.txt file: the flat
    coefficient array (placed with the closed-form index of docs/conventions.md) and the
    ``(2B, 2B, 2B)`` samples indexed ``[beta, alpha, gamma]``."""
    B = None
    section = None
    coefs, samples = [], []
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        head = line.split()
        if head[0] == "B":
            B = int(head[1])
        elif head[0] in ("coef", "sample"):
            section = head[0]
        elif section == "coef":
            l, m, mp = map(int, head[:3])
            coefs.append((l, m, mp, complex(float(head[3]), float(head[4]))))
        elif section == "sample":
            k, j1, j2 = map(int, head[:3])
            samples.append((k, j1, j2, complex(float(head[3]), float(head[4]))))
    n = 2 * B
    c = np.full((4 * B**3 - B) // 3, np.nan, complex)
    for l, m, mp, v in coefs:
        c[soft_index(B, m, mp, l)] = v
    f = np.full((n, n, n), np.nan, complex)
    for k, j1, j2, v in samples:
        f[k, j1, j2] = v
    assert not np.isnan(c).any() and not np.isnan(f).any(), "reference file not fully read"
    return B, c, f


def max_err(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))))


# ---------------------------------------------------------------------------------------
# Round trips


@pytest.mark.parametrize("B", [1, 2, 5, 16, 32])
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("real", [False, True])
def test_round_trip(rng, B, threads, real):
    plan = so3fft.Plan(B, real=real, threads=threads)
    assert plan.B == B and plan.real == real
    assert plan.sample_shape == (2 * B,) * 3 and plan.num_coeffs == (4 * B**3 - B) // 3
    c = random_coeffs(rng, B, real=real)
    f = plan.inverse(c)
    assert f.shape == (2 * B,) * 3
    assert f.dtype == (np.float64 if real else np.complex128)
    back = plan.forward(f)
    assert back.dtype == np.complex128 and back.shape == c.shape
    assert max_err(back, c) < 1e-12 * max(1.0, B / 8)


@pytest.mark.parametrize("real", [False, True])
def test_out_arrays_are_used_and_returned(rng, real):
    B = 5
    plan = so3fft.Plan(B, real=real, threads=1)
    c = random_coeffs(rng, B, real=real)
    f_out = np.full(plan.sample_shape, np.nan, np.float64 if real else np.complex128)
    f = plan.inverse(c, out=f_out)
    assert f is f_out
    c_out = np.full(plan.num_coeffs, np.nan, np.complex128)
    back = plan.forward(f_out, out=c_out)
    assert back is c_out
    assert max_err(c_out, c) < 1e-12


def test_input_dtypes_are_converted(rng):
    B = 4
    plan = so3fft.Plan(B, threads=1)
    rplan = so3fft.Plan(B, real=True, threads=1)
    ints = rng.integers(-5, 6, size=(2 * B,) * 3)
    want = plan.forward(ints.astype(np.complex128))
    # int, float32, complex64 samples to a complex plan; int, float32, bool to a real one.
    assert max_err(plan.forward(ints), want) == 0.0
    assert max_err(plan.forward(ints.astype(np.float32)), want) == 0.0
    assert max_err(plan.forward(ints.astype(np.complex64)), want) == 0.0
    assert max_err(rplan.forward(ints), rplan.forward(ints.astype(np.float64))) == 0.0
    assert max_err(rplan.forward(ints.astype(np.float32)), rplan.forward(ints * 1.0)) == 0.0
    assert max_err(rplan.forward(ints > 0), rplan.forward((ints > 0) * 1.0)) == 0.0
    # Nested lists, and coefficients as a list of Python complex numbers.
    assert max_err(plan.forward(ints.tolist()), want) == 0.0
    c = random_coeffs(rng, B)
    assert max_err(plan.inverse(c.tolist()), plan.inverse(c)) == 0.0
    c64 = c.astype(np.complex64)
    assert max_err(plan.inverse(c64), plan.inverse(c64.astype(np.complex128))) == 0.0
    # Real coefficients (zero imaginary parts).
    re = c.real.copy()
    assert max_err(plan.inverse(re), plan.inverse(re + 0j)) == 0.0


def test_tiny_bandwidth_one_from_lists():
    # B = 1: one coefficient, fhat(0,0,0); f = fhat sqrt(1/2) / (2 pi) everywhere.
    plan = so3fft.Plan(1, threads=1)
    f = plan.inverse([2.0 + 1.0j])
    assert f.shape == (2, 2, 2)
    assert np.allclose(f, (2 + 1j) * math.sqrt(0.5) / (2 * math.pi), rtol=0, atol=1e-15)
    c = plan.forward([[[1, 1], [1, 1]], [[1, 1], [1, 1]]])
    # The constant 1: fhat(0,0,0) = <1, Dt^0_{00}> = 8 pi^2 (the volume of SO(3)) * sqrt(1/2) / (2 pi).
    assert abs(c[0] - 8 * math.pi**2 * math.sqrt(0.5) / (2 * math.pi)) < 1e-13


@pytest.mark.parametrize("real", [False, True])
def test_non_contiguous_inputs(rng, real):
    B = 4
    n = 2 * B
    plan = so3fft.Plan(B, real=real, threads=1)
    dtype = np.float64 if real else np.complex128
    big = np.zeros((n, n, 2 * n), dtype)
    big[:, :, ::2] = rng.standard_normal((n, n, n))
    if not real:
        big[:, :, ::2] += 1j * rng.standard_normal((n, n, n))
    view = big[:, :, ::2]
    assert not view.flags.c_contiguous
    want = plan.forward(np.ascontiguousarray(view))
    assert max_err(plan.forward(view), want) == 0.0
    # A Fortran-ordered copy and a transposed view hold the same values at the same indices.
    assert max_err(plan.forward(np.asfortranarray(view)), want) == 0.0
    t = np.ascontiguousarray(view.transpose(2, 1, 0)).transpose(2, 1, 0)
    assert max_err(plan.forward(t), want) == 0.0
    # Strided coefficients.
    c = random_coeffs(rng, B, real=real)
    cbig = np.zeros(2 * c.size, complex)
    cbig[::2] = c
    assert max_err(plan.inverse(cbig[::2]), plan.inverse(c)) == 0.0
    # The inputs are not modified.
    assert np.array_equal(view, big[:, :, ::2]) and np.array_equal(cbig[::2], c)


@pytest.mark.parametrize("real", [False, True])
def test_flat_samples_accepted(rng, real):
    B = 5
    plan = so3fft.Plan(B, real=real, threads=1)
    f = plan.inverse(random_coeffs(rng, B, real=real))
    assert max_err(plan.forward(f.reshape(-1)), plan.forward(f)) == 0.0


def test_inputs_not_modified(rng):
    B = 4
    plan = so3fft.Plan(B, threads=1)
    c = random_coeffs(rng, B)
    c0 = c.copy()
    f = plan.inverse(c)
    f0 = f.copy()
    plan.forward(f)
    assert np.array_equal(c, c0) and np.array_equal(f, f0)


# ---------------------------------------------------------------------------------------
# Reference data (40-digit mpmath, tests/data/gen_reference.py)

REFERENCE_TOL = 1e-13  # as tests/reference.rs


def test_reference_b4_complex(data_dir):
    B, c, f = read_reference(data_dir / "transform_B4_complex.txt")
    assert B == 4
    plan = so3fft.Plan(B, threads=1)
    assert max_err(plan.forward(f), c) < REFERENCE_TOL
    assert max_err(plan.inverse(c), f) < REFERENCE_TOL


def test_reference_b8_real(data_dir):
    B, c, f = read_reference(data_dir / "transform_B8_real.txt")
    assert B == 8
    assert np.max(np.abs(f.imag)) < 1e-14  # the file's samples are real
    for threads in (1, 2):
        plan = so3fft.Plan(B, threads=threads)
        assert max_err(plan.forward(f), c) < REFERENCE_TOL
        assert max_err(plan.inverse(c), f) < REFERENCE_TOL
        rplan = so3fft.Plan(B, real=True, threads=threads)
        assert max_err(rplan.forward(f.real), c) < REFERENCE_TOL
        assert max_err(rplan.inverse(c), f.real) < REFERENCE_TOL


# ---------------------------------------------------------------------------------------
# Direct summation


def test_wigner_formula_sign_and_symmetries():
    beta = np.linspace(0.1, 3.0, 7)
    assert np.allclose(wigner_d(1, 1, 0, beta), -np.sin(beta) / math.sqrt(2), atol=1e-15)
    assert np.allclose(wigner_d(1, 0, 1, beta), np.sin(beta) / math.sqrt(2), atol=1e-15)
    assert np.allclose(wigner_d(1, 1, 1, beta), (1 + np.cos(beta)) / 2, atol=1e-15)
    assert np.allclose(wigner_d(2, 0, 0, beta), (3 * np.cos(beta) ** 2 - 1) / 2, atol=1e-15)
    for l in range(4):
        for m in range(-l, l + 1):
            for mp in range(-l, l + 1):
                d = wigner_d(l, m, mp, beta)
                assert np.allclose(d, (-1) ** (m - mp) * wigner_d(l, mp, m, beta), atol=1e-14)
                assert np.allclose(d, wigner_d(l, -mp, -m, beta), atol=1e-14)


def test_inverse_of_each_coefficient_by_direct_summation():
    B = 4
    plan = so3fft.Plan(B, threads=1)
    rplan = so3fft.Plan(B, real=True, threads=1)
    n = so3fft.num_coeffs(B)
    worst = 0.0
    for l in range(B):
        for m in range(-l, l + 1):
            for mp in range(-l, l + 1):
                c = np.zeros(n, complex)
                c[so3fft.coef_index(B, l, m, mp)] = 1.0
                want = basis_function(B, l, m, mp)
                got = plan.inverse(c)
                worst = max(worst, max_err(got, want))
                # The forward of one basis function is that unit coefficient (orthonormality).
                assert max_err(plan.forward(want), c) < 1e-13
    assert worst < 1e-14
    # A real combination, through the real plan: fhat(l,m,m') = 1, fhat(l,-m,-m') = (-1)^(m-m').
    c = np.zeros(n, complex)
    c[so3fft.coef_index(B, 3, 2, -1)] = 0.5 - 0.25j
    c[so3fft.coef_index(B, 3, -2, 1)] = (-1) ** 3 * (0.5 + 0.25j)
    want = (0.5 - 0.25j) * basis_function(B, 3, 2, -1) - (0.5 + 0.25j) * basis_function(B, 3, -2, 1)
    assert np.max(np.abs(want.imag)) < 1e-15
    assert max_err(rplan.inverse(c), want.real) < 1e-14
    assert max_err(rplan.forward(want.real), c) < 1e-13


def test_random_coefficients_by_direct_summation(rng):
    B = 4
    c = random_coeffs(rng, B)
    want = sum(
        c[so3fft.coef_index(B, l, m, mp)] * basis_function(B, l, m, mp)
        for l in range(B)
        for m in range(-l, l + 1)
        for mp in range(-l, l + 1)
    )
    plan = so3fft.Plan(B, threads=2)
    assert max_err(plan.inverse(c), want) < 1e-13
    assert max_err(plan.forward(want), c) < 1e-13


# ---------------------------------------------------------------------------------------
# Layout


def test_sizes():
    for B in (1, 2, 3, 7, 100, 2048):
        assert so3fft.num_coeffs(B) == (4 * B**3 - B) // 3
        assert so3fft.num_samples(B) == 8 * B**3
        assert so3fft.s2_num_coeffs(B) == B * B
        assert _so3fft.s2_num_samples(B) == 4 * B * B
    assert so3fft.MAX_BANDWIDTH == 2048


def test_coef_index_spot_values_of_the_docs():
    # docs/conventions.md, written (M, M', l) -> index at B = 256.
    B = 256
    spots = {
        (0, 0, 0): 0,
        (0, 0, 255): 255,
        (0, 1, 1): 256,
        (0, -1, 1): 65281,
        (1, 0, 1): 65536,
        (-1, 0, 1): 22304001,
        (-1, -1, 255): 22369535,
    }
    for (m, mp, l), i in spots.items():
        assert so3fft.coef_index(B, l, m, mp) == i
        assert soft_index(B, m, mp, l) == i
    assert so3fft.num_coeffs(B) - 1 == 22369535


@pytest.mark.parametrize("B", [1, 2, 5, 9])
def test_coef_index_and_degrees_orders(B):
    lmm = so3fft.coef_degrees_orders(B)
    assert lmm.shape == (so3fft.num_coeffs(B), 3)
    seen = set()
    for l in range(B):
        for m in range(-l, l + 1):
            for mp in range(-l, l + 1):
                i = so3fft.coef_index(B, l, m, mp)
                assert i == soft_index(B, m, mp, l)
                assert tuple(lmm[i]) == (l, m, mp)
                seen.add(i)
    assert seen == set(range(so3fft.num_coeffs(B)))
    # numpy integers are accepted as indices.
    assert so3fft.coef_index(np.int64(B), np.int32(B - 1), np.int8(0), 0) == soft_index(B, 0, 0, B - 1)


@pytest.mark.parametrize("B", [1, 3, 6])
def test_dense_view(rng, B):
    c = random_coeffs(rng, B)
    d = so3fft.to_dense(c)
    assert d.shape == (B, 2 * B - 1, 2 * B - 1)
    assert np.array_equal(so3fft.to_dense(c, B), d)
    for l in range(B):
        for m in range(-(B - 1), B):
            for mp in range(-(B - 1), B):
                v = d[l, m + B - 1, mp + B - 1]
                if abs(m) > l or abs(mp) > l:
                    assert v == 0
                else:
                    assert v == c[so3fft.coef_index(B, l, m, mp)]
    assert np.array_equal(so3fft.from_dense(d), c)
    # Entries outside the triangle are ignored.
    d2 = d.copy()
    d2[0, 0, 0] = 99.0  # l = 0, m = -(B-1): does not exist for B > 1
    if B > 1:
        assert np.array_equal(so3fft.from_dense(d2), c)
    # to_dense of a list.
    assert np.array_equal(so3fft.to_dense(list(c)), d)


@pytest.mark.parametrize("B", [1, 4, 9])
def test_s2_layout(B):
    lm = so3fft.s2_coef_degrees_orders(B)
    assert lm.shape == (B * B, 2)
    L = B - 1
    for l in range(B):
        for m in range(-l, l + 1):
            i = so3fft.s2_coef_index(B, l, m)
            # seanindex of docs/conventions-s2.md.
            if m >= 0:
                want = m * B - m * (m - 1) // 2 + (l - m)
            else:
                a = -m
                want = L * (L + 3) // 2 + 1 + (L - a) * (L - a + 1) // 2 + (l - a)
            assert i == want
            assert tuple(lm[i]) == (l, m)


# ---------------------------------------------------------------------------------------
# Grid and weights


@pytest.mark.parametrize("B", [1, 3, 8])
def test_grid_angles(B):
    alpha, beta, gamma = so3fft.grid_angles(B)
    j = np.arange(2 * B)
    assert np.allclose(alpha, np.pi * j / B, rtol=0, atol=1e-15)
    assert np.allclose(gamma, np.pi * j / B, rtol=0, atol=1e-15)
    assert np.allclose(beta, np.pi * (2 * j + 1) / (4 * B), rtol=0, atol=1e-15)
    theta, phi = so3fft.s2_grid_angles(B)
    assert np.array_equal(theta, beta) and np.array_equal(phi, alpha)


@pytest.mark.parametrize("B", [1, 2, 5, 16, 64])
def test_weights_integrate_polynomials_exactly(B):
    w = so3fft.weights(B)
    assert w.shape == (2 * B,)
    beta = np.pi * (2 * np.arange(2 * B) + 1) / (4 * B)
    # The closed form of docs/conventions.md.
    i = np.arange(B)
    closed = (2 / B) * np.sin(beta) * np.sum(
        np.sin(np.outer(beta, 2 * i + 1)) / (2 * i + 1), axis=1
    )
    assert np.allclose(w, closed, rtol=0, atol=1e-15)
    # sum_k w_k P(cos beta_k) = int_0^pi P(cos beta) sin(beta) dbeta = int_{-1}^1 P(x) dx
    # for every polynomial of degree < 2B: Legendre polynomials integrate to 2 (n = 0) and 0.
    x = np.cos(beta)
    for n in range(2 * B):
        p = np.polynomial.legendre.Legendre.basis(n)(x)
        assert abs(np.dot(w, p) - (2.0 if n == 0 else 0.0)) < 1e-13
    # Monomials, and a random polynomial of degree 2B - 1.
    for n in range(min(2 * B, 12)):
        assert abs(np.dot(w, x**n) - (2 / (n + 1) if n % 2 == 0 else 0)) < 1e-13
    coeffs = np.random.default_rng(B).standard_normal(2 * B)
    poly = np.polynomial.Polynomial(coeffs)
    exact = poly.integ()(1.0) - poly.integ()(-1.0)
    assert abs(np.dot(w, poly(x)) - exact) < 1e-12 * max(1, np.abs(coeffs).sum())


# ---------------------------------------------------------------------------------------
# Linearity and the real symmetry


def test_linearity(rng):
    B = 6
    n = 2 * B
    plan = so3fft.Plan(B, threads=2)
    x = rng.standard_normal((n, n, n)) + 1j * rng.standard_normal((n, n, n))
    y = rng.standard_normal((n, n, n)) + 1j * rng.standard_normal((n, n, n))
    a, b = 0.7 - 1.3j, -2.1 + 0.4j
    lhs = plan.forward(a * x + b * y)
    rhs = a * plan.forward(x) + b * plan.forward(y)
    assert max_err(lhs, rhs) < 1e-12
    c, d = random_coeffs(rng, B), random_coeffs(rng, B)
    assert max_err(plan.inverse(a * c + b * d), a * plan.inverse(c) + b * plan.inverse(d)) < 1e-12


@pytest.mark.parametrize("B", [3, 8])
def test_real_symmetry_of_the_forward(rng, B):
    n = 2 * B
    f = rng.standard_normal((n, n, n))  # real and not band-limited
    complex_plan = so3fft.Plan(B, threads=1)
    real_plan = so3fft.Plan(B, real=True, threads=1)
    for c in (complex_plan.forward(f.astype(complex)), real_plan.forward(f)):
        d = so3fft.to_dense(c, B)
        m = np.arange(-(B - 1), B)
        sign = (-1.0) ** (m[:, None] - m[None, :])
        assert max_err(d[:, ::-1, ::-1], sign * np.conj(d)) < 1e-13
    assert max_err(complex_plan.forward(f.astype(complex)), real_plan.forward(f)) < 1e-13


def test_real_inverse_gives_real_part_of_complex_inverse(rng):
    B = 7
    c = random_coeffs(rng, B, real=True)
    f = so3fft.Plan(B, threads=1).inverse(c)
    assert np.max(np.abs(f.imag)) < 1e-13
    assert max_err(so3fft.Plan(B, real=True, threads=1).inverse(c), f.real) < 1e-13


# ---------------------------------------------------------------------------------------
# The type stubs describe the extension


def _stub():
    """``{name: (params or None, {member: params or "property"})}`` of the stub file."""
    stub = Path(so3fft.__file__).with_name("_so3fft.pyi")
    tree = ast.parse(stub.read_text())

    def params(fn):
        return [a.arg for a in fn.args.args if a.arg != "self"]

    names = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            init, members = None, {}
            for n in node.body:
                if not isinstance(n, ast.FunctionDef):
                    continue
                if n.name == "__init__":
                    init = params(n)
                elif any(isinstance(d, ast.Name) and d.id == "property" for d in n.decorator_list):
                    members[n.name] = "property"
                else:
                    members[n.name] = params(n)
            names[node.name] = (init, members)
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = (params(node), None)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            if not node.target.id.startswith("_") or node.target.id == "__version__":
                names[node.target.id] = (None, None)
    return names


def _runtime_params(obj):
    return [p for p in inspect.signature(obj).parameters if p != "self"]


def test_stub_describes_every_name_of_the_extension():
    stub = _stub()
    runtime = {n for n in dir(_so3fft) if not n.startswith("_") or n == "__version__"}
    runtime.discard("__all__")
    assert set(stub) == runtime
    for name, (sig, members) in stub.items():
        obj = getattr(_so3fft, name)
        if members is not None:  # a class
            assert sig == _runtime_params(obj), name
            public = {n for n in dir(obj) if not n.startswith("_")}
            assert set(members) == public, name
            for m, kind in members.items():
                attr = inspect.getattr_static(obj, m)
                if kind == "property":
                    assert inspect.isdatadescriptor(attr), f"{name}.{m}"
                else:
                    assert callable(attr) and kind == _runtime_params(getattr(obj, m)), f"{name}.{m}"
        elif sig is not None:  # a function
            assert sig == _runtime_params(obj), name
