"""Argument checks shared by the plans: inputs used in place when they already have the
right dtype, layout and shape, copied when a safe conversion exists, rejected otherwise;
outputs checked, never converted; the plans' precision (``dtype``)."""

from __future__ import annotations

from typing import Any, Dict, Tuple

import numpy as np

#: The precisions of the plans: their real dtype and its complex counterpart.
_PRECISIONS: Dict[np.dtype, Tuple[np.dtype, np.dtype]] = {
    np.dtype(np.float64): (np.dtype(np.float64), np.dtype(np.complex128)),
    np.dtype(np.complex128): (np.dtype(np.float64), np.dtype(np.complex128)),
    np.dtype(np.float32): (np.dtype(np.float32), np.dtype(np.complex64)),
    np.dtype(np.complex64): (np.dtype(np.float32), np.dtype(np.complex64)),
}


def dtype_arg(dtype: Any) -> Tuple[np.dtype, np.dtype]:
    """The real and complex dtypes of the precision ``dtype`` names: ``float64`` or
    ``float32``, as a NumPy type, a ``numpy.dtype`` or a name; ``complex128`` and
    ``complex64`` name the same precisions, and ``None`` is ``float64`` (as for NumPy).
    Anything else is a ``TypeError``."""
    try:
        d = np.dtype(dtype)
    except TypeError as e:
        raise TypeError(f"dtype must be float64 or float32, not {dtype!r} ({e})") from None
    if d not in _PRECISIONS:
        raise TypeError(
            f"dtype must be float64 or float32 (or complex128, complex64), not {d}"
        )
    return _PRECISIONS[d]


def as_input(x, dtype, shapes, what) -> np.ndarray:
    """`x` as a C-contiguous array of `dtype` with one of `shapes` (tuples; `None` in a
    shape matches any length). Arrays that already fit are returned as they are.

    For a single-precision `dtype` (``float32``, ``complex64``), an input with a dtype of
    more precision (``float64``, ``complex128``, ...) is a ``TypeError``: rounding it would
    lose information. Python lists and numbers have no dtype and are rounded, as NumPy
    rounds Python floats mixed with ``float32`` arrays."""
    if (
        type(x) is np.ndarray
        and x.dtype == dtype
        and x.flags.c_contiguous
        and x.flags.aligned
        and x.shape in shapes
    ):
        return x
    a = np.asarray(x)
    if a.dtype == object or not (
        np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_
    ):
        raise TypeError(f"{what}: expected numbers, got an array of {a.dtype}")
    if not np.can_cast(a.dtype, dtype, casting="same_kind"):
        raise TypeError(
            f"{what}: cannot convert {a.dtype} to {np.dtype(dtype)} without losing "
            "information (complex data for a real plan?)"
        )
    if _narrows(x, a.dtype, np.dtype(dtype)):
        raise TypeError(
            f"{what}: a single-precision plan takes {np.dtype(dtype)}, not {a.dtype} "
            f"(convert explicitly, e.g. x.astype(numpy.{np.dtype(dtype)}), to round it, "
            "or use a plan with dtype=numpy.float64)"
        )
    if not any(_fits(a.shape, s) for s in shapes):
        expected = " or ".join(str(s) for s in shapes)
        raise ValueError(f"{what}: shape {a.shape}, expected {expected}")
    return np.require(a, dtype=dtype, requirements=["C", "A"])


def _narrows(x, have: np.dtype, want: np.dtype) -> bool:
    """Whether converting `x` (of dtype `have`, if it has one) to the single-precision
    `want` would round a more precise floating-point dtype."""
    return (
        want in (np.float32, np.complex64)
        and hasattr(x, "dtype")
        and np.issubdtype(have, np.inexact)
        and np.finfo(have).precision > np.finfo(want).precision
    )


def _fits(shape, pattern):
    return len(shape) == len(pattern) and all(
        p is None or p == s for s, p in zip(shape, pattern)
    )


def check_output(out, dtype, shape, what="out") -> np.ndarray:
    """`out` if it is a writeable C-contiguous array of `dtype` and `shape` (else an error:
    outputs are written in place, so they cannot be converted)."""
    if not isinstance(out, np.ndarray):
        raise TypeError(f"{what} must be a numpy.ndarray, not {type(out).__name__}")
    if out.dtype != dtype:
        raise TypeError(f"{what} must have dtype {np.dtype(dtype)}, not {out.dtype}")
    if out.shape != shape:
        raise ValueError(f"{what} must have shape {shape}, not {out.shape}")
    if not (out.flags.c_contiguous and out.flags.aligned):
        raise ValueError(f"{what} must be C-contiguous and aligned")
    if not out.flags.writeable:
        raise ValueError(f"{what} is read-only")
    return out


def apart(x: np.ndarray, out: np.ndarray) -> np.ndarray:
    """`x`, copied if it shares memory with `out` (the transforms read all of their input
    while they write their output)."""
    return x.copy() if np.may_share_memory(x, out) else x


def int_arg(x, name, low, high):
    """`x` as an int in `low ..= high` (TypeError for non-integers and bools)."""
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, not {x!r}")
    if x < low:
        raise ValueError(f"{name} must be at least {low}, not {x}")
    if x > high:
        raise ValueError(f"{name} must be at most {high}, not {x}")
    return int(x)


def threads_arg(threads):
    return int_arg(threads, "threads (0: all cores)", 0, 1 << 31)


def bandwidth_arg(b, name="B"):
    # The library names its own limits (MAX_BANDWIDTH, S2_MAX_BANDWIDTH) in its errors.
    return int_arg(b, name, 1, 1 << 31)
