import numpy as np, sys
sys.path.insert(0, '/tmp/f32exp')
from rec_lib import run
for B in [256, 1024]:
    num = den = 0.0
    for m in [0, 1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 768]:
        if m >= B: continue
        ref, w = run(m, 0, B, np.float64); f, _ = run(m, 0, B, np.float32)
        sw = np.sqrt(w); e = np.linalg.norm((f - ref) * sw) / np.linalg.norm(ref * sw)
        print(f"S2-like m'=0 B={B} m={m} relL2={e:.2e}"); sys.stdout.flush()
