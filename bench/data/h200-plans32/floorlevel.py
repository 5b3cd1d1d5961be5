import math, sys, collections
def cells(l): return [c.strip() for c in l.strip().strip('|').split('|')]
def levels(path):
    out, on = {}, False
    for line in open(path):
        if line.startswith('| rig | mesh |'): on = True; continue
        if on and line.startswith('| ') and not line.startswith('|---'):
            c = cells(line); out[(c[0], c[1])] = float(c[6])
    return out
def floors(path):
    cols=None; out=collections.defaultdict(dict)
    for line in open(path):
        if not line.startswith('|'): continue
        c=cells(line)
        if c[:3]==['mesh','rig','program']: cols={k:i for i,k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or 'floor' not in c[2]: continue
        try: m=float(c[cols['measured ns/vertex']]); p=float(c[cols['predicted']])
        except: continue
        out[(c[1],c[0])][c[2]]=math.log(p/m)
    return out
def corr(a,b):
    n=len(a); ma,mb=sum(a)/n,sum(b)/n
    sa=math.sqrt(sum((x-ma)**2 for x in a)); sb=math.sqrt(sum((y-mb)**2 for y in b))
    return sum((x-ma)*(y-mb) for x,y in zip(a,b))/(sa*sb)
ev=sys.argv[1]; L=levels(ev); F={}
for log in sys.argv[2:]: F.update(floors(log))
for mesh in ['dawn','head']:
  for fl in ['floor (pass-through)','floor + every input fetched']:
    ks=[k for k in L if k[1]==mesh and k in F and fl in F[k]]
    x=[F[k][fl] for k in ks]; y=[math.log(L[k]) for k in ks]
    print(f"{mesh} {fl:28s} {len(ks)} pairs: r(log level, floor's log(pred/meas)) = {corr(x,y):+.2f}; sd level {math.sqrt(sum((v-sum(y)/len(y))**2 for v in y)/len(y)):.3f}, sd floor {math.sqrt(sum((v-sum(x)/len(x))**2 for v in x)/len(x)):.3f}")
