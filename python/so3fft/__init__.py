"""so3fft: the fast Fourier transform on the rotation group SO(3), spherical-harmonic
transforms on S^2 and rotational matching, in SOFT 2.0's conventions.

Main objects:

- :class:`Plan` -- forward and inverse SO(3) transform at bandwidth ``B``;
- :class:`S2Plan` -- forward and inverse S^2 transform;
- :class:`Correlation`, :func:`correlate`, :func:`top_peaks`, :func:`refine` -- rotational
  matching (the correlation grid, its peaks, refinement off the grid);
- :class:`Rotation` -- z-y-z Euler angles, matrices, quaternions, SciPy's rotations;
- :mod:`so3fft.interop` -- conversions to ducc0's and SciPy's conventions.

Precision: every plan takes ``dtype=numpy.float64`` (the default) or ``numpy.float32``
(``float32`` and ``complex64`` arrays; see ``help(so3fft.Plan)``).

Layouts (see ``help(so3fft.Plan)``): SO(3) samples ``(2B, 2B, 2B)`` indexed
``[beta, alpha, gamma]``, coefficients flat in SOFT's order (:func:`coef_index`,
:func:`to_dense`); S^2 samples ``(2B, 2B)`` indexed ``[theta, phi]``, coefficients flat
(:func:`s2_coef_index`).
"""

from ._so3fft import __version__
from ._layout import (
    MAX_BANDWIDTH,
    S2_MAX_BANDWIDTH,
    coef_degrees_orders,
    coef_index,
    from_dense,
    grid_angles,
    num_coeffs,
    num_samples,
    s2_coef_degrees_orders,
    s2_coef_index,
    s2_grid_angles,
    s2_num_coeffs,
    to_dense,
    weights,
)
from ._matching import (
    Correlation,
    Peak,
    Rotation,
    correlate,
    evaluate,
    refine,
    rotate_s2_coeffs,
    top_peaks,
)
from ._transforms import Plan, S2Plan

__all__ = [
    "__version__",
    "MAX_BANDWIDTH",
    "S2_MAX_BANDWIDTH",
    "Plan",
    "S2Plan",
    "Correlation",
    "Peak",
    "Rotation",
    "correlate",
    "top_peaks",
    "refine",
    "evaluate",
    "rotate_s2_coeffs",
    "coef_index",
    "coef_degrees_orders",
    "num_coeffs",
    "num_samples",
    "to_dense",
    "from_dense",
    "grid_angles",
    "weights",
    "s2_coef_index",
    "s2_coef_degrees_orders",
    "s2_num_coeffs",
    "s2_grid_angles",
]
