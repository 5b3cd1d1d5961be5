#!/usr/bin/env python3
"""Session 32: the same programs (slot plans of one corpus seed, matched by rig, mesh, label and amounts) timed in
several logs: for each two logs, how far each (rig, mesh) moved as a whole (sd of its mean log ratio) and how far its
programs moved apart (within-pair sd). Usage: repeat.py LOG..."""
import math, sys, collections, itertools, statistics as st
def cells(l): return [c.strip() for c in l.strip().strip('|').split('|')]
def rows(path):
    cols=None; out={}
    for line in open(path):
        if not line.startswith('|'): continue
        c=cells(line)
        if c[:3]==['mesh','rig','program']: cols={k:i for i,k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or c[1]=='—' or 'plan under' in c[2]: continue
        try: m=float(c[cols['measured ns/vertex']])
        except: continue
        amounts=tuple(c[cols[t]] for t in ['arithmetic','locations','attribute_bytes','buffer_bytes','buffer_loads'] if t in cols)
        key=(c[1],c[0],c[2],amounts)
        out[key]=min(m,out.get(key,1e9))
    return out
logs={p:rows(p) for p in sys.argv[1:]}
name=lambda p: [x for x in p.split('/') if x.startswith(('h100','h200'))][-1]
for a,b in itertools.combinations(sys.argv[1:],2):
    A,B=logs[a],logs[b]
    common=[k for k in A if k in B]
    by=collections.defaultdict(list)
    for k in common: by[(k[0],k[1])].append(math.log(B[k]/A[k]))
    means=[st.mean(v) for v in by.values() if len(v)>=2]
    within=[x-st.mean(v) for v in by.values() if len(v)>=2 for x in v]
    if len(means)<3: continue
    print(f"{name(a):14s} vs {name(b):14s}: {len(means)} pairs, {len(within)} programs; per-pair mean log ratio: sd {st.pstdev(means):.3f} (range {min(means):+.2f}..{max(means):+.2f}); within pair sd {math.sqrt(sum(x*x for x in within)/len(within)):.3f}")
