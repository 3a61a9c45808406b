import numpy as np, sys
sys.path.insert(0, '/tmp/f32exp')
from rec_lib import run
for B in [256, 512]:
    for m in [16, 32, 48, 64, 96, 128]:
        row = []
        for mp in [0, m // 2, m - 1, m]:
            ref, w = run(m, mp, B, np.float64); f, _ = run(m, mp, B, np.float32)
            sw = np.sqrt(w); row.append(f"{mp}:{np.linalg.norm((f - ref) * sw) / np.linalg.norm(ref * sw):.1e}")
        print(f"B={B} m={m} " + " ".join(row)); sys.stdout.flush()
