#!/usr/bin/env python3
"""Exact reference values for the so3fft stress suite (so3fft-stress, tests/stress.rs).

Everything is computed from the definitions in docs/conventions.md with mpmath at 40 digits,
independently of so3fft, then rounded once to double. Inputs (coefficients or samples) are not
stored: both sides draw them from the same tiny PRNG (splitmix64, below; the Rust side is
tools/src/bin/so3fft-stress/rng.rs), so the files hold only outputs and stay small.

Usage: python3 gen_stress_reference.py [outdir]     (deterministic; about 4 minutes on one core)

Files (one per bandwidth B and kind; lines after the '#' header):
  inverse_B{B}.txt  f at a subset of grid points (k j1 j2 re im) of the inverse transform of
                    random coefficients: seed 1000+B, drawn re then im for l = 0..B-1,
                    M = -l..l, M' = -l..l (in that nesting), each uniform in [-1, 1).
  forward_B{B}.txt  coefficients (l M Mp re im) of the forward transform (the quadrature of
                    docs/conventions.md) of random samples on the whole grid, not band-limited:
                    seed 2000+B, drawn re then im in flat sample order (k, j1, j2).
  poles_B{B}.txt    the same for samples that are zero except on the first and last beta
                    slices (k = 0, then k = 2B-1, each in (j1, j2) order): seed 3000+B.
"""
import os
import random
import sys

import mpmath as mp

mp.mp.dps = 40
MASK = (1 << 64) - 1


