#!/usr/bin/env python3
"""same-plans.py LOG... (session 30): for each (rig, mesh) of collect.sh's logs, whether the profiles given to
--plans-under chose the same plan (the same term amounts), each one's time, its best time, and the fastest
program of the log. A log times each program in blocks, one process each (the instruction-slot plan and its
alternatives, then each profile's), and on this machine a block can run 20-60 % slower than another for every
program in it: where two profiles chose the same plan, the difference of their times is that drift. "best" is
the least time of any row of the log with the plan's term amounts (the same program, timed in another block,
unless two programs share every amount); the worst chosen / fastest per profile is printed both ways."""
import re
import sys
from collections import defaultdict

AMOUNTS = ["arithmetic", "locations", "attribute_bytes", "buffer_bytes", "buffer_loads", "indexed_uniform_loads",
           "buffer_vec4_loads", "indexed_uniform_vec4_loads", "buffer_table_loads", "buffer_table_vec4_loads"]


def rows(path):
    header = None
    for line in open(path):
        if line.startswith("| mesh |"):
            header = [c.strip() for c in line.strip().strip("|").split("|")]
        elif header and line.startswith("| ") and not line.startswith("|---"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) == len(header):
                yield dict(zip(header, cells))


own = re.compile(r"^plan under ([^@]+)@[0-9a-f]+: generated$")
pairs = defaultdict(dict)  # (rig, mesh) -> profile -> (amounts, ns)
fastest = {}
best_of = {}  # (rig, mesh, amounts) -> least ns of any row
for path in sys.argv[1:]:
    for r in rows(path):
        if not r["program"].startswith("plan"):
            continue
        key = (r["rig"].replace(".rig.yaml", ""), r["mesh"])
        ns = float(r["measured ns/vertex"])
        fastest[key] = min(fastest.get(key, ns), ns)
        amounts = tuple(r.get(a, "0") for a in AMOUNTS)
        best_of[key + (amounts,)] = min(best_of.get(key + (amounts,), ns), ns)
        m = own.match(r["program"])
        if m:
            pairs[key][m.group(1)] = (amounts, ns)

profiles = sorted({p for v in pairs.values() for p in v})
print("| rig | mesh | same plan | " + " | ".join(f"{p}: ns / fastest, best / fastest" for p in profiles) + " | fastest |")
print("|---|---|---|" + "---:|" * (len(profiles) + 1))
worst = {p: [(0.0, None), (0.0, None)] for p in profiles}
for key in sorted(pairs):
    got = pairs[key]
    same = len({a for a, _ in got.values()}) == 1 and len(got) == len(profiles)
    cells = []
    for p in profiles:
        if p not in got:
            cells.append("-")
            continue
        amounts, ns = got[p]
        best = best_of[key + (amounts,)]
        cells.append(f"{ns:.2f} ({ns / fastest[key]:.3f}), {best:.2f} ({best / fastest[key]:.3f})")
        for i, r in enumerate((ns / fastest[key], best / fastest[key])):
            if r > worst[p][i][0]:
                worst[p][i] = (r, key)
    print(f"| {key[0]} | {key[1]} | {'yes' if same else 'no'} | " + " | ".join(cells) + f" | {fastest[key]:.2f} |")
print()
for p in profiles:
    (w, k), (b, kb) = worst[p]
    print(f"{p}: worst chosen / fastest {w:.3f} ({k[0]} on {k[1]}); at the plan's best time {b:.3f} ({kb[0]} on {kb[1]})")
