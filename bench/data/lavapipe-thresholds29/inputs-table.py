"""Session 29: in every lavapipe log of 6 rounds or more, each rig's plan with the skin's joints and weights
from a storage buffer over its plan that fetches them as attributes, by the attribute plan's input locations.
Usage: python3 inputs-table.py (from anywhere)."""
import glob, os, sys
here = os.path.dirname(os.path.abspath(__file__))
data = os.path.join(here, '..')
sys.path.insert(0, os.path.join(data, 'h200-fresh23'))
from logtable import rows

logs = (glob.glob(f'{data}/lavapipe-rounds17/*.log') + glob.glob(f'{data}/lavapipe-unseen13/*/*.log') +
        glob.glob(f'{data}/lavapipe-heldout/*.log') + [f'{data}/lavapipe-formats19/train.log'])
out = []
for f in logs:
    by = {}
    for r in rows(f):
        by.setdefault((r['rig'], r['mesh']), {})[r['program']] = r
    for (rig, mesh), plans in by.items():
        g = plans.get('plan: generated')
        if not g:
            continue
        for p, r in plans.items():
            if 'buffered_influences for' in p and 'buffer_palette' not in p:
                out.append((int(g['locations']), float(r['measured ns/vertex']) / float(g['measured ns/vertex']), rig, mesh,
                            os.path.relpath(f, data)))
for locations, ratio, rig, mesh, log in sorted(out):
    print(f'{locations:3d} inputs  {ratio:.3f}  {rig} on {mesh}  ({log})')
