"""The transforms release the GIL, and concurrent use of plans (one shared plan or one per
thread) gives bitwise the results of sequential use. No timing is asserted: the release of
the GIL is shown by Python code of another thread running *during* a transform."""

import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import so3fft
from conftest import random_coeffs, random_s2_coeffs


def python_runs_during(call, tries=1):
    """How often another Python thread advanced a counter while ``call()`` (a single call
    into the extension) ran in a worker thread; the most of ``tries`` runs (on a loaded host
    the main thread may not be scheduled during one short call).

    The interpreter's switch interval is raised to an hour for the measurement, so the
    interpreter never takes the GIL from a thread by force: the main thread can run Python
    code between the worker's two readings of the counter only if the extension released
    the GIL. The main thread sleeps briefly in its loop so the worker gets the GIL back."""
    return max(_runs_during(call) for _ in range(tries))


def _runs_during(call):
    counter = [0]
    go, done = threading.Event(), threading.Event()
    seen = {}

    def worker():
        go.set()
        before = counter[0]
        call()
        seen["during"] = counter[0] - before
        done.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(3600.0)
    try:
        t = threading.Thread(target=worker)
        t.start()
        go.wait()
        while not done.is_set():
            counter[0] += 1
            time.sleep(1e-4)
        t.join()
    finally:
        sys.setswitchinterval(old)
    return seen["during"]


@pytest.fixture(scope="module")
def big():
    B = 64
    rng = np.random.default_rng(7)
    n = 2 * B
    plan = so3fft.Plan(B, threads=1)
    rplan = so3fft.Plan(B, real=True, threads=1)
    f = rng.standard_normal((n, n, n)) + 1j * rng.standard_normal((n, n, n))
    c = np.empty(plan.num_coeffs, complex)
    return B, plan, rplan, f, c


def test_gil_is_released_during_transforms(big):
    B, plan, rplan, f, c = big
    out = np.empty(plan.sample_shape, complex)
    rout = np.empty(plan.sample_shape)
    # The extension's own calls (no Python code of the package inside the window).
    assert python_runs_during(lambda: plan._plan.forward(f, c, True), tries=5) > 0
    assert python_runs_during(lambda: plan._plan.inverse(c, out, True), tries=5) > 0
    assert python_runs_during(lambda: rplan._plan.inverse_real(c, rout, True), tries=5) > 0
    assert python_runs_during(lambda: rplan._plan.forward_real(rout, c, True), tries=5) > 0


def test_gil_is_released_during_correlation():
    B = 48
    rng = np.random.default_rng(8)
    s2 = so3fft.S2Plan(B, threads=1)
    s, p = s2.inverse(random_s2_coeffs(rng, B)), s2.inverse(random_s2_coeffs(rng, B))
    corr = so3fft.Correlation(B, b_out=64, threads=1)
    out = np.empty(corr.grid_shape, complex)
    assert python_runs_during(lambda: corr._plan.correlate(s, p, out, False), tries=5) > 0


def test_control_a_call_that_holds_the_gil_shows_no_progress():
    # The measurement itself: pure Python work of the same length holds the GIL throughout.
    def busy():
        end = time.perf_counter() + 0.05
        while time.perf_counter() < end:
            pass

    assert python_runs_during(busy) == 0


def _run_concurrently(jobs, workers=2):
    """Run the callables ``jobs`` on ``workers`` threads started together; their results."""
    barrier = threading.Barrier(workers)

    def run(job):
        barrier.wait()
        return job()

    with ThreadPoolExecutor(workers) as ex:
        # Submit in rounds of `workers` so that each round starts together at the barrier.
        results = []
        for i in range(0, len(jobs), workers):
            results += list(ex.map(run, jobs[i : i + workers]))
    return results


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("real", [False, True])
def test_concurrent_transforms_equal_sequential_ones(threads, real):
    B = 40
    rng = np.random.default_rng(9)
    shared = so3fft.Plan(B, real=real, threads=threads)
    other = so3fft.Plan(B, real=real, threads=threads)
    coeffs = [random_coeffs(rng, B, real=real) for _ in range(4)]
    # Sequential truth (a fresh plan of the same options).
    ref = so3fft.Plan(B, real=real, threads=threads)
    want_inv = [ref.inverse(c) for c in coeffs]
    want_fwd = [ref.forward(f) for f in want_inv]

    # One shared plan, two threads at once, both directions mixed.
    jobs = []
    for c, f in zip(coeffs, want_inv):
        jobs.append(lambda c=c: shared.inverse(c))
        jobs.append(lambda f=f: shared.forward(f))
    got = _run_concurrently(jobs)
    for i in range(4):
        assert np.array_equal(got[2 * i], want_inv[i])
        assert np.array_equal(got[2 * i + 1], want_fwd[i])

    # Two plans, one per thread.
    jobs = []
    for c in coeffs:
        jobs.append(lambda c=c: shared.inverse(c))
        jobs.append(lambda c=c: other.inverse(c))
    got = _run_concurrently(jobs)
    for i in range(4):
        assert np.array_equal(got[2 * i], want_inv[i])
        assert np.array_equal(got[2 * i + 1], want_inv[i])

    # Many threads on one plan, with `out` arrays.
    outs = [np.empty(shared.num_coeffs, complex) for _ in range(4)]
    jobs = [lambda f=f, o=o: shared.forward(f, out=o) for f, o in zip(want_inv, outs)]
    got = _run_concurrently(jobs, workers=4)
    for i in range(4):
        assert got[i] is outs[i]
        assert np.array_equal(outs[i], want_fwd[i])


def test_concurrent_s2_and_correlation_equal_sequential():
    B = 24
    rng = np.random.default_rng(10)
    s2 = so3fft.S2Plan(B, threads=1)
    corr = so3fft.Correlation(B, threads=2)
    pairs = [
        (s2.inverse(random_s2_coeffs(rng, B)), s2.inverse(random_s2_coeffs(rng, B)))
        for _ in range(4)
    ]
    ref = so3fft.Correlation(B, threads=2)
    want = [ref.correlate(s, p) for s, p in pairs]
    want_s2 = [so3fft.S2Plan(B, threads=1).forward(s) for s, _ in pairs]
    got = _run_concurrently([lambda s=s, p=p: corr.correlate(s, p) for s, p in pairs], workers=4)
    assert all(np.array_equal(g, w) for g, w in zip(got, want))
    got = _run_concurrently([lambda s=s: s2.forward(s) for s, _ in pairs], workers=4)
    assert all(np.array_equal(g, w) for g, w in zip(got, want_s2))
