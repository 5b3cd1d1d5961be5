#!/usr/bin/env python3
"""augment.py against the tool's own counting: a log written since session 27 (with the table columns)
has its table reads folded back into the buffer loads, as a log written before counts them, is
rewritten by augment.py, and the inferred columns are compared row by row with the real ones.
Usage: check-augment.py LOG...   (prints one line per log, and every row that disagrees)"""
import os, subprocess, sys, tempfile
here = os.path.dirname(os.path.abspath(__file__))
COLS = ('buffer_loads', 'buffer_vec4_loads', 'buffer_table_loads', 'buffer_table_vec4_loads')


def table(path):
    rows, col, width = {}, None, 0
    for line in open(path):
        c = [x.strip() for x in line.split('|')]
        if len(c) > 5 and c[1] == 'mesh':
            col, width = {n: k for k, n in enumerate(c)}, len(c)
        elif col and len(c) == width and line.startswith('|') and not c[1].startswith('-'):
            rows[(c[1], c[2], c[3])] = tuple(c[col[n]] for n in COLS)
    return rows


def fold(src, dst):  # the table reads back into the buffer loads, the two columns dropped
    out, col, width = [], None, 0
    for line in open(src).read().split('\n'):
        c = [x.strip() for x in line.split('|')]
        if len(c) > 5 and c[1] == 'mesh':
            col, width = {n: k for k, n in enumerate(c)}, len(c)
            keep = [k for k, n in enumerate(c) if n not in COLS[2:]]
        elif col and len(c) == width and line.startswith('|'):
            if not c[1].startswith('-'):
                for a, b in ((COLS[0], COLS[2]), (COLS[1], COLS[3])):
                    c[col[a]] = str(int(c[col[a]]) + int(c[col[b]]))
        else:
            out.append(line)
            continue
        out.append('| ' + ' | '.join(c[k] for k in keep[1:-1]) + ' |')
    open(dst, 'w').write('\n'.join(out))


for log in sys.argv[1:]:
    with tempfile.TemporaryDirectory() as tmp:
        fold(log, f'{tmp}/old.log')
        subprocess.run([sys.executable, f'{here}/augment.py', f'{tmp}/old.log', f'{tmp}/new.log'], check=True,
                       stderr=subprocess.DEVNULL)
        real, inferred = table(log), table(f'{tmp}/new.log')
    bad = [k for k in real if real[k] != inferred.get(k)]
    print(f'{log}: {len(real)} rows, {sum(v[2] != "0" for v in real.values())} with table reads, {len(bad)} inferred otherwise')
    for k in bad:
        print('  ', k, 'real', real[k], 'inferred', inferred.get(k))
