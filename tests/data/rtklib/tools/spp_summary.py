#!/usr/bin/env python3
"""Summarise RTKLIB SPP solutions (.pos, ECEF, GPST week/tow) against the
RINEX header APPROX POSITION XYZ.  Plain python3, no numpy.

Usage: spp_summary.py LABEL POSFILE RINEX_OBS [LABEL POSFILE RINEX_OBS ...]

Errors are sol - header, rotated to local ENU at the header position
(WGS84 geodetic latitude/longitude of the header XYZ).
  horizontal error  = sqrt(dE^2 + dN^2)
  vertical error    = |dU|
  RMS               = sqrt(mean(err^2))
  p95               = nearest-rank 95th percentile: sorted(err)[ceil(0.95*N)-1]
  max               = max(err)
"""
import math
import sys

A_WGS84 = 6378137.0
F_WGS84 = 1.0 / 298.257223563


def ecef2pos(r):
    """RTKLIB-style ecef2pos: returns lat, lon (rad), h (m)."""
    e2 = F_WGS84 * (2.0 - F_WGS84)
    r2 = r[0] ** 2 + r[1] ** 2
    z, zk, v = r[2], 0.0, A_WGS84
    while abs(z - zk) >= 1e-4:
        zk = z
        sinp = z / math.sqrt(r2 + z * z)
        v = A_WGS84 / math.sqrt(1.0 - e2 * sinp * sinp)
        z = r[2] + v * e2 * sinp
    lat = math.atan(z / math.sqrt(r2)) if r2 > 1e-12 else (math.pi / 2 if r[2] > 0 else -math.pi / 2)
    lon = math.atan2(r[1], r[0]) if r2 > 1e-12 else 0.0
    return lat, lon, math.sqrt(r2 + z * z) - v


def enu(lat, lon, d):
    sl, cl, sp, cp = math.sin(lon), math.cos(lon), math.sin(lat), math.cos(lat)
    e = -sl * d[0] + cl * d[1]
    n = -sp * cl * d[0] - sp * sl * d[1] + cp * d[2]
    u = cp * cl * d[0] + cp * sl * d[1] + sp * d[2]
    return e, n, u


def header_xyz(obsfile):
    with open(obsfile, errors='replace') as f:
        for line in f:
            if 'APPROX POSITION XYZ' in line:
                return [float(line[0:14]), float(line[14:28]), float(line[28:42])]
            if 'END OF HEADER' in line:
                break
    raise RuntimeError('no APPROX POSITION XYZ in ' + obsfile)


def count_epochs(obsfile, step=None):
    """Number of RINEX (2 or 3) epochs; with step (s), only epochs whose time of day
    (rounded to 1 s) is a multiple of step (what rnx2rtkp -ti step processes)."""
    n, in_hdr = 0, True
    with open(obsfile, errors='replace') as f:
        for line in f:
            if in_hdr:
                in_hdr = 'END OF HEADER' not in line
                continue
            # RINEX 3 epoch line: '> yyyy mm dd hh mm ss.sssssss  f nn...'
            if line.startswith('> ') and len(line) > 31 and line[31] in '0123456':
                if step:
                    tod = int(line[13:15]) * 3600 + int(line[16:18]) * 60 + float(line[18:29])
                    if round(tod) % step:
                        continue
                if line[31] in '01':          # epoch flags 0/1 carry observations
                    n += 1
                continue
            # RINEX 2 epoch line: ' yy mm dd hh mm ss.sssssss  f nn...'
            if (len(line) > 32 and line[0] == ' ' and line[3] == ' ' and line[26] == ' '
                    and line[28] in '0123456' and line[1:3].strip().isdigit()
                    and line[10:12].strip().isdigit() and line[29:32].strip().isdigit()):
                if step:
                    tod = int(line[10:12]) * 3600 + int(line[13:15]) * 60 + float(line[15:26])
                    if round(tod) % step:
                        continue
                n += 1
    return n


def read_pos(posfile):
    sols = []
    with open(posfile) as f:
        for line in f:
            if line.startswith('%') or not line.strip():
                continue
            t = line.split()
            sols.append(dict(week=int(t[0]), tow=float(t[1]), x=float(t[2]), y=float(t[3]),
                             z=float(t[4]), q=int(t[5]), ns=int(t[6])))
    return sols


