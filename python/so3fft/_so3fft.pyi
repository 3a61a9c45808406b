"""Type stubs of the extension module ``so3fft._so3fft`` (python/src/*.rs).

The extension is the package's low level: every function takes exactly-typed, C-contiguous
arrays of the right length (the package ``so3fft`` checks and converts arguments, allocates
outputs and documents the API), releases the GIL while it computes, and turns every library
error into a Python exception (``ValueError`` for bad arguments, ``MemoryError`` when memory
runs out, ``RuntimeError`` otherwise; ``TypeError`` for an array of the wrong dtype).

The plans are made in double (``dtype="float64"``) or single (``"float32"``) precision and
then take arrays of that precision only: ``float64`` and ``complex128``, or ``float32`` and
``complex64``. A correlation's SO(3) coefficients and refinement are double in either.
"""

from typing import Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_ComplexArray = npt.NDArray[np.complex128]
_RealArray = npt.NDArray[np.float64]
_IntArray = npt.NDArray[np.int64]
# Arrays of a plan's precision: double or single.
_ComplexArrayP = Union[npt.NDArray[np.complex128], npt.NDArray[np.complex64]]
_RealArrayP = Union[npt.NDArray[np.float64], npt.NDArray[np.float32]]
# A plan's precision, by the name of its real dtype.
_DType = Literal["float64", "float32"]

# A peak of a correlation grid: (flat index, alpha, beta, gamma, |C|^2).
_PeakTuple = Tuple[int, float, float, float, float]

__version__: str
"""The version of the Rust crate the extension was built from."""

MAX_BANDWIDTH: int
"""Largest bandwidth of an SO(3) transform (2048)."""

S2_MAX_BANDWIDTH: int
"""Largest bandwidth of an S^2 transform."""

# ---------------------------------------------------------------------------------------
# Transforms (python/src/transforms.rs)


class Plan:
    """An SO(3) transform plan of one bandwidth (exact arrays, no allocation)."""

    def __init__(
        self, bandwidth: int, real: bool, threads: int, rigor: str, dtype: str = "float64"
    ) -> None:
        """Plan the transforms at ``bandwidth`` (``threads`` 0: all cores; ``rigor`` FFTW's) in
        the precision ``dtype`` (``"float64"`` or ``"float32"``)."""
        ...

    @property
    def bandwidth(self) -> int:
        """The bandwidth ``B``."""
        ...

    @property
    def real(self) -> bool:
        """Whether the plan was made for real samples."""
        ...

    @property
    def dtype(self) -> _DType:
        """The precision: ``"float64"`` or ``"float32"``."""
        ...

    @property
    def threads(self) -> int:
        """Worker threads the plan runs on."""
        ...

    @property
    def num_samples(self) -> int:
        """Number of samples, ``(2B)^3``."""
        ...

    @property
    def num_coeffs(self) -> int:
        """Number of coefficients, ``(4B^3 - B) / 3``."""
        ...

    @property
    def memory_bytes(self) -> int:
        """Bytes the plan holds (tables and buffers)."""
        ...

    @property
    def isa(self) -> str:
        """The instruction set the kernels use (lower case, e.g. ``"avx2"``)."""
        ...

    def forward(
        self, samples: _ComplexArrayP, coeffs: _ComplexArrayP, check_finite: bool
    ) -> float:
        """Complex samples to coefficients, written into ``coeffs``; the seconds the library spent."""
        ...

    def forward_real(
        self, samples: _RealArrayP, coeffs: _ComplexArrayP, check_finite: bool
    ) -> float:
        """Real samples to coefficients, written into ``coeffs``; the seconds the library spent."""
        ...

    def inverse(
        self, coeffs: _ComplexArrayP, samples: _ComplexArrayP, check_finite: bool
    ) -> float:
        """Coefficients to complex samples, written into ``samples``; the seconds the library spent."""
        ...

    def inverse_real(
        self, coeffs: _ComplexArrayP, samples: _RealArrayP, check_finite: bool
    ) -> float:
        """Coefficients of a real function to real samples, written into ``samples``; the seconds the library spent."""
        ...


