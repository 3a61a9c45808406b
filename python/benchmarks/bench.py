"""Benchmark of so3fft from Python.

Two parts:

1. S^2 transforms of real fields (forward = analysis, inverse = synthesis): so3fft's
   ``S2Plan(B, real=True)`` against ducc0's ``sht.analysis_2d`` / ``sht.synthesis_2d`` on the
   same grid (ducc0's "F1" geometry with ntheta = nphi = 2B is SOFT's grid,
   theta_j = pi (2j + 1) / (4B), phi_k = pi k / B), in the same process, on the same thread
   count. Before timing, both libraries synthesise the same coefficients and the samples are
   compared; the round-trip errors are reported too.
2. The bindings' overhead: the wall time of a Python call (``Plan.forward(f, out=out)``
   etc., with ``check_finite`` True and False) against the seconds the transform took inside
   the library (every extension transform returns them), for the SO(3) transform at
   B = 16, 32, 64 (complex and real, forward and inverse) and for the S^2 transform.

Times are medians over ``--runs`` calls (more for short calls). Outputs are preallocated and
reused (``out=``), so no part measures NumPy's allocator.

    python bench.py [--threads 1] [--runs 7] [--quick | --big] [--csv FILE]
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import platform
import statistics
import sys
import time

import numpy as np

import so3fft

try:
    import ducc0
except ImportError:  # the S^2 comparison is skipped
    ducc0 = None


# ---------------------------------------------------------------------------------------------
# The host


def cpu_info():
    """CPU model, logical CPUs, and whether the CPU has avx512f and avx2 (Linux)."""
    model, flags = None, None
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                key, _, value = line.partition(":")
                key = key.strip()
                if key == "model name" and model is None:
                    model = value.strip()
                elif key == "flags" and flags is None:
                    flags = set(value.split())
    except OSError:
        pass
    flags = flags or set()
    return model or platform.processor() or "unknown", os.cpu_count(), "avx512f" in flags, \
        "avx2" in flags


# ---------------------------------------------------------------------------------------------
# Timing


def median_time(fn, runs, warmup=1):
    """Median wall time (seconds) of ``fn()`` over ``runs`` calls."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


class Timed:
    """Stands in for a plan's extension object (``plan._plan``) and keeps the seconds the
    last transform took inside the library, so that the wall time of a Python call and the
    library's time come from the same call. (Its own cost, one Python method call, about
    0.1 us, counts as overhead.)"""

    def __init__(self, ext):
        self.ext = ext
        self.last = 0.0

    def forward(self, *a):
        self.last = self.ext.forward(*a)

    def forward_real(self, *a):
        self.last = self.ext.forward_real(*a)

    def inverse(self, *a):
        self.last = self.ext.inverse(*a)

    def inverse_real(self, *a):
        self.last = self.ext.inverse_real(*a)

    def __getattr__(self, name):
        # Everything else (sizes, bandwidth, ...) is the extension object's.
        return getattr(self.ext, name)


def timed(plan):
    """``plan`` with its extension object wrapped in :class:`Timed` (once); the wrapper."""
    if not isinstance(plan._plan, Timed):
        plan._plan = Timed(plan._plan)
    return plan._plan


def paired_times(py_call, recorder, ext_call, runs, warmup=3):
    """Interleaved calls of ``py_call()`` (a Python-level transform whose plan reports to
    ``recorder``) and ``ext_call()`` (the bare extension call, returning the library's
    seconds). Medians of: the Python call's wall time, the library's time in it, their
    difference (the overhead, call by call), and the bare extension call's wall time minus
    its library time; and the smallest overhead seen (the least noisy estimate on a busy
    host)."""
    for _ in range(warmup):
        py_call()
        ext_call()
    wall, lib, over, ext_over = [], [], [], []
    clock = time.perf_counter
    for _ in range(runs):
        t0 = clock()
        py_call()
        t1 = clock()
        t = ext_call()
        t2 = clock()
        wall.append(t1 - t0)
        lib.append(recorder.last)
        over.append(t1 - t0 - recorder.last)
        ext_over.append(t2 - t1 - t)
    m = statistics.median
    return m(wall), m(lib), m(over), m(ext_over), min(over)


