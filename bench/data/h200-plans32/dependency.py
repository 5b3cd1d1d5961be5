#!/usr/bin/env python3
"""Session 32: within each pair of the H100 own-plan logs, the residual log(predicted / measured) of the profile's own
plans less the pair's mean, by where a forced alternative reads the influences and the palette. Usage: dependency.py LOG..."""
import collections, math, sys
from tables import log_rows, number

pairs = collections.defaultdict(list)
for log in sys.argv[1:]:
    for r in log_rows(log):
        p, m = number(r, 'predicted'), number(r, 'measured ns/vertex')
        if 'plan under' in r['program'] and p is not None and m is not None:
            pairs[(log, r['rig'], r['mesh'])].append((r['program'], p, m))
cls = collections.defaultdict(list)
for k, ps in pairs.items():
    mean = sum(math.log(p / m) for _, p, m in ps) / len(ps)
    for label, p, m in ps:
        if 'buffered_influences_buffer_palette' in label: c = 'D: influences and palette from buffers'
        elif 'buffer_palette' in label: c = 'A: influences attributes, palette buffer'
        elif 'buffered_influences' in label: c = 'B: influences buffer, palette uniform'
        else: continue
        cls[(k[2], c)].append(math.log(p / m) - mean)
for (mesh, c), rs in sorted(cls.items()):
    rs.sort()
    print(f"{mesh:5s} {c:45s} n={len(rs):3d} mean residual {sum(rs)/len(rs):+.3f} median {rs[len(rs)//2]:+.3f}  (negative: slower than predicted)")
