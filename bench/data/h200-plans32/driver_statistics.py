#!/usr/bin/env python3
"""Session 32 (session 33: every plan's prediction): do the driver's statistics of a compiled vertex stage
(calibrate's "driver statistics" column, VK_KHR_pipeline_executable_properties) follow what the profile's
terms do not? Reads `calibrate --evaluate PROFILE --check-log LOG... --per-plan` output (each plan's
predicted / measured and that over its pair's level) and the logs it checked, joined by the program's hash.
Prints the statistics' names and ranges, then for each numeric statistic:
  - across pairs: r of log(level) with the pair's mean of log(statistic) over its plans;
  - within pairs: r of each plan's log(predicted / measured / level) with its log(statistic) less the pair's
    mean (what a price per statistic could still explain of a choice).
  Usage: driver_statistics.py PER_PLAN.txt LOG...
"""
import collections, math, sys
from tables import corr, log_rows, number, plan_rows


def parse(stats):
    out = {}
    if not stats or stats == '—': return out
    for part in stats.split('; '):
        name, _, value = part.rpartition('=')
        try: out[name] = float(value)
        except ValueError: pass
    return out

statistics = {}  # (rig, mesh, program) -> {name: value}
for log in sys.argv[2:]:
    for r in log_rows(log):
        st = parse(r.get('driver statistics', ''))
        if st: statistics[(r['rig'], r['mesh'], r.get('SPIR-V SHA-256', '—'))] = st
plans = collections.defaultdict(list)  # (rig, mesh) -> [(log(predicted / measured), over the level, statistics)]
for r in plan_rows(sys.argv[1]):
    ratio, over = number(r, 'predicted / measured'), number(r, 'over the level')
    st = statistics.get((r['rig'], r['mesh'], r['program']))
    if ratio and over and st: plans[(r['rig'], r['mesh'])].append((ratio / over, over, st))
names = collections.OrderedDict()
for ps in plans.values():
    for _, _, st in ps:
        for n, v in st.items(): names.setdefault(n, []).append(v)
if not names:
    print("no driver statistics for these plans"); sys.exit(0)
print(f"{len(plans)} pairs, {sum(len(p) for p in plans.values())} plans with statistics; the driver's statistics:")
for n, vs in names.items():
    print(f"  {n}: {len(vs)} plans, {min(vs):g} to {max(vs):g}, {len(set(vs))} distinct values")
for mesh in sorted({m for _, m in plans}):
    keys = [k for k in plans if k[1] == mesh]
    print(f"{mesh}: {len(keys)} pairs")
    for n in names:
        x, y, wx, wy = [], [], [], []
        for k in keys:
            vals = [(level, over, st[n]) for level, over, st in plans[k] if n in st and st[n] > 0]
            if not vals: continue
            mean = sum(math.log(v) for _, _, v in vals) / len(vals)
            x.append(mean); y.append(math.log(vals[0][0]))
            for _, over, v in vals:
                wx.append(math.log(v) - mean); wy.append(math.log(over))
        print(f"  {n:30s} across pairs: log(level) r = {corr(x, y):+.2f} ({len(x)} pairs); "
              f"within pairs: residual r = {corr(wx, wy):+.2f} ({len(wx)} plans)")
