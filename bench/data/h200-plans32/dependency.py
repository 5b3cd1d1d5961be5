#!/usr/bin/env python3
"""Session 32: within each pair of the H100 own-plan logs, the residual log(predicted / measured) of the profiles' own plans
less the pair's mean, by where a forced alternative reads the influences and the palette. Usage: dependency.py LOG..."""
import math, sys, collections, glob
def cells(l): return [c.strip() for c in l.strip().strip('|').split('|')]
def rows(path):
    cols=None
    for line in open(path):
        if not line.startswith('|'): continue
        c=cells(line)
        if c[:3]==['mesh','rig','program']: cols={k:i for i,k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or c[1]=='—' or 'plan under' not in c[2]: continue
        try: m=float(c[cols['measured ns/vertex']]); p=float(c[cols['predicted']])
        except: continue
        yield (path, c[1], c[0]), c[2], p, m
pairs=collections.defaultdict(list)
for log in sys.argv[1:]:
    for k,label,p,m in rows(log): pairs[k].append((label,p,m))
cls=collections.defaultdict(list)
for k,ps in pairs.items():
    mean=sum(math.log(p/m) for _,p,m in ps)/len(ps)
    for label,p,m in ps:
        r=math.log(p/m)-mean
        if 'buffered_influences_buffer_palette' in label: c='D: influences and palette from buffers'
        elif 'buffer_palette' in label: c='A: influences attributes, palette buffer'
        elif 'buffered_influences' in label: c='B: influences buffer, palette uniform'
        else: continue
        cls[(k[2],c)].append(r)
for (mesh,c),rs in sorted(cls.items()):
    rs.sort(); print(f"{mesh:5s} {c:45s} n={len(rs):3d} mean residual {sum(rs)/len(rs):+.3f} median {rs[len(rs)//2]:+.3f}  (negative: slower than predicted)")
