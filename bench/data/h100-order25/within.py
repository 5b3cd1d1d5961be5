#!/usr/bin/env python3
"""Call 3 (scripts/d25.sh, logs in call3/): the new default (each rig in a fresh process) against
one process per part run by hand (call 1) and against one process for the whole group (calls 1-2);
then, with --one-process, a part timed 6 times in one process, after K other parts, and the whole
model in reverse order. Usage: python3 within.py   (stdlib only)"""
import glob, os, statistics, sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402
d = os.path.join(here, 'call3')


def times(paths):  # (mesh, rig, program) -> ns per vertex; a repeated key keeps its first
    out = {}
    for p in paths:
        for r in rows(p):
            out.setdefault((r['mesh'], r['rig'], r['program']), float(r['measured ns/vertex']))
    return out


def compare(name, a, b):
    keys = sorted(set(a) & set(b))
    if not keys:
        return
    r = sorted(a[k] / b[k] for k in keys)
    over = sum(abs(x - 1) > 0.05 for x in r)
    print(f'{name}: {len(keys)} programs, ratio median {statistics.median(r):.3f}, range {r[0]:.3f}-{r[-1]:.3f}, over 5 % apart: {over}')


def log(*parts):
    p = os.path.join(*parts)
    return [p] if os.path.exists(p) else []


alone = times(sorted(glob.glob(os.path.join(here, 'call1', 'order', 'parts-BrainStem', '*.log'))))
whole = times(log(here, 'call1', 'order', 'all-BrainStem.log'))
fresh = times(log(d, 'fresh-BrainStem.log'))
compare('BrainStem, fresh process per part (default) / one process per part by hand', fresh, alone)
compare('BrainStem, fresh process per part (default) / whole model in one process', fresh, whole)
compare('world, fresh process per rig / one process (call 1)', times(log(d, 'world.log')), times(log(here, 'call1', 's2', 'world.log')))
compare('seed 7, fresh process per rig / one process (call 2)', times(log(d, 's7.log')), times(log(here, 'call2', 's7', 'corpus-heldout.log')))
compare('BrainStem reversed / forwards, both one process', times(log(d, 'reversed.log')), whole)
compare('BrainStem reversed (one process) / one process per part', times(log(d, 'reversed.log')), alone)


def occurrences(path):  # rig -> [[ns of each program] per occurrence, in timing order]
    out, seen = {}, {}
    for r in rows(path):
        key = (r['rig'], r['program'])
        n = seen.get(key, 0)
        seen[key] = n + 1
        occ = out.setdefault(r['rig'], [])
        while len(occ) <= n:
            occ.append([])
        occ[n].append(float(r['measured ns/vertex']))
    return out


for name in ['rep-45', 'rep-33'] + [f'filler-{k}' for k in range(4)]:
    for p in log(d, name + '.log'):
        for rig, occ in occurrences(p).items():
            if name.startswith('filler') and not rig.endswith('#45/0'):
                continue
            for i, v in enumerate(occ):
                print(f'{name:9} {rig:22} #{i + 1}: ' + ' '.join(f'{x:6.2f}' for x in v))
