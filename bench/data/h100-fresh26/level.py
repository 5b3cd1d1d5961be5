#!/usr/bin/env python3
"""How much of a profile's RMS error is each (rig, mesh) pair's own level: every plan of the pair off
by one common factor, which moves no choice. Prints the median RMS relative error over the pairs, the
same after each pair's mean log error is divided out, and the median of that factor.

It prices a plan as a raster profile does (docs/device-profiles.md: the additive weights plus the
slowest pipe, terms scaled by the sample's joints per warp or fragments per vertex). Profiles with draw
sizes, draw weights or a constant cache are refused. On the logs of README.md its median RMS equals
`calibrate --evaluate`'s (14.4 %, 13.7 %, 13.3 %).
Usage: python3 level.py PROFILE.yaml LOG...   (needs PyYAML)"""
import math, os, statistics, sys

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402

TERMS = ('arithmetic locations attribute_bytes buffer_bytes buffer_loads indexed_uniform_loads buffer_vec4_loads '
         'indexed_uniform_vec4_loads outputs vertices fragments').split()
FEATURE_COLUMN = {'joints_per_warp': 'joints per warp', 'fragments_per_vertex': 'fragments per vertex'}

prof = yaml.safe_load(open(sys.argv[1]))
for key in ('draw_sizes', 'draw_weights', 'constant_cache_entries'):
    if key in prof:
        sys.exit(f'{sys.argv[1]}: has {key}, which this script does not price')
scaled = prof.get('scaled_by', {})


def predict(r):
    x = {t: float(r[t]) * (float(r[FEATURE_COLUMN[scaled[t]]]) if t in scaled else 1.0) for t in TERMS}
    pipes = [sum(w * x[t] for t, w in p.items()) for p in prof.get('pipes', {}).values()]
    return sum(prof['weights'].get(t, 0) * x[t] for t in TERMS) + (max(pipes) if pipes else 0)


pairs = {}
for log in sys.argv[2:]:
    for r in rows(log):
        if r['program'].startswith('plan:'):
            amounts = tuple(r[t] for t in TERMS)
            pairs.setdefault((log, r['rig'], r['mesh']), {}).setdefault(amounts, (predict(r), float(r['measured ns/vertex'])))
rms, rest, level = [], [], []
for plans in pairs.values():
    logs = [math.log(p / m) for p, m in plans.values()]
    mean = sum(logs) / len(logs)
    rms.append(math.sqrt(sum((math.exp(e) - 1) ** 2 for e in logs) / len(logs)))
    rest.append(math.sqrt(sum((math.exp(e - mean) - 1) ** 2 for e in logs) / len(logs)))
    level.append(abs(math.exp(mean) - 1))
print(f'{len(pairs)} (rig, mesh) pairs: median RMS relative error {100 * statistics.median(rms):.1f} %; '
      f'with each pair\'s own level divided out {100 * statistics.median(rest):.1f} %; '
      f'that level, median |factor - 1| {100 * statistics.median(level):.1f} %')
