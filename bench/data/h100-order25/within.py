#!/usr/bin/env python3
"""Call 3 (scripts/d25.sh): a part's times each time one process times it again (rep-P.log, mix.log),
after K other parts (filler-K.log), and in the whole model reversed (reversed.log) against forwards
(call1/order/all-BrainStem.log) and alone (call1/order/parts-BrainStem/). Usage: python3 within.py"""
import glob, os, sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402
d = os.path.join(here, 'call3')


def occurrences(path):  # rig -> [[ns of each program] per occurrence, in timing order]
    out, seen = {}, {}
    for r in rows(path):
        key = (r['rig'], r['program'])
        n = seen.get(key, 0); seen[key] = n + 1
        occ = out.setdefault(r['rig'], [])
        while len(occ) <= n:
            occ.append([])
        occ[n].append(float(r['measured ns/vertex']))
    return out


def fmt(v):
    return ' '.join(f'{x:6.2f}' for x in v)


for name in ['rep-45', 'rep-33', 'rep-39', 'mix'] + [f'filler-{k}' for k in range(7)]:
    p = os.path.join(d, name + '.log')
    if not os.path.exists(p):
        continue
    for rig, occ in occurrences(p).items():
        if name.startswith('filler') and not rig.endswith('#45/0'):
            continue
        for i, v in enumerate(occ):
            print(f'{name:9} {rig:22} #{i + 1}: {fmt(v)}')


def single(path):
    return {(r['rig'], r['program']): float(r['measured ns/vertex']) for r in rows(path)}


rev = os.path.join(d, 'reversed.log')
if os.path.exists(rev):
    fw = single(os.path.join(here, 'call1', 'order', 'all-BrainStem.log'))
    alone = {}
    for p in glob.glob(os.path.join(here, 'call1', 'order', 'parts-BrainStem', '*.log')):
        alone.update(single(p))
    rv = single(rev)
    keys = sorted(set(rv) & set(fw) & set(alone))
    def off(a):
        return sum(abs(a[k] / alone[k] - 1) > 0.05 for k in keys)
    same = sum(abs(rv[k] / fw[k] - 1) <= 0.01 for k in keys)
    print(f'reversed: {len(keys)} programs; within 1 % of forwards: {same}; over 5 % from alone: forwards {off(fw)}, reversed {off(rv)}')
