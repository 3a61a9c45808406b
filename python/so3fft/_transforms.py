"""The SO(3) and S^2 transform plans."""

from __future__ import annotations

from typing import Optional, Protocol, Tuple

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from . import _so3fft
from ._arrays import apart, as_input, bandwidth_arg, check_output, dtype_arg, threads_arg


class _HasBandwidth(Protocol):
    """An extension plan: it knows its bandwidth."""

    @property
    def bandwidth(self) -> int: ...


class _Bandwidth:
    """What every plan answers: its bandwidth, whether its samples are real, its
    precision."""

    _plan: _HasBandwidth
    _real: bool
    _dtype: np.dtype
    _complex_dtype: np.dtype

    @property
    def B(self) -> int:
        """The bandwidth."""
        return self._plan.bandwidth

    @property
    def real(self) -> bool:
        """Whether the samples are real."""
        return self._real

    @property
    def dtype(self) -> np.dtype:
        """The precision: ``float64`` or ``float32`` (real samples have this dtype, complex
        samples and coefficients ``complex128`` or ``complex64``)."""
        return self._dtype

    def _repr_dtype(self) -> str:
        return "" if self._dtype == np.float64 else f", dtype='{self._dtype}'"


class Plan(_Bandwidth):
    """Forward and inverse FFT on SO(3) at bandwidth ``B`` (SOFT 2.0's conventions).

    Samples are a ``(2B, 2B, 2B)`` array indexed ``[k, j, i]``: the function at
    ``beta_k = pi (2k + 1) / (4B)``, ``alpha_j = pi j / B``, ``gamma_i = pi i / B`` (beta
    slowest, gamma fastest; :func:`grid_angles`). A flat array of ``(2B)^3`` values in the
    same order is accepted too.

    Coefficients are a flat array of ``(4B^3 - B) / 3`` complex values in SOFT's order
    (``so3CoefLoc``): ``fhat(l, m, m')`` is at :func:`coef_index` ``(B, l, m, m')``, with
    ``m`` paired with alpha and ``m'`` with gamma. :func:`to_dense` and :func:`from_dense`
    convert to and from an ``(l, m, m')`` array.

    The inverse transform is, with Wigner's ``D^l_{m m'}(alpha, beta, gamma) =
    e^{-i m alpha} d^l_{m m'}(beta) e^{-i m' gamma}`` normalised as in SOFT::

        f(alpha, beta, gamma) = sum_{l < B} sum_{|m|, |m'| <= l} fhat(l, m, m')
                                * sqrt((2l + 1) / 2) / (2 pi) * D^l_{m m'}(alpha, beta, gamma)

    and the forward transform is its exact inverse on band-limited samples (the library's
    docs/conventions.md has the details).

    Inputs of another dtype are converted when no information is lost (``float32`` or
    ``float64`` samples for a complex plan, for instance); C-contiguous arrays of the plan's
    dtype are used as they are, without a copy.

    A single-precision plan (``dtype=numpy.float32``) takes and returns ``float32`` and
    ``complex64`` arrays and computes in single precision (relative error about ``1e-6``
    at B = 64 to 256, against ``1e-15`` in double; half the memory, often less time).
    ``float64`` or ``complex128`` arrays given to it are a ``TypeError``, not silently
    rounded: convert them yourself (``x.astype(numpy.complex64)``). Python lists and
    numbers, which have no dtype, are rounded as NumPy rounds Python floats.

    Parameters
    ----------
    B : int
        Bandwidth (degrees ``l < B``), 1 to ``MAX_BANDWIDTH``.
    real : bool
        Samples are real: ``forward`` takes ``float64`` samples (``float32`` in single
        precision), ``inverse`` returns them (about half the work). The coefficients then satisfy
        ``fhat(l, -m, -m') = (-1)^(m - m') conj(fhat(l, m, m'))``.
    dtype : numpy dtype or name
        Precision: ``numpy.float64`` (the default) or ``numpy.float32``, or their names
        (``complex128`` and ``complex64`` name the same precisions). Real samples have this
        dtype, complex samples and coefficients its complex counterpart.
    threads : int
        Worker threads (0: all cores).
    rigor : str
        FFTW's planning rigour: ``"estimate"``, ``"measure"``, ``"patient"`` or
        ``"exhaustive"`` (more planning time, sometimes faster transforms).

    The transforms release the GIL: several threads may use one plan at once.
    """

    def __init__(
        self,
        B: int,
        *,
        real: bool = False,
        dtype: DTypeLike = np.float64,
        threads: int = 0,
        rigor: str = "estimate",
    ) -> None:
        B = bandwidth_arg(B)
        self._dtype, self._complex_dtype = dtype_arg(dtype)
        self._plan: _so3fft.Plan = _so3fft.Plan(
            B, bool(real), threads_arg(threads), rigor, self._dtype.name
        )
        self._real = bool(real)
        n = 2 * B
        self._sample_shape = (n, n, n)
        self._sample_shapes = ((n, n, n), (n * n * n,))
        self._sample_dtype = self._dtype if self._real else self._complex_dtype
        self._num_coeffs = self._plan.num_coeffs

    @property
    def sample_shape(self) -> Tuple[int, ...]:
        """Shape of a sample array, ``(2B, 2B, 2B)``."""
        return self._sample_shape

    @property
    def num_coeffs(self) -> int:
        """Number of coefficients, ``(4B^3 - B) / 3``."""
        return self._num_coeffs

    @property
    def threads(self) -> int:
        """Worker threads the plan runs on."""
        return self._plan.threads

    @property
    def memory_bytes(self) -> int:
        """Bytes the plan holds (tables and buffers)."""
        return self._plan.memory_bytes

    @property
    def isa(self) -> str:
        """The instruction set of the plan's kernels (``"avx512"``, ``"avx2"``, ...)."""
        return self._plan.isa

    def __repr__(self):
        return (
            f"so3fft.Plan({self.B}, real={self.real}{self._repr_dtype()}, "
            f"threads={self.threads})"
        )

    def forward(
        self, f: ArrayLike, out: Optional[np.ndarray] = None, *, check_finite: bool = True
    ) -> np.ndarray:
        """Samples ``f`` (``(2B, 2B, 2B)``; ``float64`` for a real plan, else
        ``complex128``; ``float32`` and ``complex64`` for a single-precision plan) to
        coefficients, written into ``out`` if given (a ``complex128`` array of
        ``num_coeffs`` values, ``complex64`` in single precision) and returned.

        With ``check_finite``, NaN or infinite samples raise ``ValueError`` (the check reads
        the coefficients: a few percent of the transform's time)."""
        x = as_input(f, self._sample_dtype, self._sample_shapes, "samples")
        if out is None:
            out = np.empty(self.num_coeffs, self._complex_dtype)
        else:
            x = apart(x, check_output(out, self._complex_dtype, (self.num_coeffs,)))
        if self.real:
            self._plan.forward_real(x, out, check_finite)
        else:
            self._plan.forward(x, out, check_finite)
        return out

    def inverse(
        self, fhat: ArrayLike, out: Optional[np.ndarray] = None, *, check_finite: bool = True
    ) -> np.ndarray:
        """Coefficients ``fhat`` (``num_coeffs`` complex values) to samples, written into
        ``out`` if given (``(2B, 2B, 2B)``, ``float64`` for a real plan, else
        ``complex128``; ``float32`` and ``complex64`` in single precision) and returned.

        A real plan reads the coefficients with ``m >= 0`` and takes the others from the
        real symmetry. With ``check_finite``, NaN or infinite coefficients raise
        ``ValueError``."""
        c = as_input(fhat, self._complex_dtype, ((self.num_coeffs,),), "coefficients")
        if out is None:
            out = np.empty(self.sample_shape, self._sample_dtype)
        else:
            c = apart(c, check_output(out, self._sample_dtype, self.sample_shape))
        if self.real:
            self._plan.inverse_real(c, out, check_finite)
        else:
            self._plan.inverse(c, out, check_finite)
        return out


