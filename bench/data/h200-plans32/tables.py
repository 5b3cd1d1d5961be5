"""Session 32: reading calibrate's logs and `calibrate --evaluate`'s table, for this folder's analyses."""
import math


def cells(line):
    return [c.strip() for c in line.strip().strip('|').split('|')]


def log_rows(path):
    """Each sample row of a calibrate log as {column header: cell}; probes (no rig) and separators left out."""
    cols = None
    for line in open(path):
        if not line.startswith('|'): continue
        c = cells(line)
        if c[:3] == ['mesh', 'rig', 'program']: cols = c; continue
        if cols is None or c[0].startswith('---') or c[1] == '—': continue
        yield dict(zip(cols, c))


def number(row, key):
    """The cell as a number; None where it is missing or not one (a row that failed, '—')."""
    try: return float(row[key])
    except (KeyError, ValueError): return None


def levels(path):
    """{(rig, mesh): level} from `calibrate --evaluate`'s table."""
    out, cols = {}, None
    for line in open(path):
        if line.startswith('| rig | mesh |'): cols = cells(line); continue
        if cols and line.startswith('| ') and not line.startswith('|---'):
            row = dict(zip(cols, cells(line)))
            level = number(row, 'level (predicted / measured)')
            if level is not None: out[(row['rig'], row['mesh'])] = level
    return out


def plan_rows(path):
    """Each row of `calibrate --evaluate --per-plan`'s table ("held-out check, every plan") as {column header: cell}."""
    cols, inside = None, False
    for line in open(path):
        if line.startswith('held-out check, every plan'): inside = True; continue
        if not inside or not line.startswith('|') or line.startswith('|---'): continue
        c = cells(line)
        if c[:3] == ['rig', 'mesh', 'plan']: cols = c; continue
        if cols: yield dict(zip(cols, c))


def corr(a, b):
    """Pearson's r; NaN for fewer than 3 points or no spread."""
    n = len(a)
    if n < 3: return float('nan')
    ma, mb = sum(a) / n, sum(b) / n
    sa = math.sqrt(sum((x - ma) ** 2 for x in a)); sb = math.sqrt(sum((y - mb) ** 2 for y in b))
    return float('nan') if sa == 0 or sb == 0 else sum((x - ma) * (y - mb) for x, y in zip(a, b)) / (sa * sb)


def sd(v):
    m = sum(v) / len(v)
    return math.sqrt(sum((x - m) ** 2 for x in v) / len(v))
