import numpy as np, math, sys
sys.path.insert(0, '/tmp/f32exp')
from rec_lib import coeffs, log_start
f32, f64 = np.float32, np.float64
def run(m, mp, B, variant):
    n = B - m
    k = np.arange(2 * B); beta = np.pi * (2 * k + 1) / (4 * B); beta = beta[beta < np.pi / 2]
    tau = 2 * np.sin(beta / 2) ** 2
    A, C, Bc = coeffs(m, mp, n)
    S = np.ones(n + 1)
    for i in range(1, n): S[i + 1] = Bc[i] * S[i - 1]
    Ap = A * S[:n] / S[1:n + 1]; ApC = (A + C) * S[:n] / S[1:n + 1]
    ls = log_start(m, mp, beta); E = np.floor(ls / math.log(2))
    dt = f64 if variant == 'f64' else f32
    p1 = np.exp(ls - E * math.log(2)).astype(dt); p0 = np.zeros_like(p1)
    tau32 = tau.astype(f32).astype(f64)
    out = np.zeros((n, beta.size))
    for i in range(n):
        out[i] = p1.astype(f64) * 2.0 ** E * S[i]
        if variant == 'f64':
            t = -Ap[i] * tau + ApC[i]
        elif variant == 'V1':   # f32 coefficients, f32 tau, t rounded
            t = (f64(f32(-Ap[i])) * tau32 + f64(f32(ApC[i]))).astype(f32).astype(f64)
        elif variant == 'V2':   # exact (hi+lo) coefficients, f32 tau, t rounded once
            t = (-Ap[i] * tau32 + ApC[i]).astype(f32).astype(f64)
        elif variant == 'V2b':  # hi+lo coefficients, t kept as unrounded sum of two f32 FMAs (3-op step)
            ahi = f64(f32(-Ap[i])); alo = f64(f32(-Ap[i] - ahi)); bhi = f64(f32(ApC[i])); blo = f64(f32(ApC[i] - bhi))
            thi = (ahi * tau32 + bhi).astype(f32).astype(f64); tlo = (alo * tau32 + blo).astype(f32).astype(f64)
            p2 = (thi * p1.astype(f64) + (tlo * p1.astype(f64) - p0.astype(f64)).astype(f32).astype(f64)).astype(dt)
            t = None
        elif variant == 'V3':   # t exact, only the state rounded
            t = -Ap[i] * tau + ApC[i]
        if t is not None:
            p2 = (t * p1.astype(f64) - p0.astype(f64)).astype(dt)
        p0, p1 = p1, p2
        big = np.abs(p1) > 2.0 ** 40
        if big.any():
            p0 = np.where(big, p0 * dt(2.0 ** -60), p0).astype(dt); p1 = np.where(big, p1 * dt(2.0 ** -60), p1).astype(dt); E = np.where(big, E + 60, E)
    return out, np.sin(beta)
for B, m, mp in [(512, 0, 0), (512, 1, 0), (512, 64, 32), (512, 32, 32), (1024, 0, 0), (1024, 256, 0)]:
    ref, w = run(m, mp, B, 'f64'); sw = np.sqrt(w); nr = np.linalg.norm(ref * sw)
    res = []
    for v in ['V1', 'V2', 'V2b', 'V3']:
        o, _ = run(m, mp, B, v); res.append(f"{v}={np.linalg.norm((o - ref) * sw) / nr:.1e}")
    print(f"B={B} m={m} m'={mp}: " + " ".join(res)); sys.stdout.flush()
