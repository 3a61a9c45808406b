"""Single precision (``dtype=numpy.float32``): SO(3), S^2 and correlation plans against the
double-precision plans on the same data, output dtypes, round trips, the ``dtype`` argument,
inputs of the wrong precision, matching (same grid peaks, refinement as in double) and
concurrent use."""

import numpy as np
import pytest

import so3fft
from conftest import random_coeffs, random_s2_coeffs
from test_threads import _run_concurrently, python_runs_during

#: The relative L2 error allowed of a single-precision transform (docs/precision.md: about
#: 1e-6 at B = 64 to 256).
TOL = 1e-5


def rel(a, b):
    """Relative L2 distance of ``a`` from ``b``, in double."""
    a = np.asarray(a, np.complex128)
    b = np.asarray(b, np.complex128)
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def single(x):
    """``x`` rounded to single precision (``complex64`` or ``float32``)."""
    return x.astype(np.complex64 if np.iscomplexobj(x) else np.float32)


# ---------------------------------------------------------------------------------------
# The dtype argument


@pytest.mark.parametrize(
    "dtype", [np.float32, "float32", "f4", np.dtype(np.float32), np.complex64, "complex64"]
)
def test_dtype_spellings_of_single(dtype):
    for plan in (
        so3fft.Plan(4, dtype=dtype, threads=1),
        so3fft.S2Plan(4, dtype=dtype, threads=1),
        so3fft.Correlation(4, dtype=dtype, threads=1),
    ):
        assert plan.dtype == np.float32 and isinstance(plan.dtype, np.dtype)
        assert plan._plan.dtype == "float32"
        assert "dtype='float32'" in repr(plan)


@pytest.mark.parametrize(
    "dtype", [np.float64, "float64", "float", float, complex, np.complex128, None]
)
def test_dtype_spellings_of_double(dtype):
    for plan in (
        so3fft.Plan(4, dtype=dtype, threads=1),
        so3fft.S2Plan(4, dtype=dtype, threads=1),
        so3fft.Correlation(4, dtype=dtype, threads=1),
    ):
        assert plan.dtype == np.float64
        assert plan._plan.dtype == "float64"
        assert "dtype" not in repr(plan)  # the default, as before


def test_default_is_double():
    assert so3fft.Plan(4, threads=1).dtype == np.float64
    assert so3fft.S2Plan(4, threads=1).dtype == np.float64
    assert so3fft.Correlation(4, threads=1).dtype == np.float64


@pytest.mark.parametrize(
    "dtype", [np.int32, np.float16, np.longdouble, "int64", np.bool_, "nonsense", object, 3]
)
def test_bad_dtype_is_a_type_error(dtype):
    for make in (so3fft.Plan, so3fft.S2Plan, so3fft.Correlation):
        with pytest.raises(TypeError, match="dtype must be float64 or float32"):
            make(2, dtype=dtype, threads=1)
    with pytest.raises(TypeError, match="dtype must be float64 or float32"):
        so3fft.correlate(np.zeros((4, 4)), np.zeros((4, 4)), dtype=dtype)


def test_extension_rejects_bad_dtype_names():
    with pytest.raises(TypeError, match="'float64' or 'float32'"):
        so3fft._so3fft.Plan(4, False, 1, "estimate", "float16")
    with pytest.raises(TypeError, match="'float64' or 'float32'"):
        so3fft._so3fft.S2Plan(4, 1, "estimate", "complex64")
    with pytest.raises(TypeError, match="'float64' or 'float32'"):
        so3fft._so3fft.Correlation(4, None, None, False, False, 1, "estimate", "f4")


# ---------------------------------------------------------------------------------------
# SO(3)


