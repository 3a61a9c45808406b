# Precision of the scaled Wigner-d recurrence (RecTables::coeffs form) run in f32
# (FMA emulated: products/sums in f64, one rounding to f32) against f64.
import numpy as np, math, sys
from math import lgamma

def coeffs(m, mp, n):
    # A_l, C_l, Bc_l for l = m .. m+n-1 (f64, adequate as reference here)
    l = np.arange(m, m + n, dtype=np.float64)
    q = lambda L: np.sqrt(np.maximum((L*L - m*m) * (L*L - mp*mp), 0.0))
    A = (l + 1) * np.sqrt((2*l + 3) * (2*l + 1)) / q(l + 1)
    with np.errstate(divide='ignore', invalid='ignore'):
        C = np.where(l > 0, -A * m * mp / (l * (l + 1)), 0.0)
        Bc = np.where(l > 0, np.sqrt((2*l + 3) / (2*l - 1)) * (l + 1) / l * q(l) / q(l + 1), 0.0)
    return A, C, Bc

def log_start(m, mp, beta):
    # log |dt^m_{m,mp}(beta)| = 0.5 log((2m+1)/2 binom(2m, m-mp)) + (m+mp) log cos(b/2) + (m-mp) log sin(b/2)
    lb = lgamma(2*m + 1) - lgamma(m - mp + 1) - lgamma(m + mp + 1)
    return 0.5 * (math.log((2*m + 1) / 2) + lb) + (m + mp) * np.log(np.cos(beta / 2)) + (m - mp) * np.log(np.sin(beta / 2))

def run(m, mp, B, dtype, mult_dtype=None):
    """Values dt^{m+i}(beta_k) for i < n, betas of the SO(3) grid, lower half only (tau = 1 - cos b)."""
    n = B - m
    k = np.arange(2 * B)
    beta = np.pi * (2 * k + 1) / (4 * B)
    beta = beta[beta < np.pi / 2]
    tau = 2 * np.sin(beta / 2) ** 2          # 1 - cos(beta), from the half angle
    A, C, Bc = coeffs(m, mp, n)
    S = np.ones(n + 1)
    for i in range(1, n):
        S[i + 1] = Bc[i] * S[i - 1]
    Ap = A * S[:n] / S[1:n + 1]
    ApC = (A + C) * S[:n] / S[1:n + 1]
    ls = log_start(m, mp, beta)
    # start split as mantissa * 2^E, E tracked in f64 (extended exponent)
    E = np.floor(ls / math.log(2))
    p1 = np.exp(ls - E * math.log(2)).astype(dtype)
    p0 = np.zeros_like(p1)
    tau_d = tau.astype(dtype)
    out = np.zeros((n, beta.size))
    STEP = 60.0
    for i in range(n):
        out[i] = p1.astype(np.float64) * 2.0 ** E * S[i]
        a = dtype(-Ap[i]); b = dtype(ApC[i])
        t = (a.astype(np.float64) * tau_d.astype(np.float64) + np.float64(b)).astype(dtype)
        p2 = (t.astype(np.float64) * p1.astype(np.float64) - p0.astype(np.float64)).astype(dtype)
        p0, p1 = p1, p2
        big = np.abs(p1) > 2.0 ** 40
        if big.any():
            p0 = np.where(big, p0 * dtype(2.0 ** -STEP), p0).astype(dtype)
            p1 = np.where(big, p1 * dtype(2.0 ** -STEP), p1).astype(dtype)
            E = np.where(big, E + STEP, E)
    w = np.sin(beta)  # crude weight proxy for the L2 norm over beta
    return out, w

def err(m, mp, B):
    ref, w = run(m, mp, B, np.float64)
    f32, _ = run(m, mp, B, np.float32)
    # mixed: f64 recurrence, d values rounded to f32
    mix = ref.astype(np.float32).astype(np.float64)
    sw = np.sqrt(w)
    nrm = np.linalg.norm(ref * sw)
    e32 = np.linalg.norm((f32 - ref) * sw) / nrm
    emix = np.linalg.norm((mix - ref) * sw) / nrm
    # worst degree (row) relative error
    rown = np.linalg.norm(ref * sw, axis=1)
    ok = rown > 1e-3 * rown.max()
    rowe = np.linalg.norm((f32 - ref) * sw, axis=1)[ok] / rown[ok]
    return e32, emix, rowe.max()