def runs_for(seconds_per_call, runs, budget):
    """Calls for one measurement: at least ``runs``, more for short calls (about ``budget``
    seconds), at most 2000."""
    return int(min(2000, max(runs, budget / max(seconds_per_call, 1e-7))))


# ---------------------------------------------------------------------------------------------
# Coefficients: so3fft's seanindex order (all orders) <-> ducc0's real "healpy" order (m >= 0)


def ducc0_layout(B):
    """Indices ``(so3fft_idx, ducc0_idx)`` of the coefficients with m >= 0 in both layouts;
    ``lmax = B - 1``, ducc0's index ``m (2 lmax + 1 - m) / 2 + l``."""
    lm = so3fft.s2_coef_degrees_orders(B)
    sel = np.nonzero(lm[:, 1] >= 0)[0]
    l, m = lm[sel, 0], lm[sel, 1]
    return sel, m * (2 * (B - 1) + 1 - m) // 2 + l


def random_real_coeffs(B, rng):
    """so3fft coefficients of a random real band-limited field (unit-variance, white)."""
    lm = so3fft.s2_coef_degrees_orders(B)
    l, m = lm[:, 0], lm[:, 1]
    c = rng.normal(size=B * B) + 1j * rng.normal(size=B * B)
    c[m == 0] = c[m == 0].real
    neg = np.nonzero(m < 0)[0]
    partner = np.array([so3fft.s2_coef_index(B, int(a), int(-b)) for a, b in zip(l[neg], m[neg])])
    c[neg] = (-1.0) ** (-m[neg]) * np.conj(c[partner])  # fhat(l, -m) = (-1)^m conj fhat(l, m)
    return c


# ---------------------------------------------------------------------------------------------
# Part 1: S^2 transforms against ducc0