class SplitMix64:
    """splitmix64 (Vigna); sym() is uniform in [-1, 1) with 53 random bits, exact in double."""

    def __init__(self, seed):
        self.state = seed & MASK

    def next_u64(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def sym(self):
        return 2.0 * ((self.next_u64() >> 11) * 2.0 ** -53) - 1.0


def beta(k, b):
    return mp.pi * (2 * k + 1) / (4 * b)


def wigner_d_sum(l, m, mp_, bet):
    """d^l_{m,m'}(beta) by Wigner's explicit sum (short sums only: the first two degrees)."""
    c, s = mp.cos(bet / 2), mp.sin(bet / 2)
    f = mp.factorial
    pref = mp.sqrt(f(l + m) * f(l - m) * f(l + mp_) * f(l - mp_))
    total = mp.mpf(0)
    for k in range(max(0, mp_ - m), min(l + mp_, l - m) + 1):
        den = f(l + mp_ - k) * f(k) * f(m - mp_ + k) * f(l - m - k)
        total += (-1) ** (m - mp_ + k) * c ** (2 * l + mp_ - m - 2 * k) * s ** (m - mp_ + 2 * k) / den
    return pref * total


def wigner_d_column(m, mp_, lmax, bet):
    """[d^l_{m,m'}(beta) for l = l0..lmax], l0 = max(|m|, |m'|), by the three-term recurrence."""
    l0 = max(abs(m), abs(mp_))
    out = [wigner_d_sum(l0, m, mp_, bet)]
    if lmax > l0:
        out.append(wigner_d_sum(l0 + 1, m, mp_, bet))
    cb = mp.cos(bet)
    for l in range(l0 + 1, lmax):
        a = (2 * l + 1) * (l * (l + 1) * cb - m * mp_)
        c = (l + 1) * mp.sqrt(mp.mpf((l * l - m * m) * (l * l - mp_ * mp_)))
        den = l * mp.sqrt(mp.mpf(((l + 1) ** 2 - m * m) * ((l + 1) ** 2 - mp_ * mp_)))
        out.append((a * out[-1] - c * out[-2]) / den)
    return out


def dt_column(m, mp_, b, bet):
    """sqrt((2l+1)/2) d^l_{m,m'}(beta) for l = l0..b-1."""
    l0 = max(abs(m), abs(mp_))
    col = wigner_d_column(m, mp_, b - 1, bet)
    return [mp.sqrt(mp.mpf(2 * (l0 + i) + 1) / 2) * v for i, v in enumerate(col)]


def weight(k, b):
    """w_B(k) = (2/B) sin(beta_k) sum_{i<B} sin((2i+1) beta_k)/(2i+1)."""
    bk = beta(k, b)
    return 2 * mp.sin(bk) / b * mp.fsum(mp.sin((2 * i + 1) * bk) / (2 * i + 1) for i in range(b))


def orders(b):
    return range(-(b - 1), b)


def expjpi_table(b):
    """exp(i pi t / B) for t = 0..2B-1 (indexed by M j mod 2B)."""
    return [mp.expjpi(mp.mpf(t) / b) for t in range(2 * b)]


def fmt(z):
    return "%r %r" % (float(mp.re(z)), float(mp.im(z)))


def write_inverse(outdir, b):
    rng = SplitMix64(1000 + b)
    coef = {}
    for l in range(b):
        for m in range(-l, l + 1):
            for mq in range(-l, l + 1):
                re = rng.sym()
                coef[(l, m, mq)] = mp.mpc(re, rng.sym())
    pick = random.Random(b)
    n = 2 * b
    ks = sorted({0, 1, b // 2, b - 1, b, n - 2, n - 1, pick.randrange(n)})
    e = expjpi_table(b)
    lines = []
    for k in ks:
        bk = beta(k, b)
        # T(M, M') = sum_l fhat(l, M, M') dt^l_{M,M'}(beta_k) / (2 pi)
        t = {}
        for m in orders(b):
            for mq in orders(b):
                l0 = max(abs(m), abs(mq))
                col = dt_column(m, mq, b, bk)
                t[(m, mq)] = mp.fsum(coef[(l0 + i, m, mq)] * v for i, v in enumerate(col)) / (2 * mp.pi)
        points = {(0, 0), (n - 1, n - 1), (b, 1)}
        while len(points) < 8:
            points.add((pick.randrange(n), pick.randrange(n)))
        for j1, j2 in sorted(points):
            # f = sum T(M, M') exp(-i M alpha_j1) exp(-i M' gamma_j2), alpha_j = pi j / B
            v = mp.fsum(tv * e[(-m * j1 - mq * j2) % n] for (m, mq), tv in t.items())
            lines.append("%d %d %d %s" % (k, j1, j2, fmt(v)))
    head = ("# inverse transform, B=%d: f(alpha_j1, beta_k, gamma_j2) of coefficients drawn by "
            "SplitMix64(%d) (see gen_stress_reference.py)\n# k j1 j2 re im (40-digit sums rounded to double)\n"
            % (b, 1000 + b))
    with open(os.path.join(outdir, "inverse_B%d.txt" % b), "w") as f:
        f.write(head + "\n".join(lines) + "\n")


def forward_reference(b, samples, wanted):
    """Quadrature coefficients fhat(l, M, M') for the (l, M, M') in `wanted`.

    samples: dict k -> list of (2B)^2 complex values (flat j1 2B + j2); missing slices are 0."""
    n = 2 * b
    e = expjpi_table(b)
    pairs = sorted({(m, mq) for (_, m, mq) in wanted})
    mps = sorted({mq for (_, mq) in pairs})
    # H[k][(M, M')] = sum_{j1, j2} exp(+i M alpha_j1) exp(+i M' gamma_j2) f
    h = {}
    for k, sl in samples.items():
        g = {(j1, mq): mp.fsum(sl[j1 * n + j2] * e[(mq * j2) % n] for j2 in range(n))
             for j1 in range(n) for mq in mps}
        h[k] = {(m, mq): mp.fsum(g[(j1, mq)] * e[(m * j1) % n] for j1 in range(n)) for (m, mq) in pairs}
    w = {k: weight(k, b) for k in samples}
    dt = {(m, mq, k): dt_column(m, mq, b, beta(k, b)) for (m, mq) in pairs for k in samples}
    out = {}
    for (l, m, mq) in wanted:
        l0 = max(abs(m), abs(mq))
        s = mp.fsum(w[k] * dt[(m, mq, k)][l - l0] * h[k][(m, mq)] for k in samples)
        out[(l, m, mq)] = mp.pi / (2 * b * b) * s
    return out


def wanted_coefficients(b, limit):
    every = [(l, m, mq) for l in range(b) for m in range(-l, l + 1) for mq in range(-l, l + 1)]
    if len(every) <= limit:
        return every
    top = b - 1
    must = {(0, 0, 0), (top, top, top), (top, top, -top), (top, -top, top), (top, 0, 0),
            (top, top, 0), (top, 0, -top), (b // 2, 1, -1)}
    pick = random.Random(7 * b)
    chosen = set(must)
    while len(chosen) < limit:
        chosen.add(pick.choice(every))
    return sorted(chosen)


def write_forward(outdir, b, kind, limit):
    n = 2 * b
    seed = (2000 if kind == "forward" else 3000) + b
    rng = SplitMix64(seed)
    slices = range(n) if kind == "forward" else (0, n - 1)
    samples = {}
    for k in slices:
        sl = []
        for _ in range(n * n):
            re = rng.sym()
            sl.append(mp.mpc(re, rng.sym()))
        samples[k] = sl
    wanted = wanted_coefficients(b, limit)
    ref = forward_reference(b, samples, wanted)
    what = "random samples on every beta" if kind == "forward" else \
        "random samples on beta_0 and beta_{2B-1} only (zero elsewhere)"
    head = ("# forward transform (quadrature), B=%d, %s drawn by SplitMix64(%d)\n"
            "# l M Mp re im (40-digit sums rounded to double)\n" % (b, what, seed))
    with open(os.path.join(outdir, "%s_B%d.txt" % (kind, b)), "w") as f:
        f.write(head + "\n".join("%d %d %d %s" % (l, m, mq, fmt(ref[(l, m, mq)]))
                                 for (l, m, mq) in wanted) + "\n")


def self_check():
    """The recurrence against the explicit sum, and d^1_{1,0} = -sin(b)/sqrt(2)."""
    bet = mp.mpf("0.7")
    for (m, mq) in [(0, 0), (2, -1), (-3, 3), (1, 0)]:
        col = wigner_d_column(m, mq, 9, bet)
        for i, v in enumerate(col):
            assert abs(v - wigner_d_sum(max(abs(m), abs(mq)) + i, m, mq, bet)) < mp.mpf(10) ** -30
    assert abs(wigner_d_sum(1, 1, 0, bet) + mp.sin(bet) / mp.sqrt(2)) < mp.mpf(10) ** -35
    assert abs(mp.fsum(weight(k, 4) for k in range(8)) - 2) < mp.mpf(10) ** -35


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    which = sys.argv[2:] or ["inverse", "forward", "poles"]
    self_check()
    if "inverse" in which:
        for b in (4, 8, 16, 32):
            write_inverse(out, b)
    if "forward" in which:
        for b in (4, 8, 16, 32):
            write_forward(out, b, "forward", 400)
    if "poles" in which:
        for b in (4, 8, 16):
            write_forward(out, b, "poles", 400)
