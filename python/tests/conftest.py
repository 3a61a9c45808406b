"""Shared fixtures of the so3fft Python tests."""

from pathlib import Path

import numpy as np
import pytest

import so3fft

#: The repository's reference data (tests/data), computed independently of so3fft.
DATA = Path(__file__).parents[2] / "tests" / "data"


@pytest.fixture
def rng():
    """A fresh, seeded random generator per test (results do not depend on test order)."""
    return np.random.default_rng(20240611)


@pytest.fixture(scope="session")
def data_dir():
    """The repository's tests/data directory."""
    if not DATA.is_dir():
        pytest.skip(f"reference data not found at {DATA}")
    return DATA


def random_coeffs(rng, B, real=False):
    """Random SO(3) coefficients at bandwidth ``B``; with ``real``, those of a real function
    (``fhat(l, -m, -m') = (-1)^(m - m') conj(fhat(l, m, m'))``), built on the dense view."""
    n = so3fft.num_coeffs(B)
    c = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    if not real:
        return c
    d = so3fft.to_dense(c, B)
    m = np.arange(-(B - 1), B)
    sign = (-1.0) ** (m[:, None] - m[None, :])
    # Entry [l, m, m'] mirrored is [l, -m, -m'] (both order axes reversed).
    d = 0.5 * (d + sign * np.conj(d[:, ::-1, ::-1]))
    return so3fft.from_dense(d)


def random_s2_coeffs(rng, B, real=False):
    """Random S^2 coefficients at bandwidth ``B`` (flat ``seanindex`` order); with ``real``,
    those of a real function (``fhat(l, -m) = (-1)^m conj(fhat(l, m))``)."""
    lm = so3fft.s2_coef_degrees_orders(B)
    c = rng.standard_normal(B * B) + 1j * rng.standard_normal(B * B)
    if not real:
        return c
    where = {(int(l), int(m)): i for i, (l, m) in enumerate(lm)}
    out = c.copy()
    for i, (l, m) in enumerate(lm):
        j = where[(int(l), -int(m))]
        out[i] = 0.5 * (c[i] + (-1.0) ** m * np.conj(c[j]))
    return out
