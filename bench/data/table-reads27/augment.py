#!/usr/bin/env python3
"""Counts a log's table reads apart (buffer_table_loads, buffer_table_vec4_loads) for logs written
before those columns existed. A program of a skinned pair that loads no uniform element at a
per-vertex index reads its palette from a storage buffer; its table loads are the uniform-palette
plans' loads of the same pair (the same entries, from the other place). Probes 'buffer palette loads N'
read N entries. Usage: augment.py IN OUT"""
import sys, collections
src, dst = sys.argv[1:3]
lines = open(src).read().split('\n')
hdr = None
rows = []
for i, line in enumerate(lines):
    c = [x.strip() for x in line.split('|')]
    if len(c) > 5 and c[1] == 'mesh' and c[3] == 'program':
        hdr = c
        continue
    if hdr and len(c) == len(hdr) and c[1] not in ('', '---') and not c[1].startswith('-'):
        rows.append(i)
col = {n: k for k, n in enumerate(hdr)}
assert 'buffer_table_loads' not in col
pal = collections.defaultdict(collections.Counter)
cells = {}
for i in rows:
    c = [x.strip() for x in lines[i].split('|')]
    cells[i] = c
    try:
        iu, iv = int(c[col['indexed_uniform_loads']]), int(c[col['indexed_uniform_vec4_loads']])
    except ValueError:
        continue
    if iu > 0 and c[2] not in ('—', ''):
        pal[(c[1], c[2])][(iu, iv)] += 1
moved = unknown = 0
out = list(lines)
for i in rows:
    c = cells[i]
    tl = tv = 0
    bl, bv = int(c[col['buffer_loads']]), int(c[col['buffer_vec4_loads']])
    iu = int(c[col['indexed_uniform_loads']])
    if c[3].startswith('buffer palette loads '):
        n = int(c[3].split()[3])
        tl, tv = n, 4 * n
    elif c[2] not in ('—', '') and 'floor' not in c[3] and iu == 0 and bl > 0:
        if pal[(c[1], c[2])]:
            (k, kv), _ = pal[(c[1], c[2])].most_common(1)[0]
            if bl >= k and bv >= kv:
                tl, tv = k, kv
        elif 'buffer_palette' in c[3]:
            unknown += 1
    if tl:
        moved += 1
        c[col['buffer_loads']] = str(bl - tl)
        c[col['buffer_vec4_loads']] = str(bv - tv)
    out[i] = '| ' + ' | '.join(c[1:-1]) + f' | {tl} | {tv} |'
for i, line in enumerate(lines):
    c = [x.strip() for x in line.split('|')]
    if len(c) > 5 and c[1] == 'mesh' and c[3] == 'program':
        out[i] = line.rstrip() + ' buffer_table_loads | buffer_table_vec4_loads |'
    elif len(c) > 5 and set(c[1]) <= set('-:') and c[1] and i > 0 and 'mesh' in lines[i - 1]:
        out[i] = line.rstrip() + '---:|---:|'
open(dst, 'w').write('\n'.join(out))
print(f'{src}: {len(rows)} rows, {moved} with table reads counted apart, {unknown} buffer-palette rows with no uniform sibling', file=sys.stderr)
