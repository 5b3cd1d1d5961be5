#!/usr/bin/env python3
"""Session 32: do the driver's statistics of a compiled vertex stage (calibrate's "driver statistics"
column, VK_KHR_pipeline_executable_properties) follow what the profile's terms do not? Reads
`calibrate --evaluate` output (each pair's "level (predicted / measured)") and the logs it checked.
Prints the statistics' names and ranges, then for each numeric statistic:
  - across pairs: r of log(level) with the pair's mean of log(statistic) over its plans;
  - within pairs: r of each plan's residual, log(predicted / measured) less log(level), with its
    log(statistic) less the pair's mean (what a price per statistic could still explain of a choice).
  Usage: statistics.py EVALUATE.txt LOG...
"""
import math, sys, collections

def cells(line):
    return [c.strip() for c in line.strip().strip('|').split('|')]

def levels(path):
    out, on = {}, False
    for line in open(path):
        if line.startswith('| rig | mesh |'): on = True; continue
        if on and line.startswith('| ') and not line.startswith('|---'):
            c = cells(line)
            out[(c[0], c[1])] = float(c[6])
    return out

def rows(path):
    cols = None
    for line in open(path):
        if not line.startswith('|'): continue
        c = cells(line)
        if c[:3] == ['mesh', 'rig', 'program']: cols = {k: i for i, k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or c[1] == '—' or 'floor' in c[2]: continue
        try: float(c[cols['measured ns/vertex']]); float(c[cols['predicted']])
        except (ValueError, IndexError, KeyError): continue
        yield {k: c[i] for k, i in cols.items() if i < len(c)}

def parse(stats):
    out = {}
    if not stats or stats == '—': return out
    for part in stats.split('; '):
        name, _, value = part.rpartition('=')
        try: out[name] = float(value)
        except ValueError: pass
    return out

def corr(a, b):
    n = len(a)
    if n < 3: return float('nan')
    ma, mb = sum(a) / n, sum(b) / n
    sa = math.sqrt(sum((x - ma) ** 2 for x in a)); sb = math.sqrt(sum((y - mb) ** 2 for y in b))
    return float('nan') if sa == 0 or sb == 0 else sum((x - ma) * (y - mb) for x, y in zip(a, b)) / (sa * sb)

level = levels(sys.argv[1])
plans = collections.defaultdict(dict)  # (rig, mesh) -> program -> (predicted, best measured, statistics)
for log in sys.argv[2:]:
    for r in rows(log):
        key = (r['rig'], r['mesh'])
        if key not in level: continue
        prog = r.get('SPIR-V SHA-256') or r['program']
        st = parse(r.get('driver statistics', ''))
        pred, meas = float(r['predicted']), float(r['measured ns/vertex'])
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
