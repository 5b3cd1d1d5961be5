#!/usr/bin/env python3
"""Session 26 (README.md): program by program, the groups timed with each rig in a fresh process
(the default since session 25) against the same groups timed with many rigs in one process
(session 25's H100 logs, ../h100-order25), and against themselves timed again (call 4; call 5 on another machine).
Only plans count (probes and floors are not rigs' programs). Usage: python3 compare.py   (stdlib only)"""
import os, statistics, sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402
old = os.path.join(here, '..', 'h100-order25')


def times(path):  # (mesh, rig, program) -> ns per vertex, plans only
    return {(r['mesh'], r['rig'], r['program']): float(r['measured ns/vertex'])
            for r in rows(path) if r['program'].startswith('plan:')}


def compare(name, a, b):
    keys = sorted(set(a) & set(b))
    if not keys:
        return []
    r = sorted(a[k] / b[k] for k in keys)
    far = [(a[k] / b[k], k) for k in keys if abs(a[k] / b[k] - 1) > 0.05]
    print(f'| {name} | {len(keys)} | {statistics.median(r):.3f} | {r[0]:.3f}-{r[-1]:.3f} | {len(far)} |')
    return far


print('| fresh processes (this session) against | programs | ratio median | range | over 5 % apart |')
print('|---|---:|---:|---:|---:|')
far = []
for g, o in [('world', 'call1/s2'), ('pbr', 'call1/s2'), ('body-depth', 'call1/s2'), ('models', 'call1/s2'),
             ('models-fox', 'call1/s2'), ('unseen', 'call2/s2'), ('unseen-formats', 'call2/s2'),
             ('unseen-models', 'call2/s2'), ('train', 'call2/s2')]:
    new = os.path.join(here, 'call2/s2/train.log' if g == 'train' else f'call1/s2/{g}.log')
    far += compare(f'{g}: one process (session 25)', times(new), times(os.path.join(old, o, f'{g}.log')))
far += compare('corpus seed 7: one process (session 25)', times(os.path.join(here, 'call3/s7/corpus-heldout.log')),
               times(os.path.join(old, 'call2/s7/corpus-heldout.log')))
for g in ['world', 'pbr', 'body-depth', 'models', 'models-fox', 'unseen-formats', 'unseen-models']:
    compare(f'{g}: fresh processes again (call 4)', times(os.path.join(here, f'call4/s2/{g}.log')),
            times(os.path.join(here, f'call1/s2/{g}.log')))
compare('unseen: fresh processes again, another machine (call 5)', times(os.path.join(here, 'call5/s2/unseen.log')),
        times(os.path.join(here, 'call1/s2/unseen.log')))
print('\nover 5 % apart, fresh against one process:')
for x, k in sorted(far):
    print(f'  {x:.3f}  {k[1]} | {k[0]} | {k[2]}')
