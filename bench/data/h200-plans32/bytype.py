#!/usr/bin/env python3
"""Session 32: each own plan's log(predicted / measured) against joints per warp, by where it reads the palette (8 or
more uniform loads at a per-vertex index, or storage-buffer table loads). Usage: bytype.py LOG..."""
import collections, math, sys
from tables import corr, log_rows, number

data = collections.defaultdict(list)
for log in sys.argv[1:]:
    for r in log_rows(log):
        p, m, j = number(r, 'predicted'), number(r, 'measured ns/vertex'), number(r, 'joints per warp')
        if 'plan under' not in r['program'] or None in (p, m, j): continue
        kind = ('uniform palette' if int(r['indexed_uniform_loads']) >= 8 else
                'table palette' if int(r['buffer_table_loads']) >= 8 else 'no/small palette')
        data[(r['mesh'], kind)].append((j, math.log(p / m)))
for (mesh, kind), v in sorted(data.items()):
    if len(v) < 3: continue
    x = [a for a, _ in v]; y = [b for _, b in v]
    # the slope of log(predicted / measured) on log(joints per warp)
    lx = [math.log(max(a, 0.5)) for a in x]; mx = sum(lx) / len(lx); my = sum(y) / len(y)
    slope = sum((a - mx) * (b - my) for a, b in zip(lx, y)) / sum((a - mx) ** 2 for a in lx)
    print(f"{mesh:5s} {kind:17s} n={len(v):3d} r(log(pred/meas), jpw)={corr(x, y):+.2f} slope on log jpw {slope:+.2f}; mean log(pred/meas) {my:+.3f}")
