#!/usr/bin/env python3
"""Measured over predicted (devices/nvidia-h200-raster.yaml) for every logged plan that reads the
palette from the uniform block at a per-vertex index (indexed_uniform_loads > 0), per (rig, mesh):
the median over those plans, beside the workload palette.sh printed.
  ratio.py PROFILE palette.txt LOG...   (needs PyYAML)"""
import statistics, sys, yaml

TERMS = ['arithmetic', 'locations', 'attribute_bytes', 'buffer_bytes', 'buffer_loads', 'indexed_uniform_loads',
         'buffer_vec4_loads', 'indexed_uniform_vec4_loads', 'outputs', 'vertices', 'fragments']

def rows(path):
    header = None
    for line in open(path):
        if line.startswith('| mesh |'):
            header = [c.strip() for c in line.strip().strip('|').split('|')]
        elif header and line.startswith('|') and not line.startswith('|---'):
            cells = [c.strip() for c in line.strip().strip('|').split('|')]
            if len(cells) == len(header):
                yield dict(zip(header, cells))
        elif not line.startswith('|'):
            header = None

def predict(profile, r):
    """The profile's prediction as docs/device-profiles.md states it: the additive weights plus
    the slowest pipe, each term scaled by its workload figure (the logged one, else the default)."""
    feature = {'joints_per_warp': float(r.get('joints per warp') or 0),
               'fragments_per_vertex': float(r.get('fragments per vertex', '0').replace('—', '0') or 0)}
    def amount(t):
        a = float(r.get(t, 1 if t == 'fragments' else 0))
        f = profile.get('scaled_by', {}).get(t)
        if f:
            a *= feature[f] if feature[f] > 0 else profile['workload_defaults'][f]
        return a
    additive = sum(w * amount(t) for t, w in profile['weights'].items())
    pipes = [sum(w * amount(t) for t, w in ws.items()) for ws in profile.get('pipes', {}).values()]
    return additive + max(pipes, default=0)

profile = yaml.safe_load(open(sys.argv[1]))
palette = {}
for line in open(sys.argv[2]):
    rig, mesh, jpw, entries = line.split()
    palette[(rig + '.rig.yaml', mesh)] = (float(jpw), float(entries))
ratios = {}
for log in sys.argv[3:]:
    for r in rows(log):
        key = (r['rig'], r['mesh'])
        if key in palette and r['program'].startswith('plan:') and float(r['indexed_uniform_loads']) > 0:
            ratios.setdefault(key, []).append(float(r['measured ns/vertex']) / predict(profile, r))
print('| rig | mesh | joints per warp | palette entries per warp | plans | measured / predicted (median) |')
print('|---|---|---:|---:|---:|---:|')
for key in sorted(ratios, key=lambda k: (k[1], palette[k][1])):
    jpw, entries = palette[key]
    print('| %s | %s | %.2f | %.1f | %d | %.2f |' % (key[0][:-9], key[1], jpw, entries, len(ratios[key]),
                                                 statistics.median(ratios[key])))
