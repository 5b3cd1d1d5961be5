#!/usr/bin/env python3
"""Session 32: the same programs (slot plans of one corpus seed, matched by rig, mesh, label and amounts) timed in
several logs: for each two logs, how far each (rig, mesh) moved as a whole (sd of its mean log ratio) and how far its
programs moved apart (within-pair sd). Usage: repeat.py LOG..."""
import collections, itertools, math, sys
from tables import log_rows, number, sd


def times(path):
    out = {}
    for r in log_rows(path):
        m = number(r, 'measured ns/vertex')
        if m is None or 'plan under' in r['program']: continue
        amounts = tuple(r[t] for t in ['arithmetic', 'locations', 'attribute_bytes', 'buffer_bytes', 'buffer_loads'] if t in r)
        key = (r['rig'], r['mesh'], r['program'], amounts)
        out[key] = min(m, out.get(key, m))
    return out


logs = {p: times(p) for p in sys.argv[1:]}
name = lambda p: [x for x in p.split('/') if x.startswith(('h100', 'h200'))][-1]
for a, b in itertools.combinations(sys.argv[1:], 2):
    by = collections.defaultdict(list)
    for k in logs[a]:
        if k in logs[b]: by[(k[0], k[1])].append(math.log(logs[b][k] / logs[a][k]))
    groups = [v for v in by.values() if len(v) >= 2]
    means = [sum(v) / len(v) for v in groups]
    within = [x - sum(v) / len(v) for v in groups for x in v]
    if len(means) < 3: continue
    print(f"{name(a):14s} vs {name(b):14s}: {len(means)} pairs, {len(within)} programs; per-pair mean log ratio: sd {sd(means):.3f} "
          f"(range {min(means):+.2f}..{max(means):+.2f}); within pair sd {math.sqrt(sum(x * x for x in within) / len(within)):.3f}")
