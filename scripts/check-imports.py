#!/usr/bin/env python3
"""Fail if two source files of the library import each other, directly or through a loop.

A file imports another when one of its `use` paths (crate::, super::, self::, a child's
name) or a `crate::` path in its code names a module or an item defined in that file. `mod` declarations are not imports.
"""
import os, re, sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")

def module_of(path):
    rel = os.path.relpath(path, ROOT)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib"):
        rel = rel[:-1]
    return tuple(rel)

files = {}
for d, _, fs in os.walk(ROOT):
    if os.path.relpath(d, ROOT).startswith("bin"):
        continue
    for f in fs:
        if f.endswith(".rs"):
            p = os.path.join(d, f)
            files[module_of(p)] = p

def strip_tests(text):
    # Ignore `#[cfg(test)] mod tests { ... }` blocks: a test module may use its parent.
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(pub(\([a-z]+\))?\s+)?mod\s+\w+\s*\{", text):
        if m.start() < i:
            continue
        out.append(text[i:m.start()])
        depth, j = 1, m.end()
        while depth and j < len(text):
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    out.append(text[i:])
    return "".join(out)

def use_paths(text, public=None):
    pat = r"^\s*(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);"
    for m in re.finditer(pat, text, re.M):
        if public is not None and bool(m.group(1)) != public:
            continue
        body = re.sub(r"\s+", "", m.group(2))
        yield from expand(body)

def expand(body):
    i = body.find("{")
    if i < 0:
        yield body.split("as")[0] if "::" in body else body
        return
    prefix, inner = body[:i], body[i + 1 : body.rfind("}")]
    depth, cur, parts = 0, "", []
    for c in inner:
        if c == "," and depth == 0:
            parts.append(cur); cur = ""
            continue
        depth += (c == "{") - (c == "}")
        cur += c
    parts.append(cur)
    for p in parts:
        if p:
            yield from expand(prefix + p)

def reexports(mod):
    """Names a module re-exports with `pub use`, and the path each comes from."""
    if mod not in _reexp:
        table = {}
        text = strip_tests(open(files[mod]).read())
        for u in use_paths(text, public=True):
            parts = re.split(r"as", u) if False else [u]
            name = u.split("::")[-1]
            if name != "*":
                table[name] = u
        _reexp[mod] = table
    return _reexp[mod]
_reexp = {}

def resolve(me, path, depth=0):
    segs = [s for s in path.split("::") if s]
    if not segs:
        return None
    if segs[0] == "crate":
        base, segs = (), segs[1:]
    elif segs[0] in ("super", "self"):
        base = me
        is_dir = files.get(me, "").endswith(("mod.rs", "lib.rs"))
        while segs and segs[0] in ("super", "self"):
            if segs[0] == "super":
                base = base[:-1]
            segs = segs[1:]
        if not is_dir and path.startswith("self"):
            base = me
    elif (me + (segs[0],)) in files:
        base = me
    else:
        return None
    mod, k = base, 0
    while k < len(segs) and mod + (segs[k],) in files:
        mod, k = mod + (segs[k],), k + 1
    # An item the module only re-exports comes from the file that defines it.
    if k < len(segs) and depth < 8 and segs[k] in reexports(mod):
        target = resolve(mod, reexports(mod)[segs[k]], depth + 1)
        if target is not None:
            return target
    return mod

edges = {}
for mod, p in files.items():
    text = re.sub(r"//[^\n]*", "", strip_tests(open(p).read()))
    inline = re.findall(r"\bcrate(?:::[A-Za-z_][A-Za-z0-9_]*)+", text)
    # A module's `pub use` of its own descendants is its public face, not a dependency.
    own_face = set()
    for u in use_paths(text, public=True):
        t = resolve(mod, u)
        if t is not None and len(t) > len(mod) and t[: len(mod)] == mod:
            own_face.add(u)
    for u in [u for u in use_paths(text) if u not in own_face] + inline:
        t = resolve(mod, u)
        if t is not None and t != mod and t in files:
            # A parent re-exporting or naming its own child is the module tree, not a loop
            # back; a child importing its parent's items is an edge like any other.
            edges.setdefault(mod, set()).add(t)

# Find cycles (Tarjan).
index, low, stack, on, sccs, n = {}, {}, [], set(), [], [0]
def strong(v):
    index[v] = low[v] = n[0]; n[0] += 1; stack.append(v); on.add(v)
    for w in edges.get(v, ()):
        if w not in index:
            strong(w); low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        comp = []
        while True:
            w = stack.pop(); on.discard(w); comp.append(w)
            if w == v:
                break
        if len(comp) > 1:
            sccs.append(comp)
sys.setrecursionlimit(10000)
for v in list(files):
    if v not in index:
        strong(v)
name = lambda m: os.path.relpath(files[m], os.path.join(ROOT, ".."))
if sccs:
    for c in sccs:
        print("import loop:", " <-> ".join(sorted(name(m) for m in c)))
    sys.exit(1)
print(f"no import loops among {len(files)} library source files")
