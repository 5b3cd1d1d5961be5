#!/usr/bin/env python3
"""The table of a measured choice (bench/gpu_pin.sh's OUTDIR; docs/performance.md, "A measured choice").

For each (rig, request, mesh) pinned: the pinned plan's time over the fastest plan's, and the search's own
choice's (the profile's plan) over the fastest, in the independent check run (check/, the N plans cheapest
under the profile, timed by the pin's clock). With --reference LOG...: the same ratios in calibrate logs of
the same rigs (a held-out collection: every plan of the pair, found by the pinned SPIR-V's hash).
Usage: python3 bench/pin_table.py OUTDIR [--reference LOG ...]
"""
import os
import re
import sys

CLOCK_COLUMN = {"raster on, timestamps": "raster on, timestamps",
                "raster on, host time (a CPU device)": "raster on, host",
                "raster off, process CPU time (a CPU device)": "raster off, process CPU"}


def pin_file(path):
    pin = {}
    for line in open(path):
        m = re.match(r'^(\w+): (.*)$', line)
        if m:
            pin[m.group(1)] = m.group(2).strip().strip('"')
    return pin


def passing_rows(path):
    """The rows of a bench log's program table that passed on the device, in its order (the objective's),
    each a dict from column name to cell."""
    header, rows = None, []
    for line in open(path):
        cells = [c.strip() for c in line.strip().strip('|').split('|')]
        if line.startswith('| program |'):
            header = cells
        elif header and line.startswith('| ') and len(cells) == len(header) and cells[1] == 'pass':
            rows.append(dict(zip(header, cells)))
        elif header and not line.startswith('|') and rows:
            break
    return rows


def bench_rows(path, clock):
    """label -> time by the clock's column, for rows that passed on the device."""
    rows = {}
    for row in passing_rows(path):
        v = row[CLOCK_COLUMN[clock]].split(' ')[0]
        if v != '—':
            rows[row['program']] = float(v)
    return rows


def reference(paths):
    """(rig, mesh) -> {program: measured ns} over calibrate logs' sample tables."""
    pairs = {}
    for path in paths:
        header = None
        for line in open(path):
            cells = [c.strip() for c in line.strip().strip('|').split('|')]
            if line.startswith('| mesh | rig | program |'):
                header = cells
            elif header and line.startswith('| ') and len(cells) == len(header) and not cells[0].startswith('---'):
                try:
                    t = float(cells[header.index('measured ns/vertex')])
                except ValueError:
                    continue
                if not cells[header.index('program')].startswith('plan:'):
                    continue  # the floors are not plans to pin or to beat
                prog = cells[header.index('SPIR-V SHA-256')]
                key = (cells[1], cells[0])
                pairs.setdefault(key, {})
                pairs[key][prog] = min(t, pairs[key].get(prog, t))
    return pairs


def main(argv):
    out = argv[1]
    refs = argv[argv.index('--reference') + 1:] if '--reference' in argv else []
    ref = reference(refs)
    lines = ["| pair | mesh | pinned | pinned / fastest | generated / fastest | plans timed | tune timed |"
             + (" reference: pinned / fastest |" if refs else ""),
             "|---|---|---|---:|---:|---:|---:|" + ("---:|" if refs else "")]
    stats = {"check": [], "generated": [], "ref": []}
    tuned = []  # validated plans each pin's tune timed (its `candidates:`; more than K where it widened)
    for name in sorted(os.listdir(os.path.join(out, 'pins'))):
        pin = pin_file(os.path.join(out, 'pins', name))
        pair, mesh = name[:-len('.pin.yaml')].rsplit('-', 1)
        check = os.path.join(out, 'check', f'{pair}-{mesh}.log')
        rows = bench_rows(check, pin['clock']) if os.path.exists(check) else {}
        cell = ["—", "—", "—"]
        if rows and pin['plan'] in rows and 'generated' in rows:
            fastest = min(rows.values())
            r, g = rows[pin['plan']] / fastest, rows['generated'] / fastest
            stats["check"].append(r)
            stats["generated"].append(g)
            cell = [f"{r:.3f}", f"{g:.3f}", str(len(rows))]
        tuned.append(int(pin.get('candidates', 0)))
        row = f"| {pair} | {mesh} | {pin['plan']} | " + " | ".join(cell) + f" | {tuned[-1]} |"
        if refs:
            rig = re.sub(r'^s\d+-', '', pair) + '.rig.yaml'
            progs = ref.get((rig, mesh), {})
            if progs and pin['program'] in progs:
                rr = progs[pin['program']] / min(progs.values())
                stats["ref"].append(rr)
                row += f" {rr:.3f} |"
            else:
                row += " — |"
        lines.append(row)
    print("\n".join(lines))
    print()
    if tuned:
        print(f"the tune timed {sum(tuned) / len(tuned):.2f} plans a pair on average, most {max(tuned)}")
    for key, what in (("check", "pinned / fastest (check run)"), ("generated", "generated / fastest (check run)"),
                      ("ref", "pinned / fastest (reference logs)")):
        v = stats[key]
        if v:
            print(f"{what}: {len(v)} pairs, within 5 %: {sum(x <= 1.05 for x in v)}, within 10 %: "
                  f"{sum(x <= 1.10 for x in v)}, worst {max(v):.3f}")


if __name__ == '__main__':
    main(sys.argv)
