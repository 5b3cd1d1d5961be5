import math,sys,glob
def cells(l): return [c.strip() for c in l.strip().strip('|').split('|')]
def levels(p):
    L={}; on=False
    for line in open(p):
        if line.startswith('| rig | mesh |'): on=True; hdr=cells(line); continue
        if on and line.startswith('| ') and not line.startswith('|---'):
            c=cells(line)
            try: L[(c[0],c[1])]=float(c[hdr.index('level (predicted / measured)')])
            except: pass
    return L
J={}; S={}
for log in sys.argv[2:]:
    cols=None
    for line in open(log):
        if not line.startswith('|'): continue
        c=cells(line)
        if c[:3]==['mesh','rig','program']: cols={k:i for i,k in enumerate(c)}; continue
        if cols is None or c[0].startswith('---') or c[1]=='—': continue
        try:
            J[(c[1],c[0])]=float(c[cols['joints per warp']])
            S[(c[1],c[0])]=max(S.get((c[1],c[0]),0), int(c[cols['indexed_uniform_loads']])+int(c[cols.get('buffer_table_loads',cols['indexed_uniform_loads'])]))
        except: pass
def corr(a,b):
    n=len(a); ma,mb=sum(a)/n,sum(b)/n
    sa=math.sqrt(sum((x-ma)**2 for x in a)); sb=math.sqrt(sum((y-mb)**2 for y in b))
    return sum((x-ma)*(y-mb) for x,y in zip(a,b))/(sa*sb)
L=levels(sys.argv[1])
for mesh in ['head','dawn']:
    ks=[k for k in L if k[1]==mesh and k in J and S.get(k,0)>=8]
    if len(ks)<3: continue
    y=[math.log(L[k]) for k in ks]
    sd=math.sqrt(sum((v-sum(y)/len(y))**2 for v in y)/len(y))
    print(f"{mesh}: {len(ks)} pairs with >= 8 palette loads: r(log level, jpw) = {corr([J[k] for k in ks],y):+.2f}, sd log level {sd:.3f}")
