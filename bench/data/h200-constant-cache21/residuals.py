# Measured over predicted, median and quartiles, of every plan and palette probe in the logs,
# grouped by mesh, by the pipe the profile says bounds it, and by whether it reads a uniform at a
# per-vertex index ("iu"). A profile's level errors by mesh and pipe.
#   python3 residuals.py PROFILE.yaml LOG...   (logs with footprints: augment.py's)
import sys, yaml, statistics
TERMS = ['arithmetic', 'locations', 'attribute_bytes', 'buffer_bytes', 'buffer_loads', 'indexed_uniform_loads',
         'buffer_vec4_loads', 'indexed_uniform_vec4_loads', 'outputs', 'vertices', 'fragments']
prof = yaml.safe_load(open(sys.argv[1]))
cache = prof.get('constant_cache')
defaults = prof.get('workload_defaults', {})
def rows(path):
    hdr = None
    for line in open(path):
        if line.startswith('| mesh |'): hdr = [c.strip() for c in line.strip().strip('|').split('|')]; continue
        if hdr and line.startswith('|') and not line.startswith('|---'):
            c = [x.strip() for x in line.strip().strip('|').split('|')]
            if len(c) == len(hdr): yield dict(zip(hdr, c))
def num(r, k):
    try: return float(r.get(k, ''))
    except ValueError: return 0.0
def feature(r, name):
    if name == 'joints_per_warp':
        j = num(r, 'joints per warp') or defaults.get(name, 1)
        e = num(r, 'palette entries per warp') or defaults.get('palette_entries_per_warp', 0)
        return j * (cache['miss_factor'] if cache and e > cache['entries'] else 1)
    return num(r, 'fragments per vertex') or defaults.get(name, 1)
def predict(r):
    scaled = prof.get('scaled_by') or {}
    amount = lambda t: (num(r, t) if t in r else (1 if t == 'fragments' else 0)) * (feature(r, scaled[t]) if t in scaled else 1)
    pipes = {n: sum(w * amount(t) for t, w in ws.items()) for n, ws in prof['pipes'].items()}
    return sum(prof['weights'].get(t, 0) * amount(t) for t in TERMS) + max(pipes.values()), max(pipes, key=pipes.get)
groups = {}
for log in sys.argv[2:]:
    for r in rows(log):
        if not r['program'].startswith('plan:') and 'palette' not in r['program']: continue
        ns, pipe = predict(r)
        key = (r['mesh'], pipe, 'iu' if num(r, 'indexed_uniform_loads') > 0 else '--')
        groups.setdefault(key, []).append(num(r, 'measured ns/vertex') / ns)
print('| mesh | bounding pipe | reads a uniform at a per-vertex index | samples | measured / predicted: median | quartiles |')
print('|---|---|---|---:|---:|---|')
for k in sorted(groups):
    v = sorted(groups[k]); q = statistics.quantiles(v, n=4) if len(v) > 1 else [v[0], v[0], v[0]]
    print(f'| {k[0]} | {k[1]} | {"yes" if k[2] == "iu" else "no"} | {len(v)} | {statistics.median(v):.2f} | {q[0]:.2f}-{q[2]:.2f} |')
