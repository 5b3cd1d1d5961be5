#!/usr/bin/env python3
"""Session 35: each pair whose chosen plan is over 5 % slower than its fastest, with both programs' driver statistics
(Register Count, Binary Size, Input Count) and predictions. Reads `calibrate --evaluate ... --per-plan` output and the
logs it checked, joined by the program's hash (h200-plans32/tables.py).
  Usage: misses.py PER_PLAN.txt LOG..."""
import collections, os, sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'h200-plans32'))
from tables import log_rows, number, plan_rows


def parse(text):
    out = {}
    for part in ([] if not text or text == '—' else text.split('; ')):
        name, _, value = part.rpartition('=')
        try: out[name] = float(value)
        except ValueError: pass
    return out

stats = {}
for log in sys.argv[2:]:
    for r in log_rows(log):
        s = parse(r.get('driver statistics', ''))
        if s: stats[(r['rig'], r['mesh'], r.get('SPIR-V SHA-256', '—'))] = s
pairs = collections.defaultdict(list)
for r in plan_rows(sys.argv[1]): pairs[(r['rig'], r['mesh'])].append(r)
print("| rig | mesh | chosen / fastest | predicted chosen / fastest ns | registers | binary bytes | input count |")
print("|---|---|---:|---:|---|---|---|")
for (rig, mesh), rows in pairs.items():
    tagged = lambda word: [r for r in rows if word in ' '.join(str(v) for v in r.values())]
    chosen, fastest = tagged('chosen'), tagged('fastest')
    if not chosen or not fastest: continue
    c, f = chosen[0], fastest[0]
    ratio = number(c, 'measured ns') / number(f, 'measured ns')
    if ratio <= 1.05: continue
    sc, sf = stats.get((rig, mesh, c['program']), {}), stats.get((rig, mesh, f['program']), {})
    both = lambda k: f"{sc.get(k, 0):.0f} / {sf.get(k, 0):.0f}"
    print(f"| {rig} | {mesh} | {ratio:.3f} | {number(c, 'predicted ns'):.2f} / {number(f, 'predicted ns'):.2f} | "
          f"{both('Register Count')} | {both('Binary Size')} | {both('Input Count')} |")
