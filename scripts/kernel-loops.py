#!/usr/bin/env python3
"""Loops with FMAs in a binary's functions and their stack references: finds sums that
LLVM spilled in the DWT kernels (a vector stack reference inside a hot loop is a load, a
store, or both, in a chain that should stay in registers).

Usage: scripts/kernel-loops.py BINARY SYMBOL_PART [--show]
  e.g. scripts/kernel-loops.py target/release/so3fft-bench inv_avx2_16
Every function whose mangled name contains SYMBOL_PART is disassembled (objdump, Intel
syntax); each backward jump spanning at least 4 FMAs is printed with its instruction
count, FMA count and vector (ymm/zmm) stack references; --show prints the loop bodies.
A stack reference in a loop is harmless when it is a loaded operand only (a loop
invariant read from memory); two of them to one slot (a reload and a store) are a spill.
"""
import re
import subprocess
import sys


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        sys.exit(2)
    binary, part = sys.argv[1], sys.argv[2]
    show = "--show" in sys.argv[3:]
    symbols = subprocess.run(["nm", "-S", binary], capture_output=True, text=True).stdout
    found = False
    for line in symbols.splitlines():
        fields = line.split()
        if len(fields) != 4 or part not in fields[3]:
            continue
        found = True
        start, size = int(fields[0], 16), int(fields[1], 16)
        dump = subprocess.run(
            ["objdump", "-d", "--no-show-raw-insn", "-M", "intel", binary,
             "--start-address=%#x" % start, "--stop-address=%#x" % (start + size)],
            capture_output=True, text=True).stdout
        insns = []
        for l in dump.splitlines():
            m = re.match(r"\s+([0-9a-f]+):\s+(.*)", l)
            if m:
                insns.append((int(m.group(1), 16), m.group(2)))
        at = {a: i for i, (a, _) in enumerate(insns)}
        print("==", fields[3], "at %#x, %d bytes" % (start, size))
        for i, (a, text) in enumerate(insns):
            m = re.match(r"j\w+\s+([0-9a-f]+)", text)
            if not m:
                continue
            target = int(m.group(1), 16)
            if target > a or target not in at:
                continue
            body = insns[at[target]:i + 1]
            fmas = sum(bool(re.match(r"vfn?m(add|sub)", t)) for _, t in body)
            if fmas < 4:
                continue
            stack = sum(("rsp" in t or "rbp" in t) and ("ymm" in t or "zmm" in t)
                        for _, t in body)
            print("loop %#x-%#x: %d instructions, %d FMAs, %d vector stack references"
                  % (target, a, len(body), fmas, stack))
            if show:
                for _, t in body:
                    print("   ", t)
    if not found:
        print("no symbol containing", part)
        sys.exit(1)


if __name__ == "__main__":
    main()