class S2Plan:
    """An S^2 transform plan of one bandwidth; each call takes ``howmany`` fields in a row."""

    def __init__(
        self, bandwidth: int, threads: int, rigor: str, dtype: str = "float64"
    ) -> None:
        """Plan the S^2 transforms at ``bandwidth`` in the precision ``dtype``."""
        ...

    @property
    def bandwidth(self) -> int:
        """The bandwidth ``B``."""
        ...

    @property
    def dtype(self) -> _DType:
        """The precision: ``"float64"`` or ``"float32"``."""
        ...

    @property
    def threads(self) -> int:
        """Worker threads the plan runs on."""
        ...

    @property
    def num_samples(self) -> int:
        """Samples per field, ``(2B)^2``."""
        ...

    @property
    def num_coeffs(self) -> int:
        """Coefficients per field, ``B^2``."""
        ...

    def forward(
        self,
        samples: _ComplexArrayP,
        coeffs: _ComplexArrayP,
        howmany: int,
        check_finite: bool,
    ) -> float:
        """Complex samples of ``howmany`` fields to their coefficients; the seconds the library spent."""
        ...

    def forward_real(
        self,
        samples: _RealArrayP,
        coeffs: _ComplexArrayP,
        howmany: int,
        check_finite: bool,
    ) -> float:
        """Real samples of ``howmany`` fields to their coefficients; the seconds the library spent."""
        ...

    def inverse(
        self,
        coeffs: _ComplexArrayP,
        samples: _ComplexArrayP,
        howmany: int,
        check_finite: bool,
    ) -> float:
        """Coefficients of ``howmany`` fields to complex samples; the seconds the library spent."""
        ...

    def inverse_real(
        self,
        coeffs: _ComplexArrayP,
        samples: _RealArrayP,
        howmany: int,
        check_finite: bool,
    ) -> float:
        """Coefficients of ``howmany`` real fields to real samples; the seconds the library spent."""
        ...


# ---------------------------------------------------------------------------------------
# Layout (python/src/layout.rs)


def num_coeffs(bandwidth: int) -> int:
    """Number of SO(3) coefficients, ``(4B^3 - B) / 3``."""
    ...


def num_samples(bandwidth: int) -> int:
    """Number of SO(3) samples, ``(2B)^3``."""
    ...


def coef_index(bandwidth: int, l: int, m: int, mp: int) -> int:
    """Index of ``fhat(l, m, mp)`` in the flat coefficient array (SOFT's ``so3CoefLoc``)."""
    ...


def coef_degrees_orders(bandwidth: int) -> _IntArray:
    """``(l, m, mp)`` of every coefficient in the flat order: shape ``(num_coeffs, 3)``."""
    ...


def s2_num_coeffs(bandwidth: int) -> int:
    """Number of S^2 coefficients, ``B^2``."""
    ...


def s2_num_samples(bandwidth: int) -> int:
    """Number of S^2 samples, ``(2B)^2``."""
    ...


def s2_coef_index(bandwidth: int, l: int, m: int) -> int:
    """Index of ``fhat(l, m)`` in the flat S^2 coefficient array (SOFT's ``seanindex``)."""
    ...


def s2_coef_degrees_orders(bandwidth: int) -> _IntArray:
    """``(l, m)`` of every S^2 coefficient in the flat order: shape ``(B^2, 2)``."""
    ...


def grid_angles(bandwidth: int) -> Tuple[_RealArray, _RealArray, _RealArray]:
    """The grid's ``(alpha, beta, gamma)``, ``2B`` values each."""
    ...


def weights(bandwidth: int) -> _RealArray:
    """The quadrature weights of the beta grid (``2B`` values)."""
    ...


# ---------------------------------------------------------------------------------------
# Matching (python/src/matching.rs)