@pytest.mark.parametrize("B", [16, 64])
@pytest.mark.parametrize("real", [False, True])
def test_so3_single_against_double(rng, B, real):
    p64 = so3fft.Plan(B, real=real, threads=2)
    p32 = so3fft.Plan(B, real=real, dtype=np.float32, threads=2)
    assert (p32.num_coeffs, p32.sample_shape, p32.real) == (
        p64.num_coeffs,
        p64.sample_shape,
        p64.real,
    )
    c = single(random_coeffs(rng, B, real=real))
    f32 = p32.inverse(c)
    assert f32.dtype == (np.float32 if real else np.complex64)
    assert f32.shape == p64.sample_shape
    f64 = p64.inverse(c)  # the same data: complex64 converted exactly
    assert rel(f32, f64) < TOL
    back32 = p32.forward(f32)
    assert back32.dtype == np.complex64 and back32.shape == (p32.num_coeffs,)
    assert rel(back32, p64.forward(f32)) < TOL
    assert rel(back32, c) < TOL  # round trip


def test_so3_single_error_is_about_1e_6(rng):
    B = 64
    c = single(random_coeffs(rng, B))
    p32 = so3fft.Plan(B, dtype="float32", threads=2)
    err = rel(p32.forward(p32.inverse(c)), c)
    assert 1e-8 < err < 5e-6  # single, not double, precision: docs/precision.md 8.6e-7


@pytest.mark.parametrize("real", [False, True])
def test_so3_single_out_arguments(rng, real):
    B = 8
    plan = so3fft.Plan(B, real=real, dtype=np.float32, threads=1)
    sdt = np.float32 if real else np.complex64
    c = single(random_coeffs(rng, B, real=real))
    f_out = np.full(plan.sample_shape, np.nan, sdt)
    assert plan.inverse(c, out=f_out) is f_out
    c_out = np.full(plan.num_coeffs, np.nan, np.complex64)
    assert plan.forward(f_out, out=c_out) is c_out
    assert rel(c_out, c) < TOL
    # Outputs of double precision are not converted.
    with pytest.raises(TypeError, match="out must have dtype"):
        plan.inverse(c, out=np.empty(plan.sample_shape, np.float64 if real else complex))
    with pytest.raises(TypeError, match="out must have dtype complex64"):
        plan.forward(f_out, out=np.empty(plan.num_coeffs, complex))


def test_so3_single_refuses_double_inputs(rng):
    B = 4
    plan = so3fft.Plan(B, dtype=np.float32, threads=1)
    rplan = so3fft.Plan(B, real=True, dtype=np.float32, threads=1)
    c = random_coeffs(rng, B)
    f = rng.standard_normal(plan.sample_shape)
    with pytest.raises(TypeError, match="single-precision plan takes complex64, not complex128"):
        plan.inverse(c)
    with pytest.raises(TypeError, match="takes complex64, not float64"):
        plan.forward(f)
    with pytest.raises(TypeError, match="takes float32, not float64"):
        rplan.forward(f)
    with pytest.raises(TypeError, match="complex data for a real plan"):
        rplan.forward(single(f + 0j))
    # Lossless inputs are converted: float32 samples to a complex plan, integers, booleans,
    # complex64 coefficients given as float32 (zero imaginary parts).
    ints = rng.integers(-5, 6, size=plan.sample_shape)
    want = plan.forward(ints.astype(np.complex64))
    assert np.array_equal(plan.forward(ints.astype(np.float32)), want)
    assert np.array_equal(plan.forward(ints), want)
    assert np.array_equal(rplan.forward(ints > 0), rplan.forward((ints > 0).astype(np.float32)))
    c32 = single(c)
    assert np.array_equal(plan.inverse(c32.real), plan.inverse(c32.real + 0j))
    # Python lists have no dtype: rounded, as NumPy rounds Python floats.
    assert np.array_equal(plan.inverse(c.tolist()), plan.inverse(c32))


def test_double_plans_still_convert_single_inputs(rng):
    B = 4
    plan = so3fft.Plan(B, threads=1)
    c = single(random_coeffs(rng, B))
    f = plan.inverse(c)
    assert f.dtype == np.complex128
    assert np.array_equal(f, plan.inverse(c.astype(np.complex128)))


