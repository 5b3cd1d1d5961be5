#!/usr/bin/env python3
"""Rewrites a log's buffer_bytes to count only per-vertex streams: the table (palette) bytes,
16 per buffer_table_vec4_loads, taken out (an experiment: palette entries are shared by the
vertices of a warp, so they are not streamed per vertex). Usage: stream_bytes.py IN OUT"""
import sys
src, dst = sys.argv[1:3]
out = []
hdr = None
for line in open(src).read().split('\n'):
    c = line.split('|')
    s = [x.strip() for x in c]
    if len(s) > 5 and s[1] == 'mesh' and s[3] == 'program':
        hdr = {n: k for k, n in enumerate(s)}; ncol = len(s)
    elif hdr and len(s) == ncol and s[1] not in ('', '---') and not s[1].startswith('-'):
        try:
            b = int(s[hdr['buffer_bytes']]); t = int(s[hdr['buffer_table_vec4_loads']])
            assert b >= 16 * t, (line, b, t)
            c[hdr['buffer_bytes']] = ' %d ' % (b - 16 * t)
            line = '|'.join(c)
        except ValueError:
            pass
    out.append(line)
open(dst, 'w').write('\n'.join(out))
