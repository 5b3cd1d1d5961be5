#!/usr/bin/env python3
"""Session 32: do the driver's statistics of a compiled vertex stage (calibrate's "driver statistics"
column, VK_KHR_pipeline_executable_properties) follow what the profile's terms do not? Reads
`calibrate --evaluate` output (each pair's "level (predicted / measured)") and the logs it checked.
Prints the statistics' names and ranges, then for each numeric statistic:
  - across pairs: r of log(level) with the pair's mean of log(statistic) over its plans;
  - within pairs: r of each plan's residual, log(predicted / measured) less log(level), with its
    log(statistic) less the pair's mean (what a price per statistic could still explain of a choice).
  Usage: driver_statistics.py EVALUATE.txt LOG...
"""
import collections, math, sys
from tables import corr, levels, log_rows, number


def parse(stats):
    out = {}
    if not stats or stats == '—': return out
    for part in stats.split('; '):
        name, _, value = part.rpartition('=')
        try: out[name] = float(value)
        except ValueError: pass
    return out

level = levels(sys.argv[1])
plans = collections.defaultdict(dict)  # (rig, mesh) -> program -> (predicted, best measured, statistics)
for log in sys.argv[2:]:
    for r in log_rows(log):
        key = (r['rig'], r['mesh'])
        pred, meas = number(r, 'predicted'), number(r, 'measured ns/vertex')
        if key not in level or 'floor' in r['program'] or pred is None or meas is None: continue
        prog = r.get('SPIR-V SHA-256') or r['program']
        st = parse(r.get('driver statistics', ''))
        if prog in plans[key] and plans[key][prog][1] <= meas: continue
        plans[key][prog] = (pred, meas, st)
names = collections.OrderedDict()
for key, ps in plans.items():
    for pred, meas, st in ps.values():
        for n, v in st.items(): names.setdefault(n, []).append(v)
if not names:
    print("no driver statistics in these logs"); sys.exit(0)
total = sum(len(p) for p in plans.values())
print(f"{len(plans)} pairs, {total} programs with a prediction; the driver's statistics:")
for n, vs in names.items():
    print(f"  {n}: {len(vs)} programs, {min(vs):g} to {max(vs):g}, {len(set(vs))} distinct values")
for mesh in sorted({m for _, m in plans}):
    keys = [k for k in plans if k[1] == mesh]
    print(f"{mesh}: {len(keys)} pairs")
    for n in names:
        x, y, wx, wy = [], [], [], []
        for k in keys:
            vals = [(p, m, st[n]) for p, m, st in plans[k].values() if n in st and st[n] > 0]
            if not vals: continue
            mean = sum(math.log(v) for _, _, v in vals) / len(vals)
            x.append(mean); y.append(math.log(level[k]))
            for p, m, v in vals:
                wx.append(math.log(v) - mean); wy.append(math.log(p / m) - math.log(level[k]))
        print(f"  {n:30s} across pairs: log(level) r = {corr(x, y):+.2f} ({len(x)} pairs); "
              f"within pairs: residual r = {corr(wx, wy):+.2f} ({len(wx)} plans)")
