"""Conversions between so3fft's layouts and conventions and those of other tools, to check
results against software you already trust.

S^2 (spherical harmonics)
-------------------------
so3fft's S^2 coefficients ``fhat`` are ``B^2`` complex values in SOFT's ``seanindex`` order
(:func:`so3fft.s2_coef_index`) of the expansion::

    f(theta, phi) = sum_{l < B} sum_{|m| <= l} fhat(l, m) Y_l^m(theta, phi)

with ``Y_l^m`` orthonormal on the sphere and with the Condon-Shortley phase: exactly
``scipy.special.sph_harm_y(l, m, theta, phi)`` (``theta`` the colatitude, ``phi`` the
longitude). :func:`s2_coefficient_table` and :func:`s2_from_table` convert to and from a
dense table ``T[l, m + B - 1]``.

ducc0 (``ducc0.sht``) uses the same ``Y_l^m`` (same normalisation, same phase), but stores
only the orders ``m >= 0`` of a **real** field, at index ``m (2 lmax + 1 - m) / 2 + l``
(healpy's order, ``lmax = B - 1``, ``mmax = lmax``); the negative orders are implied by
``a(l, -m) = (-1)^m conj(a(l, m))`` and the imaginary parts of ``a(l, 0)`` are ignored. So
for a real field ``a(l, m) = fhat(l, m)`` for ``m >= 0``, value for value. A complex field
``f = f_re + i f_im`` is, for ducc0, the pair of real fields ``f_re`` and ``f_im``:
:func:`s2_to_ducc0_alm` and :func:`s2_from_ducc0_alm` convert both ways.

so3fft's S^2 grid (``theta_j = pi (2j + 1) / (4B)``, ``phi_k = pi k / B``, ``0 <= j, k <
2B``) is ducc0's ``"F1"`` geometry (Fejer's first rule) with ``ntheta = nphi = 2B`` and
``phi0 = 0``, in the same ``[theta, phi]`` order: see :func:`ducc0_synthesis_2d_kwargs`.
ducc0's ``synthesis_2d`` then gives the samples of ``so3fft.S2Plan(B, real=True).inverse``,
and its ``analysis_2d`` the coefficients of ``forward`` for band-limited samples (degrees
below ``B``). For other samples the two forward transforms differ: so3fft applies SOFT's
quadrature, ducc0 its own analysis. :func:`ducc0_s2_inverse` and :func:`ducc0_s2_forward` run
ducc0's transforms in so3fft's layouts (also for complex fields and many fields).

Rotations: ``so3fft.rotate_s2_coeffs(fhat, Rotation(alpha, beta, gamma))`` is
``ducc0.sht.rotate_alm(alm, lmax, psi=gamma, theta=beta, phi=alpha)`` on the ``m >= 0``
part (:func:`ducc0_rotation_angles`).

SO(3) (Wigner D)
----------------
so3fft's SO(3) coefficients ``fhat(l, m, m')`` (flat, or dense ``D[l, m + B - 1, m' + B - 1]``
from :func:`so3fft.to_dense`) expand::

    f(alpha, beta, gamma) = sum_{l < B} sum_{|m|, |m'| <= l} fhat(l, m, m')
                            * sqrt((2l + 1) / 2) / (2 pi) * D^l_{m m'}(alpha, beta, gamma)

    D^l_{m m'}(alpha, beta, gamma) = e^{-i m alpha} d^l_{m m'}(beta) e^{-i m' gamma}
                                   = <l m| exp(-i alpha J_z) exp(-i beta J_y) exp(-i gamma J_z) |l m'>

with ``d`` the standard Wigner small-d (Varshalovich, Edmonds; ``d^1_{1,0}(beta) =
-sin(beta) / sqrt(2)``), the rotation ``Rz(alpha) Ry(beta) Rz(gamma)`` (SciPy's intrinsic
``"ZYZ"``), ``m`` paired with ``alpha`` and ``m'`` with ``gamma``. :func:`wigner_D` and
:func:`wigner_d_small` compute these matrices; :func:`so3_to_wigner_coefficients` rescales
the coefficients to the plain expansion ``f = sum c(l, m, m') D^l_{m m'}`` (or in
``conj(D)``, the convention of packages whose ``D`` carries ``e^{+i m alpha}``).

ducc0 and SciPy are optional: they are imported only by the functions that need them.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ._layout import s2_coef_degrees_orders

__all__ = [
    "ducc0_alm_index",
    "s2_to_ducc0_alm",
    "s2_from_ducc0_alm",
    "ducc0_synthesis_2d_kwargs",
    "ducc0_analysis_2d_kwargs",
    "ducc0_s2_inverse",
    "ducc0_s2_forward",
    "ducc0_rotation_angles",
    "s2_coefficient_table",
    "s2_from_table",
    "wigner_d_small",
    "wigner_D",
    "so3_to_wigner_coefficients",
    "so3_from_wigner_coefficients",
]


# ----------------------------------------------------------------------------------------
# argument checks


def _int_arg(x, name, minimum=0):
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, not {type(x).__name__}")
    if x < minimum:
        raise ValueError(f"{name} must be at least {minimum}, not {x}")
    return int(x)


def _complex_array(x, what):
    """``x`` as a complex128 array (a new one if a conversion is needed)."""
    a = np.asarray(x)
    if a.dtype == object or not np.issubdtype(a.dtype, np.number):
        raise TypeError(f"{what}: expected numbers, got an array of {a.dtype}")
    return a.astype(np.complex128, copy=False)


def _s2_coeffs(fhat, what="fhat"):
    """S^2 coefficients ``(B^2,)`` or ``(n, B^2)``: the array and ``B``."""
    a = _complex_array(fhat, what)
    if a.ndim not in (1, 2) or a.shape[-1] == 0:
        raise ValueError(f"{what}: shape {a.shape}, expected (B^2,) or (n, B^2)")
    B = math.isqrt(a.shape[-1])
    if B * B != a.shape[-1]:
        raise ValueError(f"{what}: {a.shape[-1]} coefficients per field is not a square B^2")
    return a, B


def _nalm(lmax):
    return (lmax + 1) * (lmax + 2) // 2


def _lmax_of(nalm, what):
    lmax = (math.isqrt(8 * nalm + 1) - 3) // 2
    if lmax < 0 or _nalm(lmax) != nalm:
        raise ValueError(
            f"{what}: {nalm} values per field is not a ducc0 alm size (lmax + 1)(lmax + 2) / 2"
        )
    return lmax


# ----------------------------------------------------------------------------------------
# S^2: ducc0


def ducc0_alm_index(l, m, lmax):
    """Index of ``a(l, m)`` (``0 <= m <= l <= lmax``) in ducc0's (and healpy's) alm array
    with ``mmax = lmax``: ``m (2 lmax + 1 - m) / 2 + l``."""
    l = _int_arg(l, "l")
    m = _int_arg(m, "m")
    lmax = _int_arg(lmax, "lmax")
    if not m <= l <= lmax:
        raise ValueError(f"ducc0 stores 0 <= m <= l <= lmax, not l={l}, m={m}, lmax={lmax}")
    return m * (2 * lmax + 1 - m) // 2 + l


def _maps(B):
    """Index maps of the seanindex order: positions of the ``m >= 0`` entries, their alm
    indices, and for every entry the position of its ``-m`` partner and ``(-1)^m``."""
    lm = s2_coef_degrees_orders(B)
    l, m = lm[:, 0].astype(np.int64), lm[:, 1].astype(np.int64)
    lmax = B - 1
    pos = np.flatnonzero(m >= 0)
    alm_idx = m[pos] * (2 * lmax + 1 - m[pos]) // 2 + l[pos]
    # seanindex(-m, l): entries sorted by (l, m), then looked up
    key = l * (2 * B) + (m + B)
    order = np.argsort(key)
    partner = order[np.searchsorted(key[order], l * (2 * B) + (-m + B))]
    sign = np.where(m % 2 == 0, 1.0, -1.0)
    return pos, alm_idx, partner, sign, m


def s2_to_ducc0_alm(fhat, real=True, *, check=True, tol=1e-12):
    """so3fft's S^2 coefficients as ducc0 ``alm`` arrays (``lmax = mmax = B - 1``).

    Parameters
    ----------
    fhat : array_like, complex, shape ``(B^2,)`` or ``(n, B^2)``
        Coefficients in SOFT's ``seanindex`` order, of one field or ``n`` fields.
    real : bool
        ``True``: the field is real, and the result is its ``m >= 0`` part (``alm[idx] =
        fhat(l, m)``, no scaling; ``Im fhat(l, 0)`` is dropped, as ducc0 ignores it). ``False``: the field may be complex, and the result is
        the pair ``(alm_re, alm_im)`` of the real fields ``Re f`` and ``Im f``::

            alm_re(l, m) = (fhat(l, m) + (-1)^m conj(fhat(l, -m))) / 2
            alm_im(l, m) = (fhat(l, m) - (-1)^m conj(fhat(l, -m))) / (2i)

    check : bool
        With ``real=True``, check that ``fhat`` is the expansion of a real field
        (``fhat(l, -m) = (-1)^m conj(fhat(l, m))``, ``fhat(l, 0)`` real) to within ``tol``
        times ``max |fhat|`` and raise ``ValueError`` otherwise. Without the check the
        negative orders are ignored, as ``S2Plan(B, real=True).inverse`` ignores them.
    tol : float
        Relative tolerance of the check.

    Raises
    ------
    ValueError
        Not ``(B^2,)`` or ``(n, B^2)`` coefficients, or (with ``check``) not a real field.
    TypeError
        Not numbers.

    Returns
    -------
    numpy.ndarray or tuple of numpy.ndarray
        complex128, shape ``(B (B + 1) / 2,)`` or ``(n, B (B + 1) / 2)``; a pair of them for
        ``real=False``. A single field's ``alm`` goes to ducc0 as ``alm[None]`` (its
        ``synthesis_2d`` wants ``(1, nalm)`` for spin 0).
    """
    a, B = _s2_coeffs(fhat)
    pos, alm_idx, partner, sign, m = _maps(B)
    shape = a.shape[:-1] + (_nalm(B - 1),)
    if real:
        if check and a.size:
            scale = np.abs(a).max()
            sym = np.abs(a[..., partner] - sign * np.conj(a)).max()
            im0 = np.abs(a[..., m == 0].imag).max()
            if max(sym, im0) > tol * scale:
                raise ValueError(
                    "fhat is not the expansion of a real field (fhat(l, -m) = (-1)^m "
                    f"conj(fhat(l, m)) and real fhat(l, 0) fail by {max(sym, im0):.3g}, "
                    f"max |fhat| = {scale:.3g}); pass real=False for a complex field, or "
                    "check=False to take the m >= 0 part"
                )
        alm = np.zeros(shape, np.complex128)
        alm[..., alm_idx] = a[..., pos]
        zero = alm_idx[m[pos] == 0]
        alm[..., zero] = alm[..., zero].real  # ducc0 ignores Im a(l, 0)
        return alm
    # complex field: split into the expansions of its real and imaginary parts
    mirrored = sign * np.conj(a[..., partner])  # coefficients of conj(f)
    alm_re = np.zeros(shape, np.complex128)
    alm_im = np.zeros(shape, np.complex128)
    alm_re[..., alm_idx] = (a[..., pos] + mirrored[..., pos]) / 2
    alm_im[..., alm_idx] = (a[..., pos] - mirrored[..., pos]) / 2j
    return alm_re, alm_im


def s2_from_ducc0_alm(alm, lmax=None, alm_imag=None):
    """so3fft's S^2 coefficients of a field given by ducc0 ``alm`` (``mmax = lmax``).

    Parameters
    ----------
    alm : array_like, complex, shape ``(nalm,)`` or ``(n, nalm)``
        ``m >= 0`` coefficients of a real field in ducc0's order (index ``m (2 lmax + 1 -
        m) / 2 + l``), ``nalm = (lmax + 1)(lmax + 2) / 2``; ducc0's ``(1, nalm)`` output is
        one field. The imaginary parts of ``a(l, 0)`` are dropped, as ducc0 ignores them.
    lmax : int, optional
        ``B - 1``; found from ``nalm`` if not given (and checked against it if given).
    alm_imag : array_like, optional
        The same for the imaginary part of a complex field ``f = f_re + i f_im``
        (``alm`` then describes ``f_re``).

    Returns
    -------
    numpy.ndarray
        complex128, ``(B^2,)`` or ``(n, B^2)`` in ``seanindex`` order, ``B = lmax + 1``;
        for a real field ``fhat(l, m) = a(l, m)`` and ``fhat(l, -m) = (-1)^m conj(a(l,
        m))``, for a complex one ``fhat = fhat_re + i fhat_im``.
    """
    a = _complex_array(alm, "alm")
    if a.ndim not in (1, 2):
        raise ValueError(f"alm: shape {a.shape}, expected (nalm,) or (n, nalm)")
    found = _lmax_of(a.shape[-1], "alm")
    if lmax is not None and _int_arg(lmax, "lmax") != found:
        raise ValueError(f"alm: {a.shape[-1]} values per field, but lmax={lmax} needs {_nalm(lmax)}")
    B = found + 1
    pos, alm_idx, partner, sign, m = _maps(B)

    def expand(x):
        half = x[..., alm_idx].copy()
        half[..., m[pos] == 0] = half[..., m[pos] == 0].real
        full = np.zeros(x.shape[:-1] + (B * B,), np.complex128)
        full[..., pos] = half
        neg = np.flatnonzero(m < 0)
        full[..., neg] = sign[neg] * np.conj(full[..., partner[neg]])
        return full

    if alm_imag is None:
        return expand(a)
    b = _complex_array(alm_imag, "alm_imag")
    if b.shape != a.shape:
        raise ValueError(f"alm_imag: shape {b.shape}, expected that of alm {a.shape}")
    return expand(a) + 1j * expand(b)


def ducc0_synthesis_2d_kwargs(B):
    """Keyword arguments of ``ducc0.sht.synthesis_2d`` (all but ``alm``) for so3fft's S^2
    grid at bandwidth ``B``: ``lmax = B - 1``, spin 0, geometry ``"F1"`` (rings at
    ``theta_j = pi (2j + 1) / (4B)``), ``ntheta = nphi = 2B`` (``phi_k = pi k / B``).

    ``ducc0.sht.synthesis_2d(alm=s2_to_ducc0_alm(fhat)[None], **ducc0_synthesis_2d_kwargs(B))[0]``
    equals ``so3fft.S2Plan(B, real=True).inverse(fhat)``.
    """
    from ._arrays import bandwidth_arg

    B = bandwidth_arg(B)
    return {"lmax": B - 1, "spin": 0, "geometry": "F1", "ntheta": 2 * B, "nphi": 2 * B}


def ducc0_analysis_2d_kwargs(B):
    """Keyword arguments of ``ducc0.sht.analysis_2d`` (all but ``map``) for so3fft's S^2
    grid at bandwidth ``B`` (``lmax = B - 1``, spin 0, geometry ``"F1"``; the grid's shape
    ``(2B, 2B)`` comes from the map). ducc0 analyses such maps exactly up to degree
    ``2B - 1`` and order ``B - 1``."""
    from ._arrays import bandwidth_arg

    B = bandwidth_arg(B)
    return {"lmax": B - 1, "spin": 0, "geometry": "F1"}


def _threads(nthreads):
    return _int_arg(nthreads, "nthreads")


def ducc0_s2_inverse(fhat, real=False, *, nthreads=1):
    """so3fft's S^2 inverse transform computed by ducc0 (``synthesis_2d``), in so3fft's
    layouts: a reference for ``S2Plan(B).inverse``.

    Parameters
    ----------
    fhat : array_like, complex, shape ``(B^2,)`` or ``(n, B^2)``
        Coefficients in ``seanindex`` order.
    real : bool
        ``True``: a real field, synthesised from the ``m >= 0`` orders (the others and
        ``Im fhat(l, 0)`` are ignored, as by ``S2Plan(B, real=True).inverse``); float64
        samples. ``False``: a complex field, synthesised as its real and imaginary parts;
        complex128 samples.
    nthreads : int
        ducc0's threads (0: all).

    Returns
    -------
    numpy.ndarray
        Samples ``(2B, 2B)`` or ``(n, 2B, 2B)`` indexed ``[theta, phi]``.
    """
    import ducc0

    a, B = _s2_coeffs(fhat)
    nt = _threads(nthreads)
    kw = ducc0_synthesis_2d_kwargs(B)
    batch = a.reshape(-1, B * B)

    def synth(alm):
        return np.stack(
            [ducc0.sht.synthesis_2d(alm=x[None], nthreads=nt, **kw)[0] for x in alm]
        ) if len(alm) else np.empty((0, 2 * B, 2 * B))

    if real:
        out = synth(s2_to_ducc0_alm(batch, real=True, check=False))
    else:
        re, im = s2_to_ducc0_alm(batch, real=False)
        out = synth(re) + 1j * synth(im)
    return out.reshape(a.shape[:-1] + (2 * B, 2 * B))


def ducc0_s2_forward(f, *, nthreads=1):
    """S^2 coefficients of samples on so3fft's grid computed by ducc0 (``analysis_2d``), in
    ``seanindex`` order: a reference for ``S2Plan(B).forward``.

    They agree with so3fft's for band-limited samples (degrees below ``B``; so3fft's
    forward is SOFT's quadrature, which for other samples gives other numbers).

    Parameters
    ----------
    f : array_like, shape ``(2B, 2B)`` or ``(n, 2B, 2B)``
        Real samples (float64 result of a real field) or complex ones (analysed as the
        real and imaginary parts).
    nthreads : int
        ducc0's threads (0: all).

    Returns
    -------
    numpy.ndarray
        complex128, ``(B^2,)`` or ``(n, B^2)``.
    """
    import ducc0

    x = np.asarray(f)
    if x.dtype == object or not np.issubdtype(x.dtype, np.number):
        raise TypeError(f"samples: expected numbers, got an array of {x.dtype}")
    if x.ndim not in (2, 3) or x.shape[-1] != x.shape[-2] or x.shape[-1] % 2 or x.shape[-1] == 0:
        raise ValueError(f"samples: shape {x.shape}, expected (2B, 2B) or (n, 2B, 2B)")
    B = x.shape[-1] // 2
    nt = _threads(nthreads)
    kw = ducc0_analysis_2d_kwargs(B)
    batch = x.reshape(-1, 2 * B, 2 * B)

    def analyse(maps):
        maps = np.ascontiguousarray(maps, dtype=np.float64)
        if not len(maps):
            return np.empty((0, _nalm(B - 1)), np.complex128)
        return np.stack([ducc0.sht.analysis_2d(map=m[None], nthreads=nt, **kw)[0] for m in maps])

    if np.iscomplexobj(batch):
        out = s2_from_ducc0_alm(analyse(batch.real), B - 1, analyse(batch.imag))
    else:
        out = s2_from_ducc0_alm(analyse(batch), B - 1)
    return out.reshape(x.shape[:-2] + (B * B,))


def ducc0_rotation_angles(rotation):
    """The angles ``(psi, theta, phi)`` of ``ducc0.sht.rotate_alm`` for a rotation given
    as a :class:`so3fft.Rotation` or z-y-z Euler angles ``(alpha, beta, gamma)``:
    ``(gamma, beta, alpha)``.

    ``ducc0.sht.rotate_alm(s2_to_ducc0_alm(fhat), B - 1, *ducc0_rotation_angles(g))`` is the
    ``m >= 0`` part of ``so3fft.rotate_s2_coeffs(fhat, g)``: the coefficients of
    ``f(g^-1 x)``.
    """
    angles = tuple(rotation)
    if len(angles) != 3:
        raise ValueError("a rotation is three Euler angles (alpha, beta, gamma)")
    alpha, beta, gamma = (float(t) for t in angles)
    return gamma, beta, alpha


# ----------------------------------------------------------------------------------------
# S^2: dense tables


def s2_coefficient_table(fhat):
    """S^2 coefficients as a dense table ``T[l, m + B - 1]`` (zero where ``|m| > l``).

    Parameters
    ----------
    fhat : array_like, complex, shape ``(B^2,)`` or ``(n, B^2)``
        Coefficients in ``seanindex`` order.

    Returns
    -------
    numpy.ndarray
        complex128, ``(B, 2B - 1)`` or ``(n, B, 2B - 1)``: ``T[l, m + B - 1]`` multiplies
        ``scipy.special.sph_harm_y(l, m, theta, phi)``.
    """
    a, B = _s2_coeffs(fhat)
    lm = s2_coef_degrees_orders(B)
    table = np.zeros(a.shape[:-1] + (B, 2 * B - 1), np.complex128)
    table[..., lm[:, 0], lm[:, 1] + B - 1] = a
    return table


def s2_from_table(table):
    """The flat ``seanindex`` coefficients of a dense table ``T[l, m + B - 1]`` of shape
    ``(B, 2B - 1)`` or ``(n, B, 2B - 1)`` (see :func:`s2_coefficient_table`); entries with
    ``|m| > l`` are ignored."""
    t = _complex_array(table, "table")
    if t.ndim not in (2, 3) or t.shape[-2] < 1 or t.shape[-1] != 2 * t.shape[-2] - 1:
        raise ValueError(f"table: shape {t.shape}, expected (B, 2B - 1) or (n, B, 2B - 1)")
    B = t.shape[-2]
    lm = s2_coef_degrees_orders(B)
    return np.ascontiguousarray(t[..., lm[:, 0], lm[:, 1] + B - 1])


# ----------------------------------------------------------------------------------------
# SO(3): Wigner matrices and coefficients


@functools.lru_cache(maxsize=8)
def _jy_eigen(l):
    """Eigenvalues (exactly ``-l..l``) and eigenvectors of ``J_y`` in the ``|l m>`` basis."""
    m = np.arange(-l, l + 1, dtype=float)
    # J_y = (J+ - J-) / (2i), J+|l m> = sqrt(l(l+1) - m(m+1)) |l m+1>; Hermitian, so
    # exp(-i beta J_y) = V diag(exp(-i beta w)) V^H
    c = np.sqrt(l * (l + 1) - m[:-1] * (m[:-1] + 1)) / 2  # <m+1| J_y |m> = c / i
    jy = np.zeros((2 * l + 1, 2 * l + 1), np.complex128)
    jy[np.arange(1, 2 * l + 1), np.arange(2 * l)] = -1j * c
    jy[np.arange(2 * l), np.arange(1, 2 * l + 1)] = 1j * c
    w, v = np.linalg.eigh(jy)
    # the eigenvalues are the integers -l..l: use them rather than the computed ones
    w = np.round(w)
    w.setflags(write=False)
    v.setflags(write=False)
    return w, v


def wigner_d_small(l, beta):
    """Wigner's small-d matrix ``d^l(beta)``, ``(2l + 1, 2l + 1)`` real, indexed
    ``[m + l, m' + l]``: ``d^l_{m m'}(beta) = <l m| exp(-i beta J_y) |l m'>`` (Varshalovich,
    Edmonds; ``d^1_{1,0}(beta) = -sin(beta) / sqrt(2)``).

    Computed from the eigendecomposition of ``J_y`` (stable; errors grow roughly like
    ``l`` times the rounding unit). Meant for checks at moderate ``l``: it costs
    ``O(l^3)``.
    """
    l = _int_arg(l, "l")
    beta = float(beta)
    if not math.isfinite(beta):
        raise ValueError(f"beta must be finite, not {beta}")
    w, v = _jy_eigen(l)
    d = (v * np.exp(-1j * beta * w)) @ v.conj().T
    return np.ascontiguousarray(d.real)


def wigner_D(l, alpha, beta, gamma):
    """Wigner's ``D^l(alpha, beta, gamma)``, ``(2l + 1, 2l + 1)`` complex, indexed
    ``[m + l, m' + l]``::

        D^l_{m m'}(alpha, beta, gamma) = e^{-i m alpha} d^l_{m m'}(beta) e^{-i m' gamma}

    the matrix of the rotation ``Rz(alpha) Ry(beta) Rz(gamma)`` on the ``|l m>`` basis, as in
    so3fft's SO(3) transform (see :func:`wigner_d_small`)."""
    d = wigner_d_small(l, beta)
    m = np.arange(-l, l + 1)
    return np.exp(-1j * m * float(alpha))[:, None] * d * np.exp(-1j * m * float(gamma))[None, :]


def _so3_dense(fhat, B):
    from ._layout import to_dense

    a = np.asarray(fhat)
    if a.ndim == 3:
        if a.shape[1] != a.shape[2] or a.shape[1] != 2 * a.shape[0] - 1:
            raise ValueError(f"dense coefficients: shape {a.shape}, expected (B, 2B - 1, 2B - 1)")
        if B is not None and B != a.shape[0]:
            raise ValueError(f"dense coefficients of bandwidth {a.shape[0]}, but B={B}")
        return _complex_array(a, "coefficients").copy()
    if a.ndim != 1:
        raise ValueError(f"coefficients: shape {a.shape}, expected flat or (B, 2B - 1, 2B - 1)")
    return to_dense(a, B)


def _wigner_factors(B, conjugate):
    l = np.arange(B)
    scale = (np.sqrt((2 * l + 1) / 2) / (2 * np.pi))[:, None, None]
    if not conjugate:
        return scale, None
    m = np.arange(-(B - 1), B)
    sign = np.where((m[:, None] - m[None, :]) % 2 == 0, 1.0, -1.0)[None]
    return scale, sign


def so3_to_wigner_coefficients(fhat, B=None, *, conjugate=False):
    """SO(3) coefficients rescaled to the plain Wigner-D expansion.

    so3fft's expansion uses the orthonormal ``sqrt((2l + 1) / 2) / (2 pi) D^l_{m m'}``; the
    result ``c[l, m + B - 1, m' + B - 1]`` expands the same function as::

        f(alpha, beta, gamma) = sum c(l, m, m') D^l_{m m'}(alpha, beta, gamma)     (conjugate=False)
        f(alpha, beta, gamma) = sum c(l, m, m') conj(D^l_{m m'}(alpha, beta, gamma))  (conjugate=True)

    with ``D`` of :func:`wigner_D`. Since ``conj(D^l_{m m'}) = (-1)^(m - m') D^l_{-m, -m'}``,
    the second is ``c(l, m, m') = (-1)^(m - m') sqrt((2l + 1) / 2) / (2 pi) fhat(l, -m, -m')``.

    Parameters
    ----------
    fhat : array_like
        Flat coefficients in SOFT's order, or the dense array of :func:`so3fft.to_dense`.
    B : int, optional
        Bandwidth (found from the size if not given).
    conjugate : bool
        Expand in ``conj(D)`` instead of ``D``.

    Returns
    -------
    numpy.ndarray
        complex128, ``(B, 2B - 1, 2B - 1)``.
    """
    dense = _so3_dense(fhat, B)
    scale, sign = _wigner_factors(dense.shape[0], conjugate)
    if conjugate:
        return scale * sign * dense[:, ::-1, ::-1]
    return scale * dense


def so3_from_wigner_coefficients(c, *, conjugate=False):
    """Inverse of :func:`so3_to_wigner_coefficients`: the flat SO(3) coefficients (SOFT's
    order) of ``f = sum c(l, m, m') D^l_{m m'}`` (or ``conj(D)`` with ``conjugate``), from
    ``c[l, m + B - 1, m' + B - 1]`` of shape ``(B, 2B - 1, 2B - 1)``; entries with ``|m| >
    l`` or ``|m'| > l`` are ignored."""
    from ._layout import from_dense

    c = np.asarray(c)
    if c.ndim != 3 or c.shape[1] != c.shape[2] or c.shape[1] != 2 * c.shape[0] - 1 or c.shape[0] < 1:
        raise ValueError(f"c: shape {c.shape}, expected (B, 2B - 1, 2B - 1)")
    c = _complex_array(c, "c")
    scale, sign = _wigner_factors(c.shape[0], conjugate)
    dense = c / scale
    if conjugate:
        dense = (sign * dense)[:, ::-1, ::-1]
    return from_dense(dense)
