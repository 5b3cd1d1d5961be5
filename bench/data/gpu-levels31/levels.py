#!/usr/bin/env python3
"""Session 31: what a held-out pair's level follows. Reads `calibrate --evaluate` output (its table's
"level (predicted / measured)" column) and the logs it checked, and prints, per mesh, the correlation of
log(level) with features of the pair: each term amount of its fastest plan, its joints per warp,
fragments per vertex, the fastest time, and the size of the request's fragment shader (instructions of
its optimised SPIR-V, from FRAGSIZES: lines "NAME COUNT") and the rig's deformers (DEFORMERS: lines
"NAME BONES INFLUENCES MORPH_TARGETS").
  Usage: levels.py EVALUATE.txt FRAGSIZES DEFORMERS LOG...
"""
import math, sys, collections

def cells(line):
    return [c.strip() for c in line.strip().strip('|').split('|')]

def levels(path):
    out, on = {}, False
    for line in open(path):
        if line.startswith('| rig | mesh |'): on = True; continue
        if on and line.startswith('| ') and not line.startswith('|---'):
            c = cells(line)
            out[(c[0], c[1])] = float(c[6])
    return out

def rows(path):
    cols = None
    for line in open(path):
        if not line.startswith('|'): continue
        c = cells(line)
        if c[:3] == ['mesh', 'rig', 'program']: cols = {k: i for i, k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or c[1] == '—' or 'floor' in c[2]: continue
        try: float(c[cols['measured ns/vertex']])
        except (ValueError, IndexError): continue  # a row that failed, or a note
        yield {k: c[i] for k, i in cols.items() if i < len(c)}

def corr(a, b):
    n = len(a); ma, mb = sum(a) / n, sum(b) / n
    sa = math.sqrt(sum((x - ma) ** 2 for x in a)); sb = math.sqrt(sum((y - mb) ** 2 for y in b))
    return float('nan') if sa == 0 or sb == 0 else sum((x - ma) * (y - mb) for x, y in zip(a, b)) / (sa * sb)

level = levels(sys.argv[1])
frag = dict(l.split() for l in open(sys.argv[2]))
deformers = {l.split()[0]: [float(x) for x in l.split()[1:]] for l in open(sys.argv[3])}
fastest = {}
for log in sys.argv[4:]:
    for r in rows(log):
        key = (r['rig'], r['mesh'])
        if key in level and (key not in fastest or float(r['measured ns/vertex']) < float(fastest[key]['measured ns/vertex'])):
            fastest[key] = r
terms = ['arithmetic', 'locations', 'attribute_bytes', 'buffer_bytes', 'buffer_loads', 'indexed_uniform_loads',
         'buffer_vec4_loads', 'indexed_uniform_vec4_loads', 'outputs', 'buffer_table_loads']
for mesh in sorted({m for _, m in fastest}):
    keys = [k for k in fastest if k[1] == mesh]
    y = [math.log(level[k]) for k in keys]
    feats = collections.OrderedDict()
    for t in terms: feats[t] = [float(fastest[k].get(t, 0) or 0) for k in keys]
    feats['joints per warp'] = [float(fastest[k]['joints per warp']) for k in keys]
    feats['fragments per vertex'] = [float(fastest[k].get('fragments per vertex', 'nan').replace('—', 'nan')) for k in keys]
    feats['fastest ns/vertex'] = [float(fastest[k]['measured ns/vertex']) for k in keys]
    feats['fragment shader instructions'] = [float(frag.get(k[0].replace('.rig.yaml', ''), 'nan')) for k in keys]
    for i, name in enumerate(['bones', 'influences', 'morph targets']):
        feats['the rig\'s ' + name] = [deformers.get(k[0].replace('.rig.yaml', ''), [math.nan] * 3)[i] for k in keys]
    spread = sorted(level[k] for k in keys)
    print(f"{mesh}: {len(keys)} pairs, level from {spread[0]:.3f} to {spread[-1]:.3f} (median {spread[len(spread) // 2]:.3f})")
    for name, x in feats.items():
        ok = [(a, b) for a, b in zip(x, y) if not math.isnan(a)]
        print(f"  log(level) against {name:30s} r = {corr([a for a, _ in ok], [b for _, b in ok]):+.2f}  ({len(ok)} pairs)")
# Is the level the rig's, whatever the mesh? The same rig's log(level) at Dawn scale against on the head.
both = [r for r, m in level if m == 'dawn' and (r, 'head') in level]
if both:
    print(f"a rig's log(level) at Dawn scale against on the head: r = "
          f"{corr([math.log(level[(r, 'dawn')]) for r in both], [math.log(level[(r, 'head')]) for r in both]):+.2f} ({len(both)} rigs)")
