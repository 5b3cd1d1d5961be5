#!/usr/bin/env python3
"""Session 27: each held-out pair's own plan under a profile, timed (calibrate --plans-under), against the
fastest program its log timed. The plan a user gets is the row 'plan under NAME: generated'; the offline
check's 'chosen' is the least predicted of the timed programs, which ties when one program was timed twice.
Usage: python3 own.py [NAME=nvidia-h200-raster] LOG...   (no device)"""
import sys, statistics
name = sys.argv[1] if not sys.argv[1].endswith('.log') else 'nvidia-h200-raster'
logs = [a for a in sys.argv[1:] if a.endswith('.log')]
rows = {}
for log in logs:
    for line in open(log):
        c = [x.strip() for x in line.split('|')]
        if len(c) < 17:
            continue
        try:
            t = float(c[15])  # measured ns per vertex
        except ValueError:
            continue
        if c[3].startswith('floor'):
            continue
        rows.setdefault((log, c[2], c[1]), []).append((c[3], t))
ratios = []
for (log, rig, mesh), progs in sorted(rows.items()):
    own = [t for p, t in progs if p == f'plan under {name}: generated']
    if not own:
        continue
    best = min(t for p, t in progs)
    fastest = min(progs, key=lambda x: x[1])[0]
    r = own[0] / best
    ratios.append(r)
    flag = ' <-- over 5 %' if r > 1.05 else ''
    print(f'{log.split("/")[0]}/{rig} {mesh}: {len(progs)} programs, own plan {own[0]:.4f} ns, fastest {best:.4f} ns ({fastest}): {r:.3f}{flag}')
over = [r for r in ratios if r > 1.05]
print(f'{len(ratios)} pairs with the plan under {name} timed: {len(over)} over 5 %, worst {max(ratios):.3f}, median {statistics.median(ratios):.3f}')
