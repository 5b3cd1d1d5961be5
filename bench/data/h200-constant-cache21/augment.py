# Adds the "palette entries per warp" column to session 18/19's H200 logs, which predate it:
# each rig's from explain's workload (workloads.txt), each palette probe's (and its exact joints
# per warp: the addresses it reads, counted as a skin's) from a session 21 calibrate run of the
# same probes (probe-footprints.log: lavapipe's times, read only for the footprints, which
# depend on the mesh alone). `blind` writes the column empty (the same logs, footprints unknown).
#   python3 augment.py LOG,LOG,... OUTDIR [blind]
import sys, os
here = os.path.dirname(os.path.abspath(__file__))
def rows(path):
    out = []
    for line in open(path):
        if line.startswith('|') and not line.startswith('|---'):
            out.append([c.strip() for c in line.strip().strip('|').split('|')])
    return out
probe = {}
t = rows(os.path.join(here, 'probe-footprints.log')); h = t[0]
J = h.index('joints per warp'); E = h.index('palette entries per warp')
for r in t[1:]:
    if 'palette' in r[2]: probe[(r[0], r[2])] = (r[J], r[E])
wl = {}
for line in open(os.path.join(here, 'workloads.txt')):
    p = line.split()
    if len(p) == 4: wl[(p[0], p[1])] = (p[2], p[3])
noentries = len(sys.argv) > 3 and sys.argv[3] == 'blind'
for src in sys.argv[1].split(','):
    lines = open(src).read().split('\n')
    out = []
    header = None
    for line in lines:
        if line.startswith('| mesh |'):
            header = [c.strip() for c in line.strip().strip('|').split('|')]
            hasE = 'palette entries per warp' in header
            out.append(line if hasE else line + ' palette entries per warp |'); continue
        if line.startswith('|---') and header:
            out.append(line if hasE else line + '---:|'); continue
        if line.startswith('|') and header:
            c = [x.strip() for x in line.strip().strip('|').split('|')]
            mesh, rig, prog = c[0], c[1], c[2]
            e = '—'
            if (mesh, prog) in probe and rig in ('—', ''):
                j, e = probe[(mesh, prog)]
                c[header.index('joints per warp')] = j
            elif (rig, mesh) in wl and float(wl[(rig, mesh)][1]) > 0:
                e = wl[(rig, mesh)][1]
            if noentries: e = '—'
            if not hasE: c.append(e)
            out.append('| ' + ' | '.join(c) + ' |'); continue
        out.append(line)
    open(os.path.join(sys.argv[2], os.path.basename(src)), 'w').write('\n'.join(out))
