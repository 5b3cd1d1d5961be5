#!/usr/bin/env python3
"""Session 27: programs a log timed twice for one (rig, mesh), once among the instruction-slot plan's
alternatives ('plan: ...') and again among the profile's plan's ('plan under NAME: ...'), the same term
amounts and the same label after 'plan: ' / 'plan under NAME: ' (both the generated plan, or both one forced
rule): one program. Prints the ratio of the second timing to the first, how well one process repeats a
program timed a few seconds later; with --twins, programs of the same amounts but other labels instead
(two programs the model's terms cannot tell apart, or one program reached two ways).
Usage: python3 repeat.py LOG..."""
import statistics, sys
ratios = []
twins = '--twins' in sys.argv
for log in [a for a in sys.argv[1:] if a != '--twins']:
    first = {}
    for line in open(log):
        c = [x.strip() for x in line.split('|')]
        if len(c) < 17 or not c[3].startswith('plan'):
            continue
        try:
            t = float(c[15])
        except ValueError:
            continue
        key = (c[1], c[2], tuple(c[4:13]))
        if c[3].startswith('plan: '):
            first.setdefault(key, (c[3], t))
        elif key in first and (first[key][0].split(': ', 1)[1] != c[3].split(': ', 1)[1]) == twins:
            ratios.append((t / first[key][1], log, c[1], c[2], first[key][0], c[3]))
ratios.sort()
for r, log, mesh, rig, a, b in ratios:
    if abs(r - 1) > 0.03:
        print(f'{r:.3f} {log} {mesh} {rig}: {a} / {b}')
rs = [r[0] for r in ratios]
for mesh in ('dawn', 'head', 'own'):
    m = [r[0] for r in ratios if r[2] == mesh]
    if m:
        print(f'{mesh}: {len(m)} programs timed twice, second / first median {statistics.median(m):.3f}, '
              f'range {min(m):.3f}-{max(m):.3f}, {sum(abs(x - 1) > 0.03 for x in m)} over 3 % apart')
