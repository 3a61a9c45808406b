"""Sizes, indices, the sampling grids, quadrature weights, and the dense ``(l, m, m')``
view of SO(3) coefficients."""

from __future__ import annotations

import functools
from typing import Optional, Tuple

import numpy as np
from numpy.typing import ArrayLike

from . import _so3fft
from ._arrays import as_input, bandwidth_arg

MAX_BANDWIDTH = _so3fft.MAX_BANDWIDTH
S2_MAX_BANDWIDTH = _so3fft.S2_MAX_BANDWIDTH


def num_coeffs(B: int) -> int:
    """Number of SO(3) coefficients at bandwidth ``B``: ``(4B^3 - B) / 3``."""
    return _so3fft.num_coeffs(bandwidth_arg(B))


def num_samples(B: int) -> int:
    """Number of SO(3) samples at bandwidth ``B``: ``(2B)^3``."""
    return _so3fft.num_samples(bandwidth_arg(B))


def _index_args(*values):
    for v in values:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            raise TypeError(f"degrees and orders are integers, not {v!r}")
    return [int(v) for v in values]


def coef_index(B: int, l: int, m: int, mp: int) -> int:
    """Index of ``fhat(l, m, mp)`` in the flat coefficient array (SOFT's ``so3CoefLoc``;
    ``m`` pairs with alpha, ``mp`` with gamma). ``ValueError`` if it does not exist."""
    return _so3fft.coef_index(bandwidth_arg(B), *_index_args(l, m, mp))


@functools.lru_cache(maxsize=8)
def _degrees_orders(B):
    a = _so3fft.coef_degrees_orders(B)
    a.setflags(write=False)
    return a


def coef_degrees_orders(B: int) -> np.ndarray:
    """``(l, m, mp)`` of every coefficient, in the flat array's order: an integer array of
    shape ``(num_coeffs(B), 3)``."""
    return _degrees_orders(bandwidth_arg(B)).copy()


def to_dense(fhat: ArrayLike, B: Optional[int] = None) -> np.ndarray:
    """SO(3) coefficients as a dense array ``D[l, m + B - 1, mp + B - 1]`` of shape
    ``(B, 2B - 1, 2B - 1)`` (zero where ``|m|`` or ``|mp|`` exceeds ``l``), the ``(l, m,
    m')`` indexing many Python packages use. ``B`` is found from the length if not given."""
    fhat = np.asarray(fhat)
    if B is None:
        B = _bandwidth_of(fhat.size)
    fhat = as_input(fhat, np.complex128, ((num_coeffs(B),),), "coefficients")
    lmm = _degrees_orders(B)
    dense = np.zeros((B, 2 * B - 1, 2 * B - 1), np.complex128)
    dense[lmm[:, 0], lmm[:, 1] + B - 1, lmm[:, 2] + B - 1] = fhat
    return dense


def from_dense(dense: ArrayLike) -> np.ndarray:
    """The flat coefficient array of a dense ``(B, 2B - 1, 2B - 1)`` array (see
    :func:`to_dense`); entries with ``|m| > l`` or ``|mp| > l`` are ignored."""
    dense = np.asarray(dense)
    if dense.ndim != 3 or dense.shape[1] != dense.shape[2] or dense.shape[1] != 2 * dense.shape[0] - 1:
        raise ValueError(f"a dense array has shape (B, 2B - 1, 2B - 1), not {dense.shape}")
    B = dense.shape[0]
    lmm = _degrees_orders(bandwidth_arg(B))
    return np.ascontiguousarray(
        dense[lmm[:, 0], lmm[:, 1] + B - 1, lmm[:, 2] + B - 1], dtype=np.complex128
    )


def _bandwidth_of(n):
    B = 1
    while (4 * B**3 - B) // 3 < n:
        B += 1
    if (4 * B**3 - B) // 3 != n:
        raise ValueError(f"{n} is not a number of SO(3) coefficients ((4B^3 - B) / 3)")
    return B


def grid_angles(B: int) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The SO(3) grid's angles ``(alpha, beta, gamma)``, ``2B`` values each:
    ``alpha_j = pi j / B``, ``beta_k = pi (2k + 1) / (4B)``, ``gamma_i = pi i / B``. Sample
    ``[k, j, i]`` is the function at ``(alpha_j, beta_k, gamma_i)``."""
    return _so3fft.grid_angles(bandwidth_arg(B))


def weights(B: int) -> np.ndarray:
    """Quadrature weights of the beta (or theta) grid, ``2B`` values; with them
    ``sum_k w_k g(beta_k)`` integrates ``g(beta) sin(beta) dbeta`` exactly for band-limited
    ``g``."""
    return _so3fft.weights(bandwidth_arg(B))


def s2_num_coeffs(B: int) -> int:
    """Number of S^2 coefficients at bandwidth ``B``: ``B^2``."""
    return _so3fft.s2_num_coeffs(bandwidth_arg(B))


def s2_coef_index(B: int, l: int, m: int) -> int:
    """Index of ``fhat(l, m)`` in the flat S^2 coefficient array (SOFT's ``seanindex``)."""
    return _so3fft.s2_coef_index(bandwidth_arg(B), *_index_args(l, m))


@functools.lru_cache(maxsize=8)
def _s2_degrees_orders(B):
    a = _so3fft.s2_coef_degrees_orders(B)
    a.setflags(write=False)
    return a


def s2_coef_degrees_orders(B: int) -> np.ndarray:
    """``(l, m)`` of every S^2 coefficient in the flat array's order: shape ``(B^2, 2)``."""
    return _s2_degrees_orders(bandwidth_arg(B)).copy()


def s2_grid_angles(B: int) -> Tuple[np.ndarray, np.ndarray]:
    """The S^2 grid's angles ``(theta, phi)``, ``2B`` values each:
    ``theta_j = pi (2j + 1) / (4B)``, ``phi_k = pi k / B``; sample ``[j, k]`` is the function
    at ``(theta_j, phi_k)``."""
    alpha, beta, _ = grid_angles(B)
    return beta, alpha
