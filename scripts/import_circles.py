#!/usr/bin/env python3
"""Import circles among the files of a crate.

Usage: python3 scripts/import_circles.py crates/jobs/src [crates/prssm/src ...]

Each `.rs` file is a module (`mod.rs` / `lib.rs` the folder's). Every `crate::a::b…` and
`super::…` path outside comments and the `#[cfg(test)] mod tests` block, including the items
of `use …::{x, y}` groups, is resolved to the file that defines the longest prefix of it; an
edge from a module to one of its own descendants (a parent declaring or re-exporting its
children) is not counted. A circle is a strongly connected component of more than one file.
Prints, per crate, the files, edges and circles; exits 1 when there is a circle.
"""
import os
import re
import sys
from collections import defaultdict


def modules(src):
    mods = {}
    for root, _, files in os.walk(src):
        for f in files:
            if f.endswith('.rs'):
                rel = os.path.relpath(os.path.join(root, f), src)[:-3].split(os.sep)
                if rel[-1] in ('mod', 'lib'):
                    rel = rel[:-1]
                mods[tuple(rel)] = os.path.join(root, f)
    return mods


def resolve(path, mods):
    for k in range(len(path), -1, -1):
        if tuple(path[:k]) in mods:
            return tuple(path[:k])
    return None


def edges(mods):
    graph = defaultdict(set)
    for m, p in mods.items():
        text = open(p, encoding='utf-8').read()
        text = '\n'.join(l for l in text.split('\n') if not l.lstrip().startswith('//'))
        text = re.sub(r'#\[cfg\(test\)\]\s*mod tests\s*\{.*', '', text, flags=re.S)
        base = list(m) if os.path.basename(p) in ('mod.rs', 'lib.rs') else list(m[:-1])

        def add(head, rest):
            path = rest if head == 'crate' else base[:-1] + rest
            t = resolve(path, mods)
            if t is not None and t != m and t[:len(m)] != m:
                graph[m].add(t)

        for mt in re.finditer(r'\b(crate|super)((?:::\w+)+)', text):
            add(mt.group(1), mt.group(2).split('::')[1:])
        for mt in re.finditer(r'\b(crate|super)((?:::\w+)*)::\{([^}]*)\}', text):
            rest = [x for x in mt.group(2).split('::') if x]
            for item in mt.group(3).split(','):
                item = item.strip().split('::')[0].split(' ')[0]
                if item and item != 'self':
                    add(mt.group(1), rest + [item])
    return graph


def circles(nodes, graph):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(comp)

    for v in nodes:
        if v not in index:
            visit(v)
    return out


found = False
for src in sys.argv[1:]:
    mods = modules(src)
    graph = edges(mods)
    bad = circles(sorted(mods), graph)
    found |= bool(bad)
    print(f"{src}: {len(mods)} files, {sum(len(v) for v in graph.values())} edges, {len(bad)} circles")
    for c in bad:
        print('   ', ' <-> '.join('::'.join(x) or 'lib' for x in sorted(c)))
sys.exit(1 if found else 0)
