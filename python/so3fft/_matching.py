"""Rotational matching: rotations, the correlation plan, peaks, refinement off the grid."""

from __future__ import annotations

import functools
import math
from typing import Iterable, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from . import _so3fft
from ._arrays import (
    apart,
    as_input,
    bandwidth_arg,
    check_output,
    dtype_arg,
    int_arg,
    threads_arg,
)


#: A rotation: a :class:`Rotation` or Euler angles ``(alpha, beta, gamma)``.
RotationLike = Union["Rotation", Sequence[float]]
#: Rotations: one, several, or an ``(n, 3)`` array of Euler angles.
Rotations = Union[RotationLike, Iterable[RotationLike], np.ndarray]


class Rotation:
    """A rotation ``g = Rz(alpha) Ry(beta) Rz(gamma)`` (z-y-z Euler angles in radians, SOFT's
    convention), acting on column vectors.

    It is SciPy's intrinsic ``"ZYZ"``: ``Rotation(a, b, c).to_scipy()`` is
    ``scipy.spatial.transform.Rotation.from_euler("ZYZ", [a, b, c])``. Quaternions are
    ``(w, x, y, z)`` here (SciPy's default order is ``(x, y, z, w)``).
    """

    __slots__ = ("alpha", "beta", "gamma")

    def __init__(self, alpha: float, beta: float, gamma: float) -> None:
        self.alpha = float(alpha)
        self.beta = float(beta)
        self.gamma = float(gamma)
        if not all(map(math.isfinite, (self.alpha, self.beta, self.gamma))):
            raise ValueError(f"Euler angles must be finite, not ({alpha}, {beta}, {gamma})")

    def __repr__(self):
        return f"so3fft.Rotation({self.alpha!r}, {self.beta!r}, {self.gamma!r})"

    def __iter__(self):
        return iter((self.alpha, self.beta, self.gamma))

    def as_euler(self) -> np.ndarray:
        """``(alpha, beta, gamma)`` as an array."""
        return np.array([self.alpha, self.beta, self.gamma])

    def as_matrix(self) -> np.ndarray:
        """The 3x3 rotation matrix."""
        return np.array(_so3fft.euler_to_matrix(self.alpha, self.beta, self.gamma))

    def as_quaternion(self) -> np.ndarray:
        """The unit quaternion ``(w, x, y, z)`` with ``w >= 0``."""
        return np.array(_so3fft.euler_to_quaternion(self.alpha, self.beta, self.gamma))

    def angle_to(self, other: RotationLike) -> float:
        """The angle (radians) of the rotation taking ``self`` to ``other``: the geodesic
        distance on SO(3), accurate for small angles."""
        p, q = self.as_quaternion(), Rotation._of(other).as_quaternion()
        if np.dot(p, q) < 0:
            q = -q
        return 4.0 * math.atan2(np.linalg.norm(p - q), np.linalg.norm(p + q))

    @classmethod
    def from_matrix(cls, matrix: ArrayLike) -> "Rotation":
        """The Euler angles of a rotation matrix (``beta`` in ``[0, pi]``, the others in
        ``(-pi, pi]``; ``gamma = 0`` where ``beta`` is 0 or ``pi``)."""
        r = np.asarray(matrix, dtype=float)
        if r.shape != (3, 3) or not np.all(np.isfinite(r)):
            raise ValueError("a rotation matrix is a finite 3x3 array")
        if not np.allclose(r @ r.T, np.eye(3), atol=1e-6) or np.linalg.det(r) < 0:
            raise ValueError("the matrix is not a rotation (orthogonal, determinant 1)")
        s = math.hypot(r[0, 2], r[1, 2])
        beta = math.atan2(s, r[2, 2])
        if s > 1e-12:
            return cls(math.atan2(r[1, 2], r[0, 2]), beta, math.atan2(r[2, 1], -r[2, 0]))
        if r[2, 2] > 0:
            return cls(math.atan2(r[1, 0], r[0, 0]), 0.0, 0.0)
        return cls(math.atan2(-r[1, 0], -r[0, 0]), math.pi, 0.0)

    @classmethod
    def from_quaternion(cls, q: ArrayLike) -> "Rotation":
        """The rotation of a quaternion ``(w, x, y, z)`` (normalised here)."""
        q = np.asarray(q, dtype=float)
        if q.shape != (4,) or not np.all(np.isfinite(q)) or not np.any(q):
            raise ValueError("a quaternion is four finite numbers (w, x, y, z), not all 0")
        w, x, y, z = q / np.linalg.norm(q)
        return cls.from_matrix(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )

    @classmethod
    def from_scipy(cls, rotation) -> "Rotation":
        """The rotation of a single ``scipy.spatial.transform.Rotation``."""
        return cls.from_matrix(rotation.as_matrix())

    def to_scipy(self):
        """This rotation as a ``scipy.spatial.transform.Rotation``."""
        from scipy.spatial.transform import Rotation as ScipyRotation

        return ScipyRotation.from_euler("ZYZ", [self.alpha, self.beta, self.gamma])

    @staticmethod
    def _of(x):
        return x if isinstance(x, Rotation) else Rotation(*x)


