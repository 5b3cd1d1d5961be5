#!/usr/bin/env python3
"""A part's times depend on the parts one calibrate run timed before it (README.md): BrainStem#33/0's
plans timed first (early.log), last of 34 (late.log) and in the whole model (all.log), and each
part's uniform-palette over storage-buffer-palette time (U/B) in two whole-model runs on the H100
and one on the H200. Usage: python3 order.py   (stdlib only)"""
import math, os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
from logtable import rows  # noqa: E402
here = os.path.dirname(os.path.abspath(__file__))


def num(r, k):
    return float(r[k])

for name in ('early', 'late', 'all'):
    print(f'{name}.log, BrainStem.glb#33/0:')
    for r in rows(os.path.join(here, name + '.log')):
        if r['rig'] == 'BrainStem.glb#33/0':
            print(f"  {r['program'][:70]:70} {num(r, 'measured ns/vertex'):8.4f}")

def ub(path):  # part -> fastest uniform-palette plan / fastest storage-buffer-palette plan
    by = {}
    for r in rows(path):
        if r['program'].startswith('plan:'):
            by.setdefault(r['rig'], []).append(r)
    out = {}
    for part, plans in by.items():
        u = [num(r, 'measured ns/vertex') for r in plans if num(r, 'indexed_uniform_loads') > 0 and num(r, 'buffer_loads') == 0]
        b = [num(r, 'measured ns/vertex') for r in plans if num(r, 'indexed_uniform_loads') == 0 and num(r, 'buffer_loads') > 0]
        if u and b:
            out[part] = min(u) / min(b)
    return out

def pearson(x, y):
    mx, my = sum(x) / len(x), sum(y) / len(y)
    return sum((a - mx) * (b - my) for a, b in zip(x, y)) / math.sqrt(sum((a - mx) ** 2 for a in x) * sum((b - my) ** 2 for b in y))

h100a = ub(os.path.join(here, 'whole-model-run1', 'BrainStem.log'))
h100b = ub(os.path.join(here, 'all.log'))
h200 = ub(os.path.join(here, '..', 'public-models', 'BrainStem.log'))
parts = sorted(set(h100a) & set(h100b) & set(h200))
print(f'U/B over {len(parts)} parts: H100 run 1 against run 2: Pearson {pearson([h100a[p] for p in parts], [h100b[p] for p in parts]):.4f}, '
      f'largest difference {max(abs(h100a[p] - h100b[p]) for p in parts):.3f}; H100 against H200: Pearson '
      f'{pearson([h100b[p] for p in parts], [h200[p] for p in parts]):.3f}')
