"""The table of a calibrate log, row by row, read by its header's column names."""


def rows(path):
    hdr = None
    for line in open(path):
        if line.startswith('| mesh |'):
            hdr = [c.strip() for c in line.strip().strip('|').split('|')]
        elif hdr and line.startswith('|') and not line.startswith('|---'):
            c = [x.strip() for x in line.strip().strip('|').split('|')]
            if len(c) == len(hdr):
                yield dict(zip(hdr, c))
