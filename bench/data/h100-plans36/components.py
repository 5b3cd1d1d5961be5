#!/usr/bin/env python3
"""Experiment: keeps the rows that carry the driver's statistics, and with MODE=components puts the
driver's Input Count (the vertex input components the compiled program reads) in the attribute_bytes
column, so a fit prices input components instead of bytes. Usage: components.py MODE IN OUT"""
import sys, re
mode, src, dst = sys.argv[1:4]
out = []; hdr = None
for line in open(src).read().split('\n'):
    c = line.split('|'); s = [x.strip() for x in c]
    if len(s) > 5 and s[1] == 'mesh' and s[3] == 'program':
        hdr = {n: k for k, n in enumerate(s)}; ncol = len(s)
    elif hdr and len(s) == ncol and s[1] not in ('', '---') and not s[1].startswith('-'):
        m = re.search(r'Input Count=(\d+)', line)
        if not m: continue
        if mode == 'components': c[hdr['attribute_bytes']] = ' %s ' % m.group(1); line = '|'.join(c)
    out.append(line)
open(dst, 'w').write('\n'.join(out))
