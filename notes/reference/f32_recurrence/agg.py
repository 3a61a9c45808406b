import numpy as np, sys
sys.path.insert(0, '/tmp/f32exp')
from rec_lib import run
B = int(sys.argv[1])
# small orders in detail
for m in [0, 1, 2, 4, 8, 16, 32]:
    for mp in sorted({0, m // 2, m}):
        ref, w = run(m, mp, B, np.float64); f, _ = run(m, mp, B, np.float32)
        sw = np.sqrt(w); e = np.linalg.norm((f - ref) * sw) / np.linalg.norm(ref * sw)
        print(f"B={B} m={m} m'={mp} relL2={e:.2e}")
# transform-wide aggregate: clusters sampled on a grid, weighted by degrees x members
step = max(B // 16, 1)
num = den = num_big = den_big = 0.0
for m in range(0, B, step):
    for mp in range(0, m + 1, step):
        ref, w = run(m, mp, B, np.float64); f, _ = run(m, mp, B, np.float32)
        sw = np.sqrt(w)
        # each row (degree) normalised: coefficients of unit size per degree
        rn = np.linalg.norm(ref * sw, axis=1); ok = rn > 0
        rel2 = (np.linalg.norm((f - ref) * sw, axis=1)[ok] / rn[ok]) ** 2
        members = 1 if m == 0 else (4 if mp in (0, m) else 8)
        # weight: this sample stands for step x step clusters (step for the diagonal)
        cnt = step * (step if mp < m else 1) if m > 0 else 1
        num += members * cnt * rel2.sum(); den += members * cnt * ok.sum()
        if m >= B // 16:
            num_big += members * cnt * rel2.sum(); den_big += members * cnt * ok.sum()
print(f"B={B} aggregate rel L2 of d (all clusters) = {np.sqrt(num/den):.2e}; clusters m >= B/16 only: {np.sqrt(num_big/den_big):.2e}")
