import sys,collections
# Offline stand-in for bench --candidates K --pin-out: in run A, the K plans of each pair cheapest by the
# profile's prediction (among the plans the log holds), the fastest of them by A's timing; judged by run B's
# timing of the same programs (B: all the pair's plans).
def load(f):
  pairs=collections.OrderedDict()
  for l in open(f):
    c=[x.strip() for x in l.split('|')]
    if len(c)<10 or not c[1].endswith('.yaml'): continue
    try: p=float(c[5]); m=float(c[6])
    except: continue
    pairs.setdefault((c[1],c[2]),{})
    d=pairs[(c[1],c[2])]
    if c[4] not in d or m<d[c[4]][1]: d[c[4]]=(p,m)
  return pairs
A=load(sys.argv[1]); B=load(sys.argv[2])
for K in (1,2,3,4,6):
  rs=[]
  for key,pl in A.items():
    if key not in B: continue
    cand=sorted(pl.items(), key=lambda x:(x[1][0],x[0]))[:K]
    pick=min(cand,key=lambda x:x[1][1])[0]
    bm={k:v[1] for k,v in B[key].items()}
    if pick not in bm: continue
    rs.append(bm[pick]/min(bm.values()))
  print(f"K={K}: {len(rs)} pairs, within 5 % {sum(r<=1.05 for r in rs)}, within 10 % {sum(r<=1.10 for r in rs)}, worst {max(rs):.3f}")
