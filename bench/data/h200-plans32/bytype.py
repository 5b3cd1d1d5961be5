import math,sys,collections
def cells(l): return [c.strip() for c in l.strip().strip('|').split('|')]
def corr(a,b):
    n=len(a); ma,mb=sum(a)/n,sum(b)/n
    sa=math.sqrt(sum((x-ma)**2 for x in a)); sb=math.sqrt(sum((y-mb)**2 for y in b))
    return sum((x-ma)*(y-mb) for x,y in zip(a,b))/(sa*sb)
data=collections.defaultdict(list)
for log in sys.argv[1:]:
    cols=None
    for line in open(log):
        if not line.startswith('|'): continue
        c=cells(line)
        if c[:3]==['mesh','rig','program']: cols={k:i for i,k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or c[1]=='—' or 'plan under' not in c[2]: continue
        try: m=float(c[cols['measured ns/vertex']]); p=float(c[cols['predicted']]); j=float(c[cols['joints per warp']])
        except: continue
        u=int(c[cols['indexed_uniform_loads']]); t=int(c[cols['buffer_table_loads']])
        kind='uniform palette' if u>=8 else 'table palette' if t>=8 else 'no/small palette'
        data[(c[0],kind)].append((j,math.log(p/m),m,p))
for (mesh,kind),v in sorted(data.items()):
    if len(v)<3: continue
    x=[a for a,_,_,_ in v]; y=[b for _,b,_,_ in v]
    # slope of log(p/m) on log(jpw)
    lx=[math.log(max(a,0.5)) for a in x]; mx=sum(lx)/len(lx); my=sum(y)/len(y)
    slope=sum((a-mx)*(b-my) for a,b in zip(lx,y))/sum((a-mx)**2 for a in lx)
    print(f"{mesh:5s} {kind:17s} n={len(v):3d} r(log(pred/meas), jpw)={corr(x,y):+.2f} slope on log jpw {slope:+.2f}; mean log(pred/meas) {my:+.3f}")
