#!/usr/bin/env python3
"""Session 32: the floors' error log(predicted / measured) against their pair's level (`calibrate --evaluate`
output): the floors share the pair's request, fragment shader, mesh and process. Usage: floorlevel.py EVALUATE.txt LOG..."""
import collections, math, sys
from tables import corr, levels, log_rows, number, sd

L = levels(sys.argv[1])
F = collections.defaultdict(dict)
for log in sys.argv[2:]:
    for r in log_rows(log):
        p, m = number(r, 'predicted'), number(r, 'measured ns/vertex')
        if 'floor' in r['program'] and p is not None and m is not None:
            F[(r['rig'], r['mesh'])][r['program']] = math.log(p / m)
for mesh in ['dawn', 'head']:
    for fl in ['floor (pass-through)', 'floor + every input fetched']:
        ks = [k for k in L if k[1] == mesh and fl in F.get(k, {})]
        x = [F[k][fl] for k in ks]; y = [math.log(L[k]) for k in ks]
        print(f"{mesh} {fl:28s} {len(ks)} pairs: r(log level, floor's log(pred/meas)) = {corr(x, y):+.2f}; sd level {sd(y):.3f}, sd floor {sd(x):.3f}")