def test_extension_checks_array_dtypes(rng):
    B = 4
    plan = so3fft.Plan(B, dtype=np.float32, threads=1)
    c = np.zeros(plan.num_coeffs, np.complex64)
    with pytest.raises(TypeError, match="samples must be a numpy array of complex64, not an"):
        plan._plan.forward(np.zeros(plan.sample_shape, complex), c, True)
    with pytest.raises(TypeError, match="out must be a numpy array of complex64"):
        plan._plan.forward(np.zeros(plan.sample_shape, np.complex64), c.astype(complex), True)
    samples = np.zeros(plan.sample_shape, np.complex64)
    with pytest.raises(TypeError, match="coefficients must be a numpy array of complex64, not li"):
        plan._plan.inverse([0j] * plan.num_coeffs, samples, True)
    # A double plan refuses single arrays at the low level too.
    p64 = so3fft.Plan(B, threads=1)
    with pytest.raises(TypeError, match="complex128"):
        p64._plan.inverse(c, np.zeros(p64.sample_shape, complex), True)


@pytest.mark.parametrize("real", [False, True])
def test_so3_single_check_finite(rng, real):
    B = 4
    plan = so3fft.Plan(B, real=real, dtype=np.float32, threads=1)
    f = np.zeros(plan.sample_shape, np.float32 if real else np.complex64)
    f[1, 2, 3] = np.inf
    with pytest.raises(ValueError, match="NaN or infinite"):
        plan.forward(f)
    c = np.zeros(plan.num_coeffs, np.complex64)
    c[-1] = np.nan
    with pytest.raises(ValueError, match="NaN or infinite"):
        plan.inverse(c)
    plan.inverse(c, check_finite=False)  # no error without the check


# ---------------------------------------------------------------------------------------
# S^2


@pytest.mark.parametrize("B", [16, 64])
@pytest.mark.parametrize("real", [False, True])
def test_s2_single_against_double(rng, B, real):
    p64 = so3fft.S2Plan(B, real=real, threads=2)
    p32 = so3fft.S2Plan(B, real=real, dtype=np.float32, threads=2)
    c = single(random_s2_coeffs(rng, B, real=real))
    f32 = p32.inverse(c)
    assert f32.dtype == (np.float32 if real else np.complex64)
    assert f32.shape == p32.sample_shape
    assert rel(f32, p64.inverse(c)) < TOL
    back = p32.forward(f32)
    assert back.dtype == np.complex64 and back.shape == (B * B,)
    assert rel(back, p64.forward(f32)) < TOL
    assert rel(back, c) < TOL


@pytest.mark.parametrize("real", [False, True])
def test_s2_single_many_fields(rng, real):
    B, n = 12, 3
    p32 = so3fft.S2Plan(B, real=real, dtype=np.float32, threads=1)
    c = single(np.stack([random_s2_coeffs(rng, B, real=real) for _ in range(n)]))
    f = p32.inverse(c)
    assert f.shape == (n, 2 * B, 2 * B) and f.dtype == (np.float32 if real else np.complex64)
    for i in range(n):
        assert np.array_equal(f[i], p32.inverse(c[i]))
    back = p32.forward(f)
    assert back.shape == (n, B * B) and back.dtype == np.complex64
    assert rel(back, c) < TOL
    out = np.empty((n, B * B), np.complex64)
    assert p32.forward(f, out=out) is out
    with pytest.raises(TypeError, match="takes complex64, not complex128"):
        p32.inverse(c.astype(np.complex128))
    with pytest.raises(TypeError, match="out must have dtype complex64"):
        p32.forward(f, out=np.empty((n, B * B), complex))


# ---------------------------------------------------------------------------------------
# Matching

G = so3fft.Rotation(-2.5, 2.2, 0.3)


def single_pair(rng, B, real):
    """Single-precision S^2 samples ``(signal, pattern)`` with ``signal(x) = pattern(g^-1 x)``
    up to rounding to single precision."""
    h = random_s2_coeffs(rng, B, real=real)
    f = so3fft.rotate_s2_coeffs(h, G)
    plan = so3fft.S2Plan(B, real=real, threads=1)
    return single(plan.inverse(f)), single(plan.inverse(h))