class S2Plan(_Bandwidth):
    """Spherical-harmonic transforms on the sphere at bandwidth ``B`` (SOFT 2.0's grid and
    coefficient order), of one field or many.

    Samples are a ``(2B, 2B)`` array indexed ``[j, k]``: the function at colatitude
    ``theta_j = pi (2j + 1) / (4B)`` and longitude ``phi_k = pi k / B``; many fields are a
    ``(n, 2B, 2B)`` array. Coefficients are ``B^2`` complex values per field (``(n, B^2)``
    for many) in SOFT's ``seanindex`` order: :func:`s2_coef_index` ``(B, l, m)``.

    ``Y_l^m`` is orthonormal with the Condon-Shortley phase, the convention of
    ``scipy.special.sph_harm_y(l, m, theta, phi)``::

        f(theta, phi) = sum_{l < B} sum_{|m| <= l} fhat(l, m) Y_l^m(theta, phi)

    :mod:`so3fft.interop` converts to and from ducc0's and SciPy's layouts.

    A single-precision plan (``dtype=numpy.float32``) takes and returns ``float32`` and
    ``complex64`` arrays, and refuses ``float64`` and ``complex128`` ones with a
    ``TypeError`` (see :class:`Plan`).

    Parameters
    ----------
    B : int
        Bandwidth, 1 to ``S2_MAX_BANDWIDTH``.
    real : bool
        ``forward`` takes real samples (of ``dtype``) and ``inverse`` returns them; the
        coefficients (all ``B^2``) satisfy ``fhat(l, -m) = (-1)^m conj(fhat(l, m))``, and
        ``inverse`` reads only the orders ``m >= 0``.
    dtype : numpy dtype or name
        Precision: ``numpy.float64`` (the default) or ``numpy.float32`` (see :class:`Plan`).
    threads : int
        Worker threads (0: all cores).
    rigor : str
        FFTW's planning rigour (see :class:`Plan`).
    """

    def __init__(
        self,
        B: int,
        *,
        real: bool = False,
        dtype: DTypeLike = np.float64,
        threads: int = 0,
        rigor: str = "estimate",
    ) -> None:
        B = bandwidth_arg(B)
        self._dtype, self._complex_dtype = dtype_arg(dtype)
        self._plan: _so3fft.S2Plan = _so3fft.S2Plan(
            B, threads_arg(threads), rigor, self._dtype.name
        )
        self._real = bool(real)
        self._sample_dtype = self._dtype if self._real else self._complex_dtype

    @property
    def sample_shape(self) -> Tuple[int, ...]:
        """Shape of one field's samples, ``(2B, 2B)``."""
        return (2 * self.B, 2 * self.B)

    @property
    def num_coeffs(self) -> int:
        """Coefficients per field, ``B^2``."""
        return self._plan.num_coeffs

    @property
    def threads(self) -> int:
        """Worker threads the plan runs on."""
        return self._plan.threads

    def __repr__(self):
        return (
            f"so3fft.S2Plan({self.B}, real={self.real}{self._repr_dtype()}, "
            f"threads={self.threads})"
        )

    def forward(
        self, f: ArrayLike, out: Optional[np.ndarray] = None, *, check_finite: bool = True
    ) -> np.ndarray:
        """Samples (``(2B, 2B)`` or ``(n, 2B, 2B)``) to coefficients (``(B^2,)`` or
        ``(n, B^2)``, ``complex128``; ``complex64`` in single precision), into ``out`` if
        given."""
        n = 2 * self.B
        x = as_input(f, self._sample_dtype, ((n, n), (None, n, n)), "samples")
        many = x.ndim == 3
        howmany = x.shape[0] if many else 1
        shape = (howmany, self.num_coeffs) if many else (self.num_coeffs,)
        if out is None:
            out = np.empty(shape, self._complex_dtype)
        else:
            x = apart(x, check_output(out, self._complex_dtype, shape))
        if howmany == 0:
            return out
        if self.real:
            self._plan.forward_real(x, out, howmany, check_finite)
        else:
            self._plan.forward(x, out, howmany, check_finite)
        return out

    def inverse(
        self, fhat: ArrayLike, out: Optional[np.ndarray] = None, *, check_finite: bool = True
    ) -> np.ndarray:
        """Coefficients (``(B^2,)`` or ``(n, B^2)``) to samples (``(2B, 2B)`` or
        ``(n, 2B, 2B)``), into ``out`` if given."""
        nc = self.num_coeffs
        c = as_input(fhat, self._complex_dtype, ((nc,), (None, nc)), "coefficients")
        many = c.ndim == 2
        howmany = c.shape[0] if many else 1
        shape = (howmany,) + self.sample_shape if many else self.sample_shape
        if out is None:
            out = np.empty(shape, self._sample_dtype)
        else:
            c = apart(c, check_output(out, self._sample_dtype, shape))
        if howmany == 0:
            return out
        if self.real:
            self._plan.inverse_real(c, out, howmany, check_finite)
        else:
            self._plan.inverse(c, out, howmany, check_finite)
        return out