class Correlation:
    """A rotational-correlation plan (exact arrays, no allocation)."""

    def __init__(
        self,
        b_in: int,
        b_out: Optional[int],
        deg_lim: Optional[int],
        real: bool,
        normalized: bool,
        threads: int,
        rigor: str,
        dtype: str = "float64",
    ) -> None:
        """Plan the correlation of S^2 functions of bandwidth ``b_in`` on the grid of ``b_out``,
        in the precision ``dtype`` (``"float64"`` or ``"float32"``)."""
        ...

    @property
    def b_in(self) -> int:
        """Bandwidth of the inputs."""
        ...

    @property
    def b_out(self) -> int:
        """Bandwidth of the SO(3) correlation grid."""
        ...

    @property
    def deg_lim(self) -> int:
        """Highest degree combined."""
        ...

    @property
    def real(self) -> bool:
        """Whether the plan takes real inputs and gives a real grid."""
        ...

    @property
    def dtype(self) -> _DType:
        """The precision of inputs and grid: ``"float64"`` or ``"float32"``."""
        ...

    @property
    def num_grid(self) -> int:
        """Number of grid values, ``(2 b_out)^3``."""
        ...

    def correlate(
        self,
        signal: _ComplexArrayP,
        pattern: _ComplexArrayP,
        out: _ComplexArrayP,
        argmax: bool,
    ) -> Optional[_PeakTuple]:
        """The correlation grid of complex inputs into ``out``; with ``argmax`` its largest ``|C|^2``."""
        ...

    def correlate_real(
        self,
        signal: _RealArrayP,
        pattern: _RealArrayP,
        out: _RealArrayP,
        argmax: bool,
    ) -> Optional[_PeakTuple]:
        """The correlation grid of real inputs into ``out``; with ``argmax`` its largest ``|C|^2``."""
        ...

    def correlate_shells(
        self,
        shells: Sequence[Tuple[_ComplexArrayP, _ComplexArrayP, float]],
        out: _ComplexArrayP,
    ) -> None:
        """The weighted sum of the correlations of ``(signal, pattern, weight)`` shells into ``out``."""
        ...

    def correlate_shells_real(
        self,
        shells: Sequence[Tuple[_RealArrayP, _RealArrayP, float]],
        out: _RealArrayP,
    ) -> None:
        """:meth:`correlate_shells` of real shells."""
        ...

    def coefficients(
        self, signal: _ComplexArrayP, pattern: _ComplexArrayP, out: _ComplexArray
    ) -> None:
        """The correlation's SO(3) coefficients (bandwidth ``b_out``) of complex inputs into ``out``."""
        ...

    def coefficients_real(
        self, signal: _RealArrayP, pattern: _RealArrayP, out: _ComplexArray
    ) -> None:
        """The correlation's SO(3) coefficients of real inputs into ``out``."""
        ...

    def refine(
        self, coeffs: _ComplexArray, starts: _RealArray
    ) -> Tuple[_RealArray, _RealArray]:
        """From each start (rows of Euler angles) the nearest maximum of ``|C|^2``: angles ``(k, 3)``, values ``(k,)``."""
        ...


def top_peaks(grid: _ComplexArrayP, k: int, min_angle: float) -> list[_PeakTuple]:
    """The ``k`` largest local maxima of ``|C|^2`` on a complex grid (``complex128`` or
    ``complex64``), ``min_angle`` apart."""
    ...


def top_peaks_real(grid: _RealArrayP, k: int, min_angle: float) -> list[_PeakTuple]:
    """:func:`top_peaks` of a real grid."""
    ...


def euler_to_quaternion(alpha: float, beta: float, gamma: float) -> list[float]:
    """The unit quaternion ``(w, x, y, z)`` (``w >= 0``) of ``Rz(alpha) Ry(beta) Rz(gamma)``."""
    ...


def euler_to_matrix(alpha: float, beta: float, gamma: float) -> list[list[float]]:
    """The 3x3 matrix (rows) of ``Rz(alpha) Ry(beta) Rz(gamma)``, acting on column vectors."""
    ...


def rotate_s2_coeffs(
    bandwidth: int, coeffs: _ComplexArray, angles: Tuple[float, float, float]
) -> _ComplexArray:
    """The S^2 coefficients of the function rotated by ``Rz(alpha) Ry(beta) Rz(gamma)``."""
    ...


def refine_series(
    bandwidth: int, deg_lim: int, coeffs: _ComplexArray, starts: _RealArray
) -> Tuple[_RealArray, _RealArray]:
    """Refine each start to the nearest maximum of ``|f|^2`` of an SO(3) series: angles, values."""
    ...


def evaluate_series(
    bandwidth: int, deg_lim: int, coeffs: _ComplexArray, at: _RealArray
) -> _ComplexArray:
    """The SO(3) series of ``coeffs`` (degrees ``<= deg_lim``) at rotations (rows of Euler angles)."""
    ...
