# Each program's process-CPU time per vertex (raster off) under the two placements, and their ratio.
import sys
def rows(f):
    out = {}
    for line in open(f):
        c = [x.strip() for x in line.strip().strip('|').split('|')]
        if len(c) == 12 and c[0] not in ('program', '---') and not c[0].startswith('-'):
            out[c[0]] = float(c[11].split()[0]) if c[11] not in ('—', '') else None
    return out
a, b = rows(sys.argv[1]), rows(sys.argv[2])
ratios = []
print('| program | device-local | mapped | device-local / mapped |\n|---|---:|---:|---:|')
for k in a:
    if a[k] and b.get(k):
        ratios.append(a[k] / b[k])
        print('| %s | %.2f | %.2f | %.3f |' % (k, a[k], b[k], a[k] / b[k]))
ratios.sort()
print('\n%d programs: device-local / mapped median %.3f, range %.3f-%.3f' % (len(ratios), ratios[len(ratios) // 2], ratios[0], ratios[-1]))