def p95(v):
    s = sorted(v)
    return s[max(0, math.ceil(0.95 * len(s)) - 1)]


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v))


def stats_block(rows, title):
    h = [math.hypot(r[0], r[1]) for r in rows]
    vv = [abs(r[2]) for r in rows]
    n = len(rows)
    me = sum(r[0] for r in rows) / n
    mn = sum(r[1] for r in rows) / n
    mu = sum(r[2] for r in rows) / n
    out = ['  %s (N=%d)' % (title, n),
           '    mean dE / dN / dU      : %8.3f %8.3f %8.3f m' % (me, mn, mu),
           '    RMS  dE / dN / dU      : %8.3f %8.3f %8.3f m' % (rms([r[0] for r in rows]),
                                                               rms([r[1] for r in rows]),
                                                               rms([r[2] for r in rows])),
           '    horizontal RMS/p95/max : %8.3f %8.3f %8.3f m' % (rms(h), p95(h), max(h)),
           '    vertical   RMS/p95/max : %8.3f %8.3f %8.3f m' % (rms(vv), p95(vv), max(vv)),
           '    3D RMS                 : %8.3f m' % rms([math.sqrt(r[0] ** 2 + r[1] ** 2 + r[2] ** 2)
                                                         for r in rows])]
    return out


def summarise(label, posfile, obsfile):
    hdr = header_xyz(obsfile)
    lat, lon, hgt = ecef2pos(hdr)
    sols = read_pos(posfile)
    dts = sorted(round(b['tow'] - a['tow']) for a, b in zip(sols, sols[1:]))
    step = dts[len(dts) // 2] if dts else 0
    decim = step > 30
    nep = count_epochs(obsfile, step if decim else None)
    rows, rows6 = [], []
    worst = None
    for s in sols:
        d = (s['x'] - hdr[0], s['y'] - hdr[1], s['z'] - hdr[2])
        e, n, u = enu(lat, lon, d)
        rows.append((e, n, u))
        if s['ns'] >= 6:
            rows6.append((e, n, u))
        h3 = math.sqrt(e * e + n * n + u * u)
        if worst is None or h3 > worst[0]:
            worst = (h3, s, e, n, u)
    qh = {}
    nsh = {}
    for s in sols:
        qh[s['q']] = qh.get(s['q'], 0) + 1
        nsh[s['ns']] = nsh.get(s['ns'], 0) + 1
    out = ['== %s' % label,
           '  pos file   : %s' % posfile.split('/')[-1],
           '  obs file   : %s' % obsfile.split('/')[-1],
           '  header APPROX POSITION XYZ : %.4f %.4f %.4f m' % tuple(hdr),
           '  header lat/lon/h (WGS84)   : %.9f %.9f deg %.4f m' % (math.degrees(lat), math.degrees(lon), hgt),
           '  epochs in RINEX%s: %d, SPP solutions: %d (missing %d)' % (
               ' on the %d s output grid (rnx2rtkp -ti %d)' % (step, step) if decim else '',
               nep, len(sols), nep - len(sols)),
           '  Q histogram: %s   ns histogram: %s' % (
               ', '.join('Q%d=%d' % kv for kv in sorted(qh.items())),
               ', '.join('%d:%d' % kv for kv in sorted(nsh.items())))]
    out += stats_block(rows, 'all solutions')
    if len(rows6) != len(rows):
        out += stats_block(rows6, 'solutions with ns>=6 only')
    out.append('  worst 3D epoch: week %d tow %.6f ns=%d dE=%.3f dN=%.3f dU=%.3f (3D %.3f m)' % (
        worst[1]['week'], worst[1]['tow'], worst[1]['ns'], worst[2], worst[3], worst[4], worst[0]))
    return out


def main():
    a = sys.argv[1:]
    if not a or len(a) % 3:
        sys.exit(__doc__)
    lines = []
    for i in range(0, len(a), 3):
        lines += summarise(a[i], a[i + 1], a[i + 2])
        lines.append('')
    print('\n'.join(lines))


if __name__ == '__main__':
    main()
