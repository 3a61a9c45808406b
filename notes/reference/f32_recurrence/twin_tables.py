# Tables of rust-twin.md from the CSV the Rust study prints:
#   cargo test --release --lib f32_accuracy -- --ignored --nocapture | grep -E '^[0-9B]' > twin.csv
#   python3 twin_tables.py twin.csv
import csv, sys

rows = list(csv.DictReader(open(sys.argv[1])))
for r in rows:
    for k in r:
        r[k] = float(r[k])
BS = sorted({int(r['B']) for r in rows})


def mband(m):
    m = int(m)
    if m <= 2:
        return str(m)
    if m <= 4:
        return "3-4"
    if m <= 8:
        return "5-8"
    lo = 8
    while m > 2 * lo:
        lo *= 2
    return f"{lo + 1}-{2 * lo}"


def dband(d):
    return "0" if d == 0 else "1-2" if d <= 2 else "3-8" if d <= 8 else "9-32" if d <= 32 else ">32"


def band_table(key):
    ds = ["0", "1-2", "3-8", "9-32", ">32"]
    for B in BS:
        R = [r for r in rows if r['B'] == B]
        bands = []
        for r in R:
            if mband(r['m']) not in bands:
                bands.append(mband(r['m']))
        print(f"\nB = {B}, `{key}` (largest over the sampled clusters of each cell)\n")
        print("| m \\ m-m' | " + " | ".join(ds) + " |")
        print("|---|" + "---|" * len(ds))
        for b in bands:
            cells = []
            for d in ds:
                v = [r[key] for r in R if mband(r['m']) == b and dband(r['m'] - r['mp']) == d]
                cells.append(f"{max(v):.1e}" if v else "")
            print(f"| {b} | " + " | ".join(cells) + " |")


def summary():
    print("| B | clusters | m >= B/16, m-m' > 32: median / max | m <= 2 | m = m', m >= 16 | f64 rounded to f32 |")
    print("|---|---|---|---|---|---|")
    for B in BS:
        R = [r for r in rows if r['B'] == B]
        far = sorted(r['single_weighted'] for r in R if r['m'] >= B / 16 and r['m'] - r['mp'] > 32)
        low = max(r['single_weighted'] for r in R if r['m'] <= 2)
        low_l2 = max(r['single_l2'] for r in R if r['m'] <= 2)
        diag = max(r['single_weighted'] for r in R if r['m'] == r['mp'] and r['m'] >= 16)
        rounded = max(r['rounded_l2'] for r in R)
        print(f"| {B} | {len(R)} | {far[len(far) // 2]:.1e} / {far[-1]:.1e} | {low:.1e} (unweighted {low_l2:.1e}) "
              f"| {diag:.1e} | {rounded:.1e} |")


def frac(B, f):
    tot = fb = 0
    for m in range(B):
        for mp in range(m + 1):
            tot += B - m
            if f(B, m, mp):
                fb += B - m
    return fb / tot


RULES = {
    "single, no fallback": ('single', lambda B, m, mp: False),
    "single, A: B<=128: m<2; B>=256: m<17 or (m=m', m<B/2)":
        ('single', lambda B, m, mp: m < 2 if B <= 128 else (m < 17 or (m == mp and m < B / 2))),
    "single, B: B<=128: m<2; B>=256: m<16 or (m-m'<=4, m<B/2)":
        ('single', lambda B, m, mp: m < 2 if B <= 128 else (m < 16 or (m - mp <= 4 and m < B / 2))),
    "delta form, no fallback": ('delta', lambda B, m, mp: False),
    "delta form, B>=256: m-m'<=2, m<B/2":
        ('delta', lambda B, m, mp: False if B <= 128 else (m - mp <= 2 and m < B / 2)),
}


def rules():
    print("| recurrence, f64 fallback for | " + " | ".join(f"B = {B}" for B in BS) + " |")
    print("|---|" + "---|" * len(BS))
    for name, (v, f) in RULES.items():
        cells = []
        for B in BS:
            R = [r for r in rows if r['B'] == B and not f(B, int(r['m']), int(r['mp']))]
            cells.append(f"{max(r[v + '_weighted'] for r in R):.1e} / "
                         f"{max(r[v + '_roundtrip'] for r in R):.1e} ({100 * frac(B, f):.1f}%)")
        print(f"| {name} | " + " | ".join(cells) + " |")


summary()
print()
rules()
for key in ['single_weighted', 'single_l2', 'single_roundtrip', 'delta_weighted', 'delta_roundtrip']:
    band_table(key)
