#!/usr/bin/env python3
"""Session 32: log(level) of each pair (`calibrate --evaluate` output) against its mesh's joints per warp, over the
pairs whose plans read 8 or more palette entries. Usage: jpwlevel.py EVALUATE.txt LOG..."""
import math, sys
from tables import corr, levels, log_rows, number, sd

J, S = {}, {}
for log in sys.argv[2:]:
    for r in log_rows(log):
        j = number(r, 'joints per warp')
        if j is None: continue
        key = (r['rig'], r['mesh'])
        J[key] = j
        palette = int(r['indexed_uniform_loads']) + int(r.get('buffer_table_loads', r['indexed_uniform_loads']))
        S[key] = max(S.get(key, 0), palette)
L = levels(sys.argv[1])
for mesh in ['head', 'dawn']:
    ks = [k for k in L if k[1] == mesh and k in J and S.get(k, 0) >= 8]
    if len(ks) < 3: continue
    y = [math.log(L[k]) for k in ks]
    print(f"{mesh}: {len(ks)} pairs with >= 8 palette loads: r(log level, jpw) = {corr([J[k] for k in ks], y):+.2f}, sd log level {sd(y):.3f}")
