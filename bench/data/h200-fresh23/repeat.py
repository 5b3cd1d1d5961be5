#!/usr/bin/env python3
"""The same held-out groups timed twice on the H200 (sessions 18-19, and this collection): how far
one program's time moves between collections, and whether a pair's chosen / fastest does.
Usage: python3 repeat.py OLD_EVALUATION NEW_EVALUATION OLD_LOG:NEW_LOG ...
(the evaluations are `calibrate --evaluate` outputs over those logs, in the same order)."""
import math, sys

from logtable import rows


def pairs(path):  # (rig, mesh) -> chosen / fastest, from an evaluation's table
    out = {}
    for line in open(path):
        c = [x.strip() for x in line.strip().strip('|').split('|')]
        if line.startswith('| ') and len(c) == 6 and c[0] != 'rig':
            out.setdefault((c[0].split(' (')[0], c[1]), []).append(float(c[4].split()[0]))
    return out

old_eval, new_eval = pairs(sys.argv[1]), pairs(sys.argv[2])
moves = []
for spec in sys.argv[3:]:
    old, new = spec.split(':')
    t = {(r['mesh'], r['rig'], r['program']): float(r['measured ns/vertex']) for r in rows(old)}
    for r in rows(new):
        k = (r['mesh'], r['rig'], r['program'])
        if k in t and r['program'].startswith('plan:'):
            moves.append(abs(math.log(float(r['measured ns/vertex']) / t[k])))
moves.sort()
q = lambda p: math.exp(moves[min(len(moves) - 1, int(p * len(moves)))]) - 1
print(f'{len(moves)} plans timed in both: |change| median {100 * q(0.5):.1f} %, 90th percentile {100 * q(0.9):.1f} %, max {100 * q(1.0):.1f} %')
print('| rig | mesh | chosen / fastest, then | now |')
print('|---|---|---:|---:|')
for k in sorted(set(old_eval) & set(new_eval)):
    a, b = old_eval[k], new_eval[k]
    if max(a + b) > 1.03:
        print(f'| {k[0]} | {k[1]} | {" ".join("%.3f" % x for x in a)} | {" ".join("%.3f" % x for x in b)} |')
