#!/usr/bin/env python3
"""Which state carries a part's times over from the parts timed before it (README.md)? For each model
timed by order-next.sh: each part's uniform-palette over storage-buffer-palette time (U/B, as
h200-fresh23/order-h100/order.py) and each program's time, in the whole-model runs (mapped, staged,
mapped without the shader cache) against one process per part (mapped, nothing timed before it).
Usage: python3 order.py [DIR=order]   (stdlib only)"""
import glob, math, os, sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402

d = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, 'order')


def times(paths):  # (rig, program) -> measured ns/vertex
    out = {}
    for p in paths:
        for r in rows(p):
            out[(r['rig'], r['program'])] = (float(r['measured ns/vertex']), r)
    return out


def ub(t):  # rig -> fastest uniform-palette plan / fastest storage-buffer-palette plan
    by = {}
    for (rig, prog), (ns, r) in t.items():
        if prog.startswith('plan:'):
            by.setdefault(rig, []).append((ns, r))
    out = {}
    for rig, plans in by.items():
        u = [ns for ns, r in plans if float(r['indexed_uniform_loads']) > 0 and float(r['buffer_loads']) == 0]
        b = [ns for ns, r in plans if float(r['indexed_uniform_loads']) == 0 and float(r['buffer_loads']) > 0]
        if u and b:
            out[rig] = min(u) / min(b)
    return out


def pearson(x, y):
    mx, my = sum(x) / len(x), sum(y) / len(y)
    sx = math.sqrt(sum((a - mx) ** 2 for a in x)); sy = math.sqrt(sum((b - my) ** 2 for b in y))
    return sum((a - mx) * (b - my) for a, b in zip(x, y)) / (sx * sy) if sx and sy else float('nan')


for alone in sorted(glob.glob(os.path.join(d, 'parts-*'))):
    model = os.path.basename(alone)[len('parts-'):]
    ref = times(sorted(glob.glob(os.path.join(alone, '*.log'))))
    refub = ub(ref)
    print(f'{model}: {len({k[0] for k in ref})} parts timed alone, {len(ref)} programs')
    base = times([os.path.join(d, f'all-{model}.log')])
    for run in ('staged', 'nocache'):
        t = times([os.path.join(d, f'{run}-{model}.log')])
        r = sorted(t[k][0] / base[k][0] for k in set(t) & set(base))
        print(f'  {run:8} against all (both whole-model runs): {len(r)} programs, time ratio {r[0]:.3f}-{r[-1]:.3f}')
    for run in ('all', 'staged', 'nocache'):
        p = os.path.join(d, f'{run}-{model}.log')
        if not os.path.exists(p):
            continue
        t = times([p]); tub = ub(t)
        keys = sorted(set(t) & set(ref))
        ratios = sorted(t[k][0] / ref[k][0] for k in keys)
        parts = sorted(set(tub) & set(refub))
        worst = max(parts, key=lambda q: abs(tub[q] - refub[q])) if parts else None
        print(f'  {run:8} against alone: {len(keys)} programs, time ratio median {ratios[len(ratios) // 2]:.3f}, '
              f'range {ratios[0]:.3f}-{ratios[-1]:.3f}; U/B over {len(parts)} parts: Pearson '
              f'{pearson([tub[q] for q in parts], [refub[q] for q in parts]):.3f}'
              + (f', largest difference {abs(tub[worst] - refub[worst]):.3f} ({worst}: {tub[worst]:.3f} against {refub[worst]:.3f})' if worst else ''))
