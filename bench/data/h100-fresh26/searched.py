#!/usr/bin/env python3
"""The held-out check with the search's own choice. `calibrate --evaluate` calls "chosen" the least
predicted of the programs a log timed and, where several share that prediction, counts the slowest of
them. Here each random rig of the logs is searched again under the profile (`shadergen explain --mesh`,
with the device limits calibrate timed under: 32 vertex inputs, a 64 KiB uniform block), and its plan is
looked up among the rig's timed programs by its term amounts. Prints, per (rig, mesh) pair, both ratios
to the fastest timed program; a plan the log did not time is reported as such.
Usage: python3 searched.py SHADERGEN PROFILE CORPUS_DIR LOG...
(CORPUS_DIR: `shadergen calibrate --corpus 16 --seed S --write-corpus CORPUS_DIR -r examples/dawn/rules.yaml`
for each seed the logs hold; run from the repository root.)"""
import os, re, subprocess, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'h200-fresh23'))
from logtable import rows  # noqa: E402

TERMS = ('arithmetic locations attribute_bytes buffer_bytes buffer_loads indexed_uniform_loads buffer_vec4_loads '
         'indexed_uniform_vec4_loads outputs').split()
sg, profile, corpus = sys.argv[1:4]


def searched_amounts(rig, mesh):
    base = os.path.join(corpus, rig[:-len('.rig.yaml')])
    out = subprocess.run([sg, 'explain', '--rig', base + '.rig.yaml', '-f', base + '.frag', '-r', 'examples/dawn/rules.yaml',
                          '--device-profile', profile, '--mesh', mesh, '--max-attributes', '32',
                          '--max-uniform-bytes', '65536'], capture_output=True, text=True, check=True).stdout
    found = {t: int(n) for t, n in re.findall(r'^\s+(\w+)\s+(\d+)\s+[\d.]+\s+[\d.]+', out, re.M)}
    # A log written before table reads were counted apart (session 27) counts them as buffer loads.
    for table, streamed in (('buffer_table_loads', 'buffer_loads'), ('buffer_table_vec4_loads', 'buffer_vec4_loads')):
        if table not in TERMS:
            found[streamed] = found.get(streamed, 0) + found.get(table, 0)
    return tuple(str(found[t]) for t in TERMS)


counted_apart = {any('buffer_table_loads' in r for r in rows(log)) for log in sys.argv[4:]}
if len(counted_apart) > 1:
    sys.exit('the logs must all count table reads apart (session 27), or none')
if counted_apart == {True}:
    TERMS = TERMS + ['buffer_table_loads', 'buffer_table_vec4_loads']
evaluated = {}
for log in sys.argv[4:]:
    for r in rows(log):
        if r['program'].startswith('plan') and r['rig'].startswith('corpus-'):  # 'plan: ', 'plan under NAME: '
            evaluated.setdefault((r['rig'], r['mesh']), []).append((tuple(r[t] for t in TERMS), float(r['measured ns/vertex'])))
print('| rig | mesh | searched plan / fastest timed |')
print('|---|---|---:|')
over = missing = 0
for (rig, mesh), plans in sorted(evaluated.items()):
    fastest = min(ns for _, ns in plans)
    amounts = searched_amounts(rig, mesh)
    times = [ns for a, ns in plans if a == amounts]
    if not times:
        missing += 1
        print(f'| {rig} | {mesh} | not timed |')
        continue
    ratio = times[0] / fastest
    over += ratio > 1.05
    print(f'| {rig} | {mesh} | {ratio:.3f} |')
print(f'\n{len(evaluated)} pairs: the searched plan over 5 % from the fastest timed in {over}; not among the timed programs in {missing}')
