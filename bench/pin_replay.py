#!/usr/bin/env python3
"""Replays bench's widening rule (measure/gpu_bench.h rankCandidates) over check runs (gpu_pin.sh's
OUTDIR/check: the N cheapest plans of each pair, timed): for each pair, the K cheapest are "timed"; where the
objective puts them --spread or more apart and the check shows under --shown of that spread, the pick is the
fastest of the --max cheapest instead. Prints how many pairs widen, the plans timed a pair and the picks'
time over the fastest of all N. The check's table gives each plan's best round, not the median rounds bench
weighs, and the same timing both picks and judges: an estimate of the rule, not a held-out test.
Usage: python3 bench/pin_replay.py CHECKDIR... [--k 4] [--max 12] [--spread 0.05] [--shown 0.1]
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pin_table import CLOCK_COLUMN, passing_rows  # noqa: E402


def plans(path):
    """[(predicted, measured)] in the table's order (the objective's), rows that passed and were timed; the time
    by the first prediction clock (pin_table.CLOCK_COLUMN) the row has a figure for: raster-on timestamps on a
    GPU, the process's CPU time with raster off on lavapipe."""
    out = []
    for row in passing_rows(path):
        times = [row[c].split(' ')[0] for c in CLOCK_COLUMN.values() if c in row]
        t = next((float(v) for v in times if v != '—'), None)
        if t is not None:
            out.append((float(row['predicted']), t))
    return out


def main(argv):
    opt = {'--k': 4, '--max': 12, '--spread': 0.05, '--shown': 0.1}
    dirs = []
    i = 1
    while i < len(argv):
        if argv[i] in opt:
            opt[argv[i]] = type(opt[argv[i]])(argv[i + 1])
            i += 2
        else:
            dirs.append(argv[i])
            i += 1
    for d in dirs:
        picks, timed, widened = [], [], 0
        for name in sorted(os.listdir(d)):
            rows = plans(os.path.join(d, name))
            if not rows:
                continue
            k = min(opt['--k'], len(rows))
            first = rows[:k]
            spread = lambda i: max(r[i] for r in first) / min(r[i] for r in first) - 1
            if k == opt['--k'] and len(rows) > k and min(r[0] for r in first) > 0 and spread(0) >= opt['--spread'] \
                    and spread(1) < opt['--shown'] * spread(0):
                k = min(opt['--max'], len(rows))
                widened += 1
            timed.append(k)
            picks.append(min(r[1] for r in rows[:k]) / min(r[1] for r in rows))
        print(f"{d}: {len(picks)} pairs, widened {widened}, {sum(timed) / len(timed):.2f} plans timed a pair; "
              f"pick / fastest within 5 %: {sum(p <= 1.05 for p in picks)}, worst {max(picks):.3f}")


if __name__ == '__main__':
    main(sys.argv)