class Peak(NamedTuple):
    """A grid point of a correlation: flat index ``k (2B)^2 + j 2B + i``, its Euler angles
    and ``|C|^2`` there."""

    index: int  # type: ignore[assignment]  # shadows tuple.index on purpose
    alpha: float
    beta: float
    gamma: float
    value: float

    @property
    def rotation(self) -> Rotation:
        """The peak's rotation."""
        return Rotation(self.alpha, self.beta, self.gamma)


def _rows(rotations):
    """Rotations (a ``Rotation``, an angle triple, a list of either, or an ``(n, 3)`` array)
    as a C-contiguous ``(n, 3)`` array of Euler angles."""
    if isinstance(rotations, Rotation):
        rotations = [tuple(rotations)]
    elif not isinstance(rotations, np.ndarray):
        rotations = [tuple(g) if isinstance(g, Rotation) else g for g in rotations]
    a = np.asarray(rotations)
    if np.iscomplexobj(a) or not (a.size == 0 or np.issubdtype(a.dtype, np.number)):
        raise TypeError("rotations are real Euler angles (alpha, beta, gamma)")
    a = a.astype(float)
    if a.ndim == 1 and a.size == 3:
        a = a.reshape(1, 3)
    if a.size == 0:
        a = a.reshape(0, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError("rotations are rows of three Euler angles (alpha, beta, gamma)")
    return np.require(a, requirements=["C", "A"])


class Correlation:
    """The rotational correlation of two functions on the sphere over the SO(3) grid::

        C(g) = integral over S^2 of f(x) conj(h(g^-1 x)) dx

    for a signal ``f`` and a pattern ``h`` sampled on the S^2 grid of bandwidth ``B`` (see
    :class:`S2Plan`), at every rotation ``g`` of the SO(3) grid of bandwidth ``b_out`` (a
    ``(2 b_out)^3`` array laid out as SO(3) samples, see :class:`Plan`). ``C`` is largest
    where the signal is the pattern rotated by ``g``: ``f(x) = h(g^-1 x)``.

    Parameters
    ----------
    B : int
        Bandwidth of the inputs.
    b_out : int, optional
        Bandwidth of the SO(3) grid (default ``B``; larger samples the correlation more
        finely).
    deg_lim : int, optional
        Highest degree combined (default ``min(B, b_out) - 1``).
    real : bool
        Real inputs and a real correlation grid (about half the work).
    normalized : bool
        Normalised cross-correlation: the means left out and the result divided by the
        norms, so ``|C| <= 1`` with 1 for an exact rotated, scaled and shifted copy.
    dtype : numpy dtype or name
        Precision of the inputs and the grid: ``numpy.float64`` (the default) or
        ``numpy.float32`` (inputs and grid ``float32``, or ``complex64`` for a complex
        plan; ``float64`` or ``complex128`` inputs are a ``TypeError``, as for
        :class:`Plan`). A single-precision plan finds the same grid peaks in less time;
        :meth:`coefficients` are ``complex128`` and :meth:`refine` computes in double
        precision whatever ``dtype`` is, so refined rotations are as accurate as in double.
    threads, rigor
        As for :class:`Plan`.
    """

    def __init__(
        self,
        B: int,
        *,
        b_out: Optional[int] = None,
        deg_lim: Optional[int] = None,
        real: bool = False,
        normalized: bool = False,
        dtype: DTypeLike = np.float64,
        threads: int = 0,
        rigor: str = "estimate",
    ) -> None:
        B = bandwidth_arg(B)
        b_out = None if b_out is None else bandwidth_arg(b_out, "b_out")
        deg_lim = None if deg_lim is None else int_arg(deg_lim, "deg_lim", 0, 1 << 31)
        self._dtype, complex_dtype = dtype_arg(dtype)
        self._plan = _so3fft.Correlation(
            B,
            b_out,
            deg_lim,
            bool(real),
            bool(normalized),
            threads_arg(threads),
            rigor,
            self._dtype.name,
        )
        self._normalized = bool(normalized)
        self._in_dtype = self._dtype if self.real else complex_dtype
        self._s2_shapes = ((2 * B, 2 * B),)

    @property
    def B(self) -> int:
        """Bandwidth of the inputs."""
        return self._plan.b_in

    @property
    def b_out(self) -> int:
        """Bandwidth of the correlation grid."""
        return self._plan.b_out

    @property
    def deg_lim(self) -> int:
        """Highest degree combined."""
        return self._plan.deg_lim

    @property
    def real(self) -> bool:
        """Whether inputs and grid are real."""
        return self._plan.real

    @property
    def normalized(self) -> bool:
        """Whether this is the normalised cross-correlation."""
        return self._normalized

    @property
    def dtype(self) -> np.dtype:
        """The precision of inputs and grid: ``float64`` or ``float32`` (complex inputs and
        grids ``complex128`` or ``complex64``)."""
        return self._dtype

    @property
    def grid_shape(self) -> Tuple[int, int, int]:
        """Shape of the correlation grid, ``(2 b_out,) * 3``."""
        return (2 * self.b_out,) * 3

    def __repr__(self):
        return (
            f"so3fft.Correlation({self.B}, b_out={self.b_out}, deg_lim={self.deg_lim}, "
            f"real={self.real}, normalized={self.normalized}"
            + ("" if self._dtype == np.float64 else f", dtype='{self._dtype}'")
            + ")"
        )

    def _inputs(self, signal, pattern, out):
        """The inputs as arrays, apart from `out` (the grid or coefficients written)."""
        return (
            apart(as_input(signal, self._in_dtype, self._s2_shapes, "signal"), out),
            apart(as_input(pattern, self._in_dtype, self._s2_shapes, "pattern"), out),
        )

    def _grid(self, out):
        if out is None:
            return np.empty(self.grid_shape, self._in_dtype)
        return check_output(out, self._in_dtype, self.grid_shape)

    def correlate(
        self, signal: ArrayLike, pattern: ArrayLike, out: Optional[np.ndarray] = None
    ) -> np.ndarray:
        """The correlation grid (``(2 b_out)^3``; real for a real plan; of the plan's
        precision), into ``out`` if given."""
        out = self._grid(out)
        s, p = self._inputs(signal, pattern, out)
        run = self._plan.correlate_real if self.real else self._plan.correlate
        run(s, p, out, False)
        return out

    def correlate_argmax(
        self, signal: ArrayLike, pattern: ArrayLike, out: Optional[np.ndarray] = None
    ) -> Tuple[np.ndarray, Peak]:
        """The correlation grid and its largest ``|C|^2`` (a :class:`Peak`, found while the
        grid is computed: ties go to the lowest index)."""
        out = self._grid(out)
        s, p = self._inputs(signal, pattern, out)
        run = self._plan.correlate_real if self.real else self._plan.correlate
        peak = run(s, p, out, True)
        assert peak is not None  # the extension returns the peak when asked for it
        return out, Peak(*peak)

    def correlate_shells(
        self,
        shells: Iterable[Tuple[ArrayLike, ArrayLike, float]],
        out: Optional[np.ndarray] = None,
    ) -> np.ndarray:
        """``sum_i w_i C_i``: the correlations of shells ``(signal_i, pattern_i, w_i)``
        (functions on concentric spheres, e.g. of a 3-D map), in one inverse transform."""
        out = self._grid(out)
        arrays = [(*self._inputs(s, p, out), float(w)) for s, p, w in shells]
        run = self._plan.correlate_shells_real if self.real else self._plan.correlate_shells
        run(arrays, out)
        return out

    def coefficients(
        self, signal: ArrayLike, pattern: ArrayLike, out: Optional[np.ndarray] = None
    ) -> np.ndarray:
        """The correlation's SO(3) coefficients (bandwidth ``b_out``; zero above
        ``deg_lim``), the input of :meth:`refine`: ``complex128`` in either precision
        (a single-precision plan computes them in double from its inputs, widened exactly)."""
        n = _so3fft.num_coeffs(self.b_out)
        if out is None:
            out = np.empty(n, np.complex128)
        else:
            check_output(out, np.complex128, (n,))
        s, p = self._inputs(signal, pattern, out)
        run = self._plan.coefficients_real if self.real else self._plan.coefficients
        run(s, p, out)
        return out

    def refine(self, coeffs: ArrayLike, starts: Rotations) -> List[Tuple[Rotation, float]]:
        """From each start rotation, the nearest maximum of ``|C|^2`` of the band-limited
        correlation with coefficients ``coeffs`` (from :meth:`coefficients`), off the grid:
        a list of ``(Rotation, value)``, computed in double precision whatever the plan's
        ``dtype``."""
        c = as_input(coeffs, np.complex128, ((_so3fft.num_coeffs(self.b_out),),), "coefficients")
        angles, values = self._plan.refine(c, _rows(starts))
        return [(Rotation(*a), float(v)) for a, v in zip(angles, values)]

    def match(
        self, signal: ArrayLike, pattern: ArrayLike, k: int = 1, min_angle: Optional[float] = None
    ) -> List[Tuple[Rotation, float]]:
        """The rotations that best take the pattern to the signal: the ``k`` largest peaks of
        the correlation grid (at least ``min_angle`` radians apart, default one grid step),
        each refined off the grid; a list of ``(Rotation, value)``, best first. Peaks that
        refine to the same maximum (within 1e-6 rad) are reported once."""
        grid = self.correlate(signal, pattern)
        peaks = top_peaks(grid, k, math.pi / self.b_out if min_angle is None else min_angle)
        if not peaks:
            return []
        found = self.refine(self.coefficients(signal, pattern), [p.rotation for p in peaks])
        kept: List[Tuple[Rotation, float]] = []
        for g, v in sorted(found, key=lambda gv: -gv[1]):
            if all(g.angle_to(h) > 1e-6 for h, _ in kept):
                kept.append((g, v))
        return kept


@functools.lru_cache(maxsize=4)
def _cached_correlation(B, b_out, deg_lim, real, normalized, threads, dtype):
    return Correlation(
        B,
        b_out=b_out,
        deg_lim=deg_lim,
        real=real,
        normalized=normalized,
        dtype=dtype,
        threads=threads,
    )


def correlate(
    signal: ArrayLike,
    pattern: ArrayLike,
    b_out: Optional[int] = None,
    deg_lim: Optional[int] = None,
    *,
    normalized: bool = False,
    dtype: DTypeLike = np.float64,
    threads: int = 0,
) -> np.ndarray:
    """The correlation grid of ``signal`` and ``pattern`` (S^2 samples, ``(2B, 2B)``): see
    :class:`Correlation`. Real inputs (both ``float``) give a real grid; ``dtype`` is the
    precision (``numpy.float32`` for ``float32`` or ``complex64`` inputs and grid). The
    plan is kept for the next call with the same arguments (a :class:`Correlation` made once
    is faster for many calls with different ones)."""
    s, p = np.asarray(signal), np.asarray(pattern)
    if s.ndim != 2 or s.shape[0] != s.shape[1] or s.shape[0] % 2:
        raise ValueError(f"signal: shape {s.shape}, expected (2B, 2B)")
    real = not (np.iscomplexobj(s) or np.iscomplexobj(p))
    b_out = None if b_out is None else bandwidth_arg(b_out, "b_out")
    deg_lim = None if deg_lim is None else int_arg(deg_lim, "deg_lim", 0, 1 << 31)
    plan = _cached_correlation(
        s.shape[0] // 2,
        b_out,
        deg_lim,
        real,
        bool(normalized),
        threads_arg(threads),
        dtype_arg(dtype)[0],
    )
    return plan.correlate(signal, pattern)  # lists keep their rounding rule (as_input)


def top_peaks(grid: ArrayLike, k: int = 1, min_angle: float = 0.0) -> List[Peak]:
    """The ``k`` largest local maxima of ``|C|^2`` on a correlation grid (``(2B)^3``, complex
    or real), each at least ``min_angle`` radians (geodesic) from every larger one taken: a
    list of :class:`Peak`, largest first. ``complex64`` and ``float32`` grids (of
    single-precision plans) are searched as they are, other grids in double precision."""
    g = np.asarray(grid)
    k = int_arg(k, "k", 0, 1 << 31)
    if np.iscomplexobj(g):
        c = np.complex64 if g.dtype == np.complex64 else np.complex128
        g = as_input(g, c, (g.shape,), "grid")
        found = _so3fft.top_peaks(g, k, float(min_angle))
    else:
        r = np.float32 if g.dtype == np.float32 else np.float64
        g = as_input(g, r, (g.shape,), "grid")
        found = _so3fft.top_peaks_real(g, k, float(min_angle))
    return [Peak(*p) for p in found]


def _coeffs_and_limit(coeffs, deg_lim):
    c = np.asarray(coeffs)
    from ._layout import _bandwidth_of

    B = _bandwidth_of(c.size)
    c = as_input(c, np.complex128, ((c.size,),), "coefficients")
    if deg_lim is None:
        return c, B, B - 1
    return c, B, int_arg(deg_lim, "deg_lim", 0, B - 1)


def refine(
    coeffs: ArrayLike, starts: Rotations, deg_lim: Optional[int] = None
) -> List[Tuple[Rotation, float]]:
    """From each start rotation, the nearest maximum of ``|f|^2`` of the band-limited SO(3)
    function with coefficients ``coeffs`` (degrees up to ``deg_lim``, default all), by
    damped Newton steps off the grid: a list of ``(Rotation, value)``."""
    c, B, L = _coeffs_and_limit(coeffs, deg_lim)
    angles, values = _so3fft.refine_series(B, L, c, _rows(starts))
    return [(Rotation(*a), float(v)) for a, v in zip(angles, values)]


def evaluate(coeffs: ArrayLike, rotations: Rotations, deg_lim: Optional[int] = None) -> np.ndarray:
    """The band-limited SO(3) function with coefficients ``coeffs`` at any rotations
    (``Rotation`` objects or rows of Euler angles), off the grid."""
    c, B, L = _coeffs_and_limit(coeffs, deg_lim)
    return _so3fft.evaluate_series(B, L, c, _rows(rotations))


def rotate_s2_coeffs(coeffs: ArrayLike, rotation: RotationLike) -> np.ndarray:
    """The S^2 coefficients of ``f(g^-1 x)``: the function of ``coeffs`` rotated by
    ``rotation`` (a :class:`Rotation` or Euler angles)."""
    c = np.asarray(coeffs)
    B = math.isqrt(c.size)
    if B * B != c.size or B < 1:
        raise ValueError(f"S^2 coefficients number B^2, not {c.size}")
    c = as_input(c, np.complex128, ((c.size,),), "coefficients")
    return _so3fft.rotate_s2_coeffs(B, c, tuple(Rotation._of(rotation)))