@pytest.mark.parametrize("real", [False, True])
@pytest.mark.parametrize("B, b_out", [(16, None), (24, 32)])
def test_correlation_single_against_double(rng, real, B, b_out):
    signal, pattern = single_pair(rng, B, real)
    c64 = so3fft.Correlation(B, b_out=b_out, real=real, threads=2)
    c32 = so3fft.Correlation(B, b_out=b_out, real=real, dtype=np.float32, threads=2)
    assert (c32.b_out, c32.deg_lim, c32.grid_shape) == (c64.b_out, c64.deg_lim, c64.grid_shape)
    grid64, best64 = c64.correlate_argmax(signal, pattern)  # the same data, widened
    grid32, best32 = c32.correlate_argmax(signal, pattern)
    assert grid32.dtype == (np.float32 if real else np.complex64)
    assert grid32.shape == c32.grid_shape
    assert rel(grid32, grid64) < TOL
    assert np.array_equal(c32.correlate(signal, pattern), grid32)
    # The same grid argmax, in the fused search and in top_peaks of the float grid.
    assert best32.index == best64.index
    assert best32.value == pytest.approx(best64.value, rel=1e-5)
    peaks32 = so3fft.top_peaks(grid32, k=3)
    peaks64 = so3fft.top_peaks(grid64, k=3)
    assert [p.index for p in peaks32] == [p.index for p in peaks64]
    assert peaks32[0].index == best32.index
    # top_peaks searches a float grid as it is: the same as the grid widened.
    assert so3fft.top_peaks(grid32, k=3) == so3fft.top_peaks(
        grid32.astype(np.complex128 if not real else np.float64), k=3
    )
    # Coefficients are complex128 and those of double precision; so is the refinement.
    co32 = c32.coefficients(signal, pattern)
    co64 = c64.coefficients(signal, pattern)
    assert co32.dtype == np.complex128
    assert rel(co32, co64) < 1e-12
    starts = [p.rotation for p in peaks32[:1]]
    (g32, v32), = c32.refine(co32, starts)
    (g64, v64), = c64.refine(co64, starts)
    assert isinstance(g32.alpha, float) and isinstance(v32, float)
    assert g32.angle_to(g64) < 1e-8
    assert v32 == pytest.approx(v64, rel=1e-10)
    # The true rotation, up to the rounding of the data to single precision.
    assert g32.angle_to(G) < 1e-6


@pytest.mark.parametrize("real", [False, True])
def test_match_single_equals_double(rng, real):
    B = 16
    signal, pattern = single_pair(rng, B, real)
    found32 = so3fft.Correlation(B, real=real, dtype="float32", threads=1).match(signal, pattern)
    found64 = so3fft.Correlation(B, real=real, threads=1).match(signal, pattern)
    assert len(found32) == len(found64) == 1
    assert found32[0][0].angle_to(found64[0][0]) < 1e-8


@pytest.mark.parametrize("real", [False, True])
def test_correlation_single_shells_and_errors(rng, real):
    B = 8
    c32 = so3fft.Correlation(B, real=real, dtype=np.float32, threads=1)
    c64 = so3fft.Correlation(B, real=real, threads=1)
    pairs = [single_pair(rng, B, real) for _ in range(2)]
    shells = [(s, p, w) for (s, p), w in zip(pairs, (1.0, 0.5))]
    g32 = c32.correlate_shells(shells)
    assert g32.dtype == (np.float32 if real else np.complex64)
    assert rel(g32, c64.correlate_shells(shells)) < TOL
    s, p = pairs[0]
    wide = s.astype(np.float64 if real else np.complex128)
    with pytest.raises(TypeError, match="single-precision plan"):
        c32.correlate(wide, p)
    with pytest.raises(TypeError, match="single-precision plan"):
        c32.coefficients(s, wide)
    with pytest.raises(TypeError, match="single-precision plan"):
        c32.correlate_shells([(wide, p, 1.0)])
    with pytest.raises(TypeError, match="out must have dtype"):
        c32.correlate(s, p, out=np.empty(c32.grid_shape, wide.dtype))
    with pytest.raises(TypeError, match="out must have dtype complex128"):
        c32.coefficients(s, p, out=np.empty(so3fft.num_coeffs(B), np.complex64))
    bad = s.copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN or infinite"):
        c32.correlate(bad, p)


