"""Every bad input raises an ordinary Python exception (a subclass of ``Exception``) with a
useful message, and never crashes the interpreter: wrong dtypes and shapes, bad bandwidths,
bad outputs, non-finite values, memory exhaustion, bad options, bad rotations and peaks."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import so3fft
from so3fft import _so3fft

B = 4
N = 2 * B
NC = (4 * B**3 - B) // 3


@pytest.fixture(scope="module")
def plans():
    return {
        "complex": so3fft.Plan(B, threads=1),
        "real": so3fft.Plan(B, real=True, threads=1),
        "s2": so3fft.S2Plan(B, threads=1),
        "s2real": so3fft.S2Plan(B, real=True, threads=1),
        "corr": so3fft.Correlation(B, threads=1),
        "corrreal": so3fft.Correlation(B, real=True, threads=1),
    }


def run_isolated(code, timeout=60):
    """Run ``code`` in a fresh interpreter; its stdout (the process must exit normally)."""
    proc = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={"RUST_BACKTRACE": "0", "PATH": "/usr/bin:/bin"},
    )
    assert proc.returncode == 0, f"exit {proc.returncode}\nstdout: {proc.stdout}\nstderr: {proc.stderr}"
    return proc.stdout


def raised(f):
    """The exception ``f()`` raises, caught as ``BaseException`` (so that a Rust panic, which
    PyO3 raises as ``pyo3_runtime.PanicException``, a ``BaseException``, is seen), or None."""
    try:
        f()
    except BaseException as e:  # noqa: BLE001 - the point is to see anything raised
        return e
    return None


# ---------------------------------------------------------------------------------------
# dtypes and shapes


def test_complex_samples_to_a_real_plan(plans):
    z = np.zeros((N, N, N), complex)
    with pytest.raises(TypeError, match="complex data for a real plan"):
        plans["real"].forward(z)
    with pytest.raises(TypeError, match="complex"):
        plans["s2real"].forward(np.zeros((N, N), complex))
    with pytest.raises(TypeError, match="complex"):
        plans["corrreal"].correlate(np.zeros((N, N), complex), np.zeros((N, N)))
    # Complex samples that happen to be real-valued are still refused (no silent dropping).
    with pytest.raises(TypeError):
        plans["real"].forward(np.ones((N, N, N), complex))


@pytest.mark.parametrize(
    "bad",
    [np.array([["a"] * N] * N * N), np.array([None] * N**3, dtype=object), "samples", None],
    ids=["strings", "objects", "str", "None"],
)
def test_non_numeric_samples(plans, bad):
    with pytest.raises(TypeError, match="expected numbers"):
        plans["complex"].forward(bad)


@pytest.mark.parametrize(
    "shape",
    [(N, N, N - 1), (N, N), (1, N, N, N), (N**3 - 1,), (N**3 + 1,), (), (0,), (N + 2,) * 3],
)
def test_wrong_sample_shapes(plans, shape):
    for kind in ("complex", "real"):
        with pytest.raises(ValueError, match=r"samples: shape"):
            plans[kind].forward(np.zeros(shape))


@pytest.mark.parametrize("n", [0, 1, NC - 1, NC + 1, 2 * NC])
def test_wrong_size_coefficients(plans, n):
    for kind in ("complex", "real"):
        with pytest.raises(ValueError, match=r"coefficients: shape"):
            plans[kind].inverse(np.zeros(n, complex))
    with pytest.raises(ValueError, match=r"coefficients: shape"):
        plans["complex"].inverse(np.zeros((1, NC), complex))
    with pytest.raises(ValueError, match="shape"):
        plans["corr"].refine(np.zeros(n), [(0, 0, 0)])
    # Sizes that are no number of SO(3) coefficients at any bandwidth ((4B^3 - B) / 3 is
    # 1, 10, 35, 84, 165, ...).
    if n not in (1, NC):
        with pytest.raises(ValueError):
            so3fft.to_dense(np.zeros(n))
        with pytest.raises(ValueError):
            so3fft.evaluate(np.zeros(n), [(0, 0, 0)])
        with pytest.raises(ValueError):
            so3fft.refine(np.zeros(n), [(0, 0, 0)])


def test_wrong_size_s2_coefficients(plans):
    with pytest.raises(ValueError, match="B\\^2"):
        so3fft.rotate_s2_coeffs(np.ones(15), (0, 0, 0))
    with pytest.raises(ValueError, match="B\\^2"):
        so3fft.rotate_s2_coeffs(np.ones(0), (0, 0, 0))
    with pytest.raises(ValueError, match="coefficients: shape"):
        plans["s2"].inverse(np.ones(15))
    with pytest.raises(ValueError, match="samples: shape"):
        plans["s2"].forward(np.ones((N, N - 1)))
    with pytest.raises(ValueError, match="signal: shape"):
        plans["corr"].correlate(np.ones((N, N - 1)), np.ones((N, N)))
    with pytest.raises(ValueError, match="pattern: shape"):
        so3fft.correlate(np.ones((N, N)), np.ones((N - 2, N - 2)))
    with pytest.raises(ValueError, match="expected \\(2B, 2B\\)"):
        so3fft.correlate(np.ones((7, 7)), np.ones((7, 7)))


def test_dense_shapes():
    with pytest.raises(ValueError, match="dense array"):
        so3fft.from_dense(np.zeros((4, 7, 6)))
    with pytest.raises(ValueError, match="not a number of SO\\(3\\) coefficients"):
        so3fft.to_dense(np.zeros(85))
    with pytest.raises(ValueError):
        so3fft.to_dense(np.zeros(NC), B=5)


# ---------------------------------------------------------------------------------------
# Bandwidths


@pytest.mark.parametrize("make", [so3fft.Plan, so3fft.S2Plan, so3fft.Correlation])
def test_bad_bandwidths(make):
    with pytest.raises(ValueError, match="at least 1"):
        make(0)
    with pytest.raises(ValueError, match="at least 1"):
        make(-3)
    for bad in (4.0, 4.5, "4", None, True, [4]):
        with pytest.raises(TypeError, match="must be an integer"):
            make(bad)
    assert make(np.int32(2)).B == 2


def test_too_large_bandwidths():
    with pytest.raises(ValueError, match="invalid bandwidth 2049"):
        so3fft.Plan(so3fft.MAX_BANDWIDTH + 1)
    with pytest.raises(ValueError, match="invalid bandwidth"):
        so3fft.S2Plan(so3fft.S2_MAX_BANDWIDTH + 1)
    with pytest.raises(ValueError, match="invalid bandwidth"):
        so3fft.Correlation(so3fft.S2_MAX_BANDWIDTH + 1)
    with pytest.raises(ValueError, match="at most"):
        so3fft.Plan(2**70)
    for f in (so3fft.num_coeffs, so3fft.num_samples, so3fft.coef_degrees_orders):
        with pytest.raises(ValueError):
            f(so3fft.MAX_BANDWIDTH + 1)
        with pytest.raises(ValueError):
            f(0)
    # The grids and weights serve the S^2 transforms too, up to their larger limit.
    for f in (so3fft.weights, so3fft.grid_angles, so3fft.s2_grid_angles):
        assert np.size(f(so3fft.MAX_BANDWIDTH + 1)) > 0
        with pytest.raises(ValueError):
            f(so3fft.S2_MAX_BANDWIDTH + 1)
        with pytest.raises(ValueError):
            f(0)


def test_correlation_options():
    with pytest.raises(ValueError, match="b_out must be at least 1"):
        so3fft.Correlation(B, b_out=0)
    with pytest.raises(TypeError, match="b_out must be an integer"):
        so3fft.Correlation(B, b_out=2.5)
    with pytest.raises(ValueError, match="degree limit"):
        so3fft.Correlation(B, deg_lim=B)
    with pytest.raises(ValueError, match="degree limit"):
        so3fft.Correlation(B, b_out=2, deg_lim=3)
    with pytest.raises(ValueError, match="deg_lim"):
        so3fft.Correlation(B, deg_lim=-1)
    with pytest.raises(TypeError, match="deg_lim"):
        so3fft.Correlation(B, deg_lim=1.5)
    with pytest.raises(TypeError, match="deg_lim"):
        so3fft.Correlation(B, deg_lim=True)


def test_index_out_of_range():
    with pytest.raises(ValueError, match="does not exist"):
        so3fft.coef_index(B, B, 0, 0)
    with pytest.raises(ValueError, match="does not exist"):
        so3fft.coef_index(B, 1, 2, 0)
    with pytest.raises(ValueError, match="does not exist"):
        so3fft.coef_index(B, 1, 0, -2)
    with pytest.raises(ValueError, match="negative"):
        so3fft.coef_index(B, -1, 0, 0)
    with pytest.raises(ValueError, match="does not exist"):
        so3fft.coef_index(B, 3, 2**62, 0)
    with pytest.raises(ValueError, match="does not exist"):
        so3fft.s2_coef_index(B, B, 0)
    with pytest.raises(ValueError, match="does not exist"):
        so3fft.s2_coef_index(B, 2, 3)


# ---------------------------------------------------------------------------------------
# Outputs


@pytest.mark.parametrize("kind", ["complex", "real"])
def test_bad_out_arrays(plans, kind):
    plan = plans[kind]
    f = np.zeros((N, N, N), np.float64 if kind == "real" else np.complex128)
    c = np.zeros(NC, complex)
    # Non-contiguous.
    with pytest.raises(ValueError, match="C-contiguous"):
        plan.forward(f, out=np.zeros(2 * NC, complex)[::2])
    with pytest.raises(ValueError, match="C-contiguous"):
        plan.inverse(c, out=np.zeros((N, N, 2 * N), f.dtype)[:, :, ::2])
    with pytest.raises(ValueError, match="C-contiguous"):
        plan.inverse(c, out=np.asfortranarray(np.zeros((N, N, N), f.dtype)))
    # Read-only.
    ro = np.zeros(NC, complex)
    ro.setflags(write=False)
    with pytest.raises(ValueError, match="read-only"):
        plan.forward(f, out=ro)
    ro = np.broadcast_to(np.zeros(1, f.dtype), (N, N, N))
    with pytest.raises(ValueError):
        plan.inverse(c, out=ro)
    # Wrong dtype.
    for dt in (np.complex64, np.float64, np.int64):
        with pytest.raises(TypeError, match="dtype complex128"):
            plan.forward(f, out=np.zeros(NC, dt))
    other = np.complex128 if kind == "real" else np.float64
    with pytest.raises(TypeError, match="must have dtype"):
        plan.inverse(c, out=np.zeros((N, N, N), other))
    # Wrong shape, not an array.
    with pytest.raises(ValueError, match="must have shape"):
        plan.forward(f, out=np.zeros(NC - 1, complex))
    with pytest.raises(ValueError, match="must have shape"):
        plan.inverse(c, out=np.zeros(N**3, f.dtype))
    with pytest.raises(TypeError, match="numpy.ndarray"):
        plan.forward(f, out=[0j] * NC)


def test_bad_out_arrays_of_s2_and_correlation(plans):
    z = np.zeros((N, N), complex)
    with pytest.raises(TypeError, match="dtype"):
        plans["s2"].forward(z, out=np.zeros(B * B))
    with pytest.raises(ValueError, match="read-only"):
        ro = np.zeros(B * B, complex)
        ro.setflags(write=False)
        plans["s2"].forward(z, out=ro)
    with pytest.raises(ValueError, match="C-contiguous"):
        plans["s2"].inverse(np.zeros(B * B), out=np.zeros((N, 2 * N), complex)[:, ::2])
    with pytest.raises(TypeError, match="dtype"):
        plans["corr"].correlate(z, z, out=np.zeros((N, N, N)))
    with pytest.raises(ValueError, match="C-contiguous"):
        plans["corr"].correlate(z, z, out=np.zeros((N, N, 2 * N), complex)[:, :, ::2])
    with pytest.raises(ValueError, match="must have shape"):
        plans["corr"].coefficients(z, z, out=np.zeros(NC - 1, complex))


def _overlap_cases():
    rng = np.random.default_rng(1)
    buf = rng.standard_normal(4096) + 1j * rng.standard_normal(4096)
    s, p = buf[:64].reshape(N, N), buf[64:128].reshape(N, N)
    return {
        "Plan.forward": lambda: (so3fft.Plan(B, threads=1).forward, (buf[:512].reshape(N, N, N),), buf[:NC]),
        "Plan.inverse": lambda: (so3fft.Plan(B, threads=1).inverse, (buf[:NC],), buf[:512].reshape(N, N, N)),
        "S2Plan.forward": lambda: (so3fft.S2Plan(B, threads=1).forward, (buf[:64].reshape(N, N),), buf[:16]),
        "Correlation.correlate": lambda: (so3fft.Correlation(B, threads=1).correlate, (s, p), buf[:512].reshape(N, N, N)),
        "Correlation.coefficients": lambda: (so3fft.Correlation(B, threads=1).coefficients, (s, p), buf[:NC]),
    }


@pytest.mark.parametrize("case", list(_overlap_cases()))
def test_out_overlapping_an_input(case):
    # An `out` that overlaps an input must not reach Rust as aliased slices (a panic of
    # rust-numpy's borrow check, or worse): a ValueError, or a correct result from a copied
    # input, are both fine.
    method, args, out = _overlap_cases()[case]()
    want = method(*(a.copy() for a in args))  # the result without overlap
    err = raised(lambda: method(*args, out=out))
    if err is None:
        assert np.allclose(out, want)  # the input was copied before `out` was written
    else:
        assert isinstance(err, ValueError), f"{type(err).__module__}.{type(err).__name__}: {err}"
        assert "overlap" in str(err)


def test_out_disjoint_from_the_input_in_one_buffer():
    # Disjoint parts of one buffer are fine (the borrow check looks at the memory ranges).
    buf = np.zeros(2048, complex)
    buf[:512] = np.arange(512)
    plan = so3fft.Plan(B, threads=1)
    out = buf[1024 : 1024 + NC]
    assert plan.forward(buf[:512].reshape(N, N, N), out=out) is out
    assert np.array_equal(out, plan.forward(np.arange(512).reshape(N, N, N)))


# ---------------------------------------------------------------------------------------
# Non-finite values


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_samples_and_coefficients(plans, bad):
    f = np.zeros((N, N, N), complex)
    f[1, 2, 3] = bad
    with pytest.raises(ValueError, match="samples contain NaN or infinite"):
        plans["complex"].forward(f)
    got = plans["complex"].forward(f, check_finite=False)  # no check, no exception
    assert got.shape == (NC,) and not np.all(np.isfinite(got))
    with pytest.raises(ValueError, match="samples contain NaN or infinite"):
        plans["real"].forward(f.real)
    plans["real"].forward(f.real, check_finite=False)
    f[1, 2, 3] = complex(0, bad)  # in the imaginary part only
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["complex"].forward(f)

    c = np.zeros(NC, complex)
    c[7] = bad
    for kind in ("complex", "real"):
        with pytest.raises(ValueError, match="coefficients contain NaN or infinite"):
            plans[kind].inverse(c)
        assert not np.all(np.isfinite(plans[kind].inverse(c, check_finite=False)))
    c[7] = complex(1, bad)
    with pytest.raises(ValueError, match="coefficients contain NaN or infinite"):
        plans["complex"].inverse(c)

    # S^2 transforms.
    g = np.zeros((N, N), complex)
    g[0, 5] = bad
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["s2"].forward(g)
    plans["s2"].forward(g, check_finite=False)
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["s2real"].forward(g.real)
    s2c = np.zeros(B * B, complex)
    s2c[3] = bad
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["s2"].inverse(s2c)
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["s2real"].inverse(s2c)
    plans["s2"].inverse(s2c, check_finite=False)

    # Matching.
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["corr"].correlate(g, np.ones((N, N)))
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["corrreal"].correlate(np.ones((N, N)), g.real)
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["corr"].coefficients(np.ones((N, N)), g)
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["corr"].correlate_shells([(np.ones((N, N)), g, 1.0)])
    with pytest.raises(ValueError, match="NaN or infinite"):
        so3fft.correlate(g.real, np.ones((N, N)))
    cc = np.ones(NC, complex)
    cc[0] = bad
    with pytest.raises(ValueError, match="NaN or infinite"):
        plans["corr"].refine(cc, [(0, 0, 0)])
    with pytest.raises(ValueError, match="NaN or infinite"):
        so3fft.refine(cc, [(0, 0, 0)])
    with pytest.raises(ValueError, match="NaN or infinite"):
        so3fft.evaluate(cc, [(0, 0, 0)])
    with pytest.raises(ValueError, match="not finite"):
        plans["corr"].correlate_shells([(np.ones((N, N)), np.ones((N, N)), bad)])


@pytest.mark.parametrize("bad", [np.nan, np.inf, complex(0, -np.inf)])
def test_rotate_s2_coeffs_rejects_non_finite_coefficients(bad):
    # Like every entry point taking coefficients: non-finite input is an error, not NaN out.
    c = np.ones(B * B, complex)
    c[2] = bad
    with pytest.raises(ValueError, match="NaN or infinite"):
        so3fft.rotate_s2_coeffs(c, (0.1, 0.2, 0.3))


# ---------------------------------------------------------------------------------------
# Memory


def test_too_large_to_allocate_raises_memory_error():
    # Plan(2048) needs far more than this machine has; the library refuses it from its
    # estimate, before building tables. The test still runs in a child process whose
    # address space is capped 1 GiB above what it already maps, so that a regression fails
    # fast instead of allocating.
    out = run_isolated(
        """
        import os, resource
        import numpy as np
        import so3fft
        page = os.sysconf("SC_PAGE_SIZE")
        with open("/proc/self/statm") as f:
            mapped = int(f.read().split()[0]) * page
        cap = mapped + (1 << 30)
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        for make in (lambda: so3fft.Plan(2048), lambda: so3fft.Plan(2048, real=True),
                     lambda: so3fft.Correlation(2048)):
            try:
                make()
                print("no error")
            except MemoryError as e:
                print("MemoryError", e)
        # The process is still usable afterwards.
        p = so3fft.Plan(4, threads=1)
        c = np.zeros(p.num_coeffs, complex); c[0] = 1
        print("ok", abs(p.forward(p.inverse(c))[0] - 1) < 1e-14)
        """
    )
    lines = out.splitlines()
    assert all(line.startswith("MemoryError out of memory") for line in lines[:3]), out
    assert lines[3] == "ok True", out


# ---------------------------------------------------------------------------------------
# Options


@pytest.mark.parametrize("make", [so3fft.Plan, so3fft.S2Plan, so3fft.Correlation])
def test_bad_rigor_and_threads(make):
    for rigor in ("fast", "", "estimate "):
        with pytest.raises(ValueError, match="rigor must be 'estimate'"):
            make(2, rigor=rigor)
    for rigor in (None, 3):
        with pytest.raises(TypeError):
            make(2, rigor=rigor)
    assert make(2, rigor="MEASURE", threads=1).B == 2  # case does not matter
    with pytest.raises(ValueError, match="threads .* must be at least 0"):
        make(2, threads=-1)
    for threads in (1.5, "x", None, [1]):
        with pytest.raises((TypeError, ValueError)):
            make(2, threads=threads)
    with pytest.raises(ValueError, match="threads requested"):
        make(2, threads=10**6)
    with pytest.raises(ValueError, match="at most"):
        make(2, threads=2**64)


# ---------------------------------------------------------------------------------------
# Peaks and rotations


def test_bad_top_peaks_arguments():
    grid = np.ones((N, N, N))
    for k in (-1, 1.5, "x", None):
        with pytest.raises((ValueError, TypeError)):
            so3fft.top_peaks(grid, k=k)
    with pytest.raises(ValueError, match="k must be at least 0"):
        so3fft.top_peaks(grid, k=-1)
    for k in (True, 2.0, np.inf, 2**70):
        with pytest.raises((TypeError, ValueError)):
            so3fft.top_peaks(grid, k=k)
    for angle in (-1.0, np.nan, -np.inf):
        with pytest.raises(ValueError, match="min_angle must be a non-negative"):
            so3fft.top_peaks(grid, min_angle=angle)
        with pytest.raises(ValueError, match="min_angle must be a non-negative"):
            so3fft.top_peaks(grid + 0j, min_angle=angle)
    with pytest.raises(ValueError):
        so3fft.top_peaks(grid, min_angle="wide")
    for shape in ((N, N, N - 1), (0,), (7,), (5, 5)):
        with pytest.raises(ValueError, match="\\(2B\\)\\^3"):
            so3fft.top_peaks(np.ones(shape))
    with pytest.raises(TypeError):
        so3fft.top_peaks(np.array(["a"] * 8))
    corr = so3fft.Correlation(B, threads=1)
    s = np.ones((N, N))
    with pytest.raises(ValueError, match="k must be at least 0"):
        corr.match(s, s, k=-2)
    assert corr.match(s, s, k=0) == []
    with pytest.raises(ValueError, match="min_angle"):
        corr.match(s, s, min_angle=-0.1)
    assert so3fft.top_peaks(grid, k=0) == []


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_bad_rotations(bad):
    c = np.ones(NC, complex)
    for rot in ((bad, 0, 0), (0, bad, 0), (0, 0, bad)):
        with pytest.raises(ValueError, match="angles must be finite"):
            so3fft.rotate_s2_coeffs(np.ones(B * B), rot)
        with pytest.raises(ValueError, match="angles must be finite"):
            so3fft.rotate_s2_coeffs(np.ones(B * B), so3fft.Rotation(*rot))
        with pytest.raises(ValueError, match="angles must be finite"):
            so3fft.evaluate(c, [(0, 0, 0), rot])
        with pytest.raises(ValueError, match="angles must be finite"):
            so3fft.refine(c, [rot])
        with pytest.raises(ValueError, match="angles must be finite"):
            so3fft.Correlation(B, threads=1).refine(c, np.array([rot]))
    with pytest.raises(ValueError, match="finite 3x3"):
        so3fft.Rotation.from_matrix(np.full((3, 3), bad))
    with pytest.raises(ValueError, match="four finite numbers"):
        so3fft.Rotation.from_quaternion([1, 0, bad, 0])


def test_malformed_rotations():
    c = np.ones(NC, complex)
    with pytest.raises(ValueError, match="rows of three Euler angles"):
        so3fft.evaluate(c, np.zeros((2, 4)))
    with pytest.raises(ValueError, match="rows of three Euler angles"):
        so3fft.refine(c, np.zeros((1, 2, 3)))
    with pytest.raises((ValueError, TypeError)):
        so3fft.evaluate(c, [(0, 0)])
    with pytest.raises(ValueError):
        so3fft.Rotation("a", 0, 0)
    with pytest.raises(TypeError):
        so3fft.rotate_s2_coeffs(np.ones(B * B), (0, 0))
    with pytest.raises(ValueError, match="not a rotation"):
        so3fft.Rotation.from_matrix(-np.eye(3))
    with pytest.raises(ValueError, match="not a rotation"):
        so3fft.Rotation.from_matrix(2 * np.eye(3))
    with pytest.raises(ValueError, match="finite 3x3"):
        so3fft.Rotation.from_matrix(np.eye(2))
    with pytest.raises(ValueError, match="not all 0"):
        so3fft.Rotation.from_quaternion([0, 0, 0, 0])
    with pytest.raises(ValueError):
        so3fft.Rotation.from_quaternion([1, 0, 0])


def test_bad_series_arguments():
    c = np.ones(NC, complex)
    with pytest.raises(ValueError, match="deg_lim"):
        so3fft.evaluate(c, [(0, 0, 0)], deg_lim=B)
    with pytest.raises(ValueError, match="deg_lim"):
        so3fft.refine(c, [(0, 0, 0)], deg_lim=B + 3)
    with pytest.raises(TypeError, match="deg_lim"):
        so3fft.evaluate(c, [(0, 0, 0)], deg_lim=1.5)
    with pytest.raises(TypeError, match="deg_lim"):
        so3fft.evaluate(c, [(0, 0, 0)], deg_lim=np.inf)
    with pytest.raises(ValueError, match="not a number of SO\\(3\\) coefficients"):
        so3fft.evaluate(np.ones(NC + 1), [(0, 0, 0)])
    with pytest.raises(ValueError, match="no shells"):
        so3fft.Correlation(B, threads=1).correlate_shells([])
    with pytest.raises(ValueError):
        so3fft.Correlation(B, threads=1).correlate_shells([(np.ones((N, N)), np.ones((N, N)))])


def test_negative_deg_lim_of_series_is_a_value_error():
    """A negative degree limit is a ValueError, not an OverflowError from the conversion."""
    c = np.ones(NC, complex)
    with pytest.raises(ValueError, match="deg_lim"):
        so3fft.evaluate(c, [(0, 0, 0)], deg_lim=-1)
    with pytest.raises(ValueError, match="deg_lim"):
        so3fft.refine(c, [(0, 0, 0)], deg_lim=-1)


# ---------------------------------------------------------------------------------------
# The extension's low level, misused directly: exceptions, never a crash


def test_extension_misuse_in_a_child_process():
    out = run_isolated(
        """
        import numpy as np
        from so3fft import _so3fft as m
        p = m.Plan(4, False, 1, "estimate")
        c, s = np.zeros(84, complex), np.zeros(512, complex)
        S = m.S2Plan(4, 1, "estimate")
        C = m.Correlation(4, None, None, False, False, 1, "estimate")
        cases = {
            "short input": lambda: p.forward(np.zeros(511, complex), c, True),
            "short output": lambda: p.forward(s, np.zeros(83, complex), True),
            "strided input": lambda: p.forward(np.zeros(1024, complex)[::2], c, True),
            "strided output": lambda: p.forward(s, np.zeros(168, complex)[::2], True),
            "wrong dtype": lambda: p.forward(np.zeros(512), c, True),
            "a list": lambda: p.forward([0j] * 512, c, True),
            "read-only output": lambda: p.forward(s, np.frombuffer(bytes(84 * 16), complex), True),
            "output is the input": lambda: p.inverse(c, c, True),
            "output inside the input": lambda: p.forward(s, s[:84], True),
            "real on a complex plan": lambda: p.forward_real(np.zeros(512), c, True),
            "howmany too large": lambda: S.forward(np.zeros(64, complex), np.zeros(16, complex), 2**62, True),
            "howmany 0": lambda: S.forward(np.zeros(0, complex), np.zeros(0, complex), 0, True),
            "howmany negative": lambda: S.forward(np.zeros(64, complex), np.zeros(16, complex), -1, True),
            "grid too short": lambda: C.correlate(np.zeros(64, complex), np.zeros(64, complex), np.zeros(511, complex), False),
            "starts of 4 columns": lambda: C.refine(c, np.zeros((1, 4))),
            "series bandwidth 0": lambda: m.refine_series(0, 0, c, np.zeros((1, 3))),
            "series length": lambda: m.evaluate_series(5, 0, c, np.zeros((1, 3))),
            "rotate bandwidth 0": lambda: m.rotate_s2_coeffs(0, np.zeros(0, complex), (0.0, 0.0, 0.0)),
            "rotate bandwidth huge": lambda: m.rotate_s2_coeffs(10**5, np.zeros(16, complex), (0.0, 0.0, 0.0)),
            "coef_index huge": lambda: m.coef_index(4, 2**62, 0, 0),
        }
        for name, f in cases.items():
            try:
                f()
                print(name, "| no error")
            except Exception as e:
                print(name, "|", type(e).__name__)
            except BaseException as e:
                print(name, "| BaseException", type(e).__name__)
        print("survived")
        """
    )
    lines = out.splitlines()
    assert lines[-1] == "survived"
    results = dict(line.split(" | ") for line in lines[:-1])
    assert not any(r.startswith("BaseException") for r in results.values()), out
    assert results["short input"] == "ValueError"
    assert results["strided output"] == "ValueError"
    assert results["wrong dtype"] == "TypeError"
    assert results["read-only output"] == "ValueError"
    assert results["output inside the input"] == "ValueError"
    assert results["real on a complex plan"] == "ValueError"
    assert results["howmany too large"] == "ValueError"
    assert results["howmany 0"] == "ValueError"
    assert results["rotate bandwidth huge"] == "ValueError"
    assert all(r != "no error" for r in results.values()), out