def bench_s2_vs_ducc0(bandwidths, threads, runs, rng, rows):
    print(f"\n== S^2 transforms of one real field: so3fft vs ducc0 {ducc0.__version__} "
          f"(grid F1, ntheta = nphi = 2B), {threads} thread(s), medians ==")
    head = (f"{'B':>5} {'dir':>4} | {'so3fft py (s)':>13} {'library (s)':>12} | "
            f"{'ducc0 (s)':>10} | {'ducc0/so3fft':>12} | {'same samples':>12} "
            f"{'round trip so3fft / ducc0':>26}")
    print(head)
    print("-" * len(head))
    for B in bandwidths:
        L, n = B - 1, 2 * B
        plan = so3fft.S2Plan(B, real=True, threads=threads)
        ext = plan._plan  # the bare extension object
        rec = timed(plan)  # plan's calls now report the library's time to rec
        sel, didx = ducc0_layout(B)
        c = random_real_coeffs(B, rng)
        alm = np.zeros((1, B * (B + 1) // 2), np.complex128)
        alm[0, didx] = c[sel]

        # The same coefficients give the same samples (checked before any timing).
        f = plan.inverse(c)
        dmap = np.empty((1, n, n))
        ducc0.sht.synthesis_2d(alm=alm, spin=0, lmax=L, geometry="F1", ntheta=n, nphi=n,
                               nthreads=threads, map=dmap)
        scale = np.max(np.abs(f))
        same = np.max(np.abs(dmap[0] - f)) / scale
        if not same < 1e-10:  # a convention mismatch gives O(1); rounding ~1e-14 B
            raise SystemExit(f"B = {B}: so3fft and ducc0 disagree on the samples ({same:.1e})")
        # Round trips (samples -> coefficients), relative to the largest coefficient.
        back = plan.forward(f)
        dalm = np.empty_like(alm)
        ducc0.sht.analysis_2d(map=dmap, spin=0, lmax=L, geometry="F1", nthreads=threads,
                              alm=dalm)
        cmax = np.max(np.abs(c))
        rt_so3, rt_ducc = np.max(np.abs(back - c)) / cmax, np.max(np.abs(dalm - alm)) / cmax

        out_c = np.empty(B * B, np.complex128)
        out_f = np.empty((n, n))
        cases = {
            "fwd": (lambda: plan.forward(f, out=out_c, check_finite=False),
                    lambda: ext.forward_real(f, out_c, 1, False),
                    lambda: ducc0.sht.analysis_2d(map=dmap, spin=0, lmax=L, geometry="F1",
                                                  nthreads=threads, alm=dalm)),
            "inv": (lambda: plan.inverse(c, out=out_f, check_finite=False),
                    lambda: ext.inverse_real(c, out_f, 1, False),
                    lambda: ducc0.sht.synthesis_2d(alm=alm, spin=0, lmax=L, geometry="F1",
                                                   map=dmap, nthreads=threads)),
        }
        for direction, (py_call, ext_call, ducc_call) in cases.items():
            t_once = median_time(py_call, 1)
            r = runs_for(t_once, runs, 0.3)
            t_py, t_lib, _, _, _ = paired_times(py_call, rec, ext_call, r)
            t_ducc = median_time(ducc_call, r)
            print(f"{B:>5} {direction:>4} | {t_py:>13.3e} {t_lib:>12.3e} | {t_ducc:>10.3e} | "
                  f"{t_ducc / t_py:>12.2f} | {same:>12.1e} {rt_so3:>12.1e} / {rt_ducc:.1e}")
            rows.append(dict(part="s2_vs_ducc0", transform="S2", field="real", B=B,
                             direction=direction, check_finite=False, threads=threads, runs=r,
                             python_s=t_py, library_s=t_lib, ducc0_s=t_ducc,
                             ducc0_over_so3fft=t_ducc / t_py, max_sample_diff=same,
                             round_trip_so3fft=rt_so3, round_trip_ducc0=rt_ducc))


# ---------------------------------------------------------------------------------------------
# Part 2: Python overhead over the library's own time


def overhead_cases(B, threads, rng):
    """(transform, field, direction, Python call(check_finite), its recorder, bare
    extension call(check_finite)) for the SO(3) plan (complex and real) and the S^2 plan
    (real)."""
    n = 2 * B
    for real in (False, True):
        plan = so3fft.Plan(B, real=real, threads=threads)
        shape = plan.sample_shape
        if real:
            f = rng.normal(size=shape)
        else:
            f = rng.normal(size=shape) + 1j * rng.normal(size=shape)
        fhat = plan.forward(f)
        out_c = np.empty(plan.num_coeffs, np.complex128)
        out_f = np.empty(shape, f.dtype)
        ext_fwd = plan._plan.forward_real if real else plan._plan.forward
        ext_inv = plan._plan.inverse_real if real else plan._plan.inverse
        rec = timed(plan)
        field = "real" if real else "complex"
        yield ("SO3", field, "fwd",
               lambda cf, p=plan, f=f, o=out_c: p.forward(f, out=o, check_finite=cf), rec,
               lambda cf, e=ext_fwd, f=f, o=out_c: e(f, o, cf))
        yield ("SO3", field, "inv",
               lambda cf, p=plan, c=fhat, o=out_f: p.inverse(c, out=o, check_finite=cf), rec,
               lambda cf, e=ext_inv, c=fhat, o=out_f: e(c, o, cf))
    s2 = so3fft.S2Plan(B, real=True, threads=threads)
    g = rng.normal(size=(n, n))
    ghat = s2.forward(g)
    out_c = np.empty(B * B, np.complex128)
    out_f = np.empty((n, n))
    ext = s2._plan
    rec = timed(s2)
    yield ("S2", "real", "fwd",
           lambda cf: s2.forward(g, out=out_c, check_finite=cf), rec,
           lambda cf: ext.forward_real(g, out_c, 1, cf))
    yield ("S2", "real", "inv",
           lambda cf: s2.inverse(ghat, out=out_f, check_finite=cf), rec,
           lambda cf: ext.inverse_real(ghat, out_f, 1, cf))


def bench_overhead(bandwidths, threads, runs, budget, rng, rows):
    print(f"\n== Python overhead: wall time of a Python call minus the library's time in the "
          f"same call, {threads} thread(s), medians ==")
    print("   ext over.: the same for the bare extension call (plan._plan.forward(...), no "
          "Python layer)")
    head = (f"{'transform':>9} {'B':>3} {'field':>7} {'dir':>3} {'finite':>6} | "
            f"{'library (us)':>12} {'Python (us)':>11} | "
            f"{'overhead (us)':>13} {'overhead %':>10} {'min (us)':>8} | {'ext over. (us)':>14}")
    print(head)
    print("-" * len(head))
    for B in bandwidths:
        for transform, field, direction, py_call, rec, ext_call in overhead_cases(B, threads, rng):
            for cf in (False, True):
                t_once = median_time(lambda: py_call(cf), 1)
                r = runs_for(t_once, runs, budget)
                t_py, t_lib, over, ext_over, over_min = paired_times(
                    lambda: py_call(cf), rec, lambda: ext_call(cf), r)
                print(f"{transform:>9} {B:>3} {field:>7} {direction:>3} {str(cf):>6} | "
                      f"{1e6 * t_lib:>12.1f} {1e6 * t_py:>11.1f} | "
                      f"{1e6 * over:>13.1f} {100 * over / t_lib:>9.1f}% {1e6 * over_min:>8.1f} | "
                      f"{1e6 * ext_over:>14.1f}")
                rows.append(dict(part="overhead", transform=transform, field=field, B=B,
                                 direction=direction, check_finite=cf, threads=threads, runs=r,
                                 python_s=t_py, library_s=t_lib, overhead_us=1e6 * over,
                                 overhead_pct=100 * over / t_lib, overhead_min_us=1e6 * over_min,
                                 extension_overhead_us=1e6 * ext_over))


# ---------------------------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--threads", type=int, default=1,
                    help="threads for so3fft and ducc0 alike (default 1; 0: all cores)")
    ap.add_argument("--runs", type=int, default=7, help="timed calls per point, at least (default 7)")
    ap.add_argument("--big", action="store_true", help="add B = 1024 to the S^2 comparison")
    ap.add_argument("--quick", action="store_true", help="a short run (fewer sizes and calls)")
    ap.add_argument("--csv", metavar="FILE", help="write every measurement to FILE")
    ap.add_argument("--seed", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.runs < 1:
        ap.error("--runs must be at least 1")
    threads = args.threads if args.threads > 0 else os.cpu_count()
    rng = np.random.default_rng(args.seed)

    if args.quick:
        s2_bandwidths, so3_bandwidths, budget = [64, 128], [16, 32], 0.1
        runs = min(args.runs, 5)
    else:
        s2_bandwidths, so3_bandwidths, budget = [64, 128, 256, 512], [16, 32, 64], 0.4
        runs = args.runs
    if args.big:
        s2_bandwidths.append(1024)

    model, ncpu, avx512f, avx2 = cpu_info()
    isa = getattr(so3fft.Plan(2, threads=1)._plan, "isa", "?")  # the kernels the library chose
    print(f"so3fft {so3fft.__version__} (kernels: {isa}), numpy {np.__version__}, "
          f"Python {platform.python_version()}")
    print(f"CPU: {model}, {ncpu} logical CPUs; avx512f: {'yes' if avx512f else 'no'}, "
          f"avx2: {'yes' if avx2 else 'no'}")

    rows = []
    if ducc0 is None:
        print("\n(ducc0 is not installed: the S^2 comparison is skipped; pip install ducc0)")
    else:
        bench_s2_vs_ducc0(s2_bandwidths, threads, runs, rng, rows)
    bench_overhead(so3_bandwidths, threads, runs, budget, rng, rows)

    if args.csv:
        fields = []
        for r in rows:
            fields += [k for k in r if k not in fields]
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=fields)
            w.writeheader()
            w.writerows(rows)
        print(f"\nwrote {len(rows)} rows to {args.csv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
