#!/usr/bin/env python3
"""RobotExpressive's 19 parts on lavapipe, timed twice in one process (--one-process) and twice with
each part in a fresh process (the default): how far apart two runs of each kind are, and the kinds
from each other (README.md). Usage: python3 compare.py   (stdlib only)"""
import os, statistics, sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402


def times(name):
    return {(r['rig'], r['program']): float(r['measured ns/vertex']) for r in rows(os.path.join(here, name + '.log'))}


logs = {n: times(n) for n in ('one-A', 'one-B', 'fresh-A', 'fresh-B')}
for a, b in (('one-A', 'one-B'), ('fresh-A', 'fresh-B'), ('one-A', 'fresh-A'), ('one-B', 'fresh-B')):
    keys = sorted(set(logs[a]) & set(logs[b]))
    r = sorted(logs[a][k] / logs[b][k] for k in keys)
    print(f'{a} / {b}: {len(keys)} programs, median {statistics.median(r):.3f}, 5th-95th percentile '
          f'{r[len(r) // 20]:.3f}-{r[len(r) * 19 // 20]:.3f}, over 5 % apart: {sum(abs(x - 1) > 0.05 for x in r)}')