@pytest.mark.parametrize("real", [False, True])
def test_module_level_correlate_single(rng, real):
    B = 8
    s, p = single_pair(rng, B, real)
    grid = so3fft.correlate(s, p, dtype=np.float32, threads=1)
    assert grid.dtype == (np.float32 if real else np.complex64)
    assert np.array_equal(
        grid, so3fft.Correlation(B, real=real, dtype=np.float32, threads=1).correlate(s, p)
    )
    # Lists are rounded; float64 arrays refused.
    assert np.array_equal(so3fft.correlate(s.tolist(), p.tolist(), dtype="float32"), grid)
    with pytest.raises(TypeError, match="single-precision plan"):
        so3fft.correlate(s.astype(np.result_type(s, np.float64)), p, dtype=np.float32)
    # The default stays double, whatever the inputs' precision.
    assert so3fft.correlate(s, p, threads=1).dtype == (np.float64 if real else np.complex128)


# ---------------------------------------------------------------------------------------
# Threads


@pytest.mark.parametrize("real", [False, True])
def test_concurrent_single_transforms_equal_sequential_ones(real):
    B = 32
    rng = np.random.default_rng(11)
    shared = so3fft.Plan(B, real=real, dtype=np.float32, threads=1)
    ref = so3fft.Plan(B, real=real, dtype=np.float32, threads=1)
    coeffs = [single(random_coeffs(rng, B, real=real)) for _ in range(4)]
    want_inv = [ref.inverse(c) for c in coeffs]
    want_fwd = [ref.forward(f) for f in want_inv]
    jobs = []
    for c, f in zip(coeffs, want_inv):
        jobs.append(lambda c=c: shared.inverse(c))
        jobs.append(lambda f=f: shared.forward(f))
    got = _run_concurrently(jobs)
    for i in range(4):
        assert np.array_equal(got[2 * i], want_inv[i])
        assert np.array_equal(got[2 * i + 1], want_fwd[i])


def test_concurrent_single_s2_and_correlation_equal_sequential():
    B = 24
    rng = np.random.default_rng(12)
    s2 = so3fft.S2Plan(B, dtype=np.float32, threads=1)
    corr = so3fft.Correlation(B, dtype=np.float32, threads=2)
    ref = so3fft.Correlation(B, dtype=np.float32, threads=2)
    pairs = [single_pair(rng, B, False) for _ in range(4)]
    want = [ref.correlate(s, p) for s, p in pairs]
    want_s2 = [so3fft.S2Plan(B, dtype=np.float32, threads=1).forward(s) for s, _ in pairs]
    got = _run_concurrently([lambda s=s, p=p: corr.correlate(s, p) for s, p in pairs], workers=4)
    assert all(np.array_equal(g, w) for g, w in zip(got, want))
    got = _run_concurrently([lambda s=s: s2.forward(s) for s, _ in pairs], workers=4)
    assert all(np.array_equal(g, w) for g, w in zip(got, want_s2))


def test_gil_is_released_during_single_transforms():
    B = 64
    rng = np.random.default_rng(13)
    plan = so3fft.Plan(B, dtype=np.float32, threads=1)
    shape = plan.sample_shape
    f = single(rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    c = np.empty(plan.num_coeffs, np.complex64)
    out = np.empty(plan.sample_shape, np.complex64)
    assert python_runs_during(lambda: plan._plan.forward(f, c, True), tries=5) > 0
    assert python_runs_during(lambda: plan._plan.inverse(c, out, True), tries=5) > 0
