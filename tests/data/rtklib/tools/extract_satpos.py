#!/usr/bin/env python3
"""Extract RTKLIB (rnx2rtkp -x 4) satellite positions/clocks from a trace file.

Usage:
  extract_satpos.py TRACE NAVFILE OUT.csv [--every N] [--report]

Reads the level-4 trace written by `rnx2rtkp -x 4 -o X.pos ...` (X.pos.trace)
and writes, for a subset of epochs (every N-th epoch, default 20 = 10 min at
30 s, plus the last epoch), one CSV row per observed satellite:

  week,tow_s,prn,tx_tow_s,x_m,y_m,z_m,clk_s

  week, tow_s : receiver time tag of the epoch (RINEX epoch line), GPS week and
                seconds of week, as RTKLIB's obs[i].time (NOT clock-corrected).
  prn         : GPS PRN.
  tx_tow_s    : signal transmission time (GPST seconds of week), recomputed here
                exactly as RTKLIB satposs() does:
                   t1 = tow_s - P/c            (P = obs.P[0] = C1 for these files)
                   dt = eph2clk(t1)            (af0+af1*t+af2*t^2, RTKLIB's
                                                2-step iteration, no relativity,
                                                no TGD; t relative to toc)
                   tx = t1 - dt
                and checked against the microsecond-rounded time printed in the
                trace (|diff| <= 0.5 us).
  x_m,y_m,z_m : rs[] from the trace (3 decimals): ECEF (WGS84/ECEF frame at the
                transmission epoch, i.e. NO Earth-rotation/Sagnac correction
                applied), broadcast ephemeris, antenna phase centre per broadcast
                convention.
  clk_s       : dts[0] from the trace (trace prints ns with 3 decimals): satellite
                clock bias at tx time, af0+af1*dt+af2*dt^2 PLUS the relativistic
                correction -2*sqrt(mu*A)*e*sinE/c^2, WITHOUT TGD.

With --report it also re-evaluates the broadcast orbit/clock independently
(own implementation of RTKLIB eph2pos with RTKLIB constants) at tx_tow_s and
prints the max difference to the trace values.
"""
import math
import re
import sys
from datetime import datetime

from rtklib_eph import CLIGHT, GPS_EPOCH, cal2gps, eph2clk, eph2pos, fnum


RE_RTKPOS = re.compile(r'^3 rtkpos  : time=(\S+ \S+) n=(\d+)')
RE_OBS = re.compile(r'^ \(\s*\d+\) (\S+ \S+) G(\d\d) rcv\d\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)')
RE_RS = re.compile(r'^4 (\S+ \S+) sat=\s*(\d+) rs=\s*(\S+)\s+(\S+)\s+(\S+) dts=\s*(\S+) var=\s*(\S+) svh=(\S+)')


def parse_trace(path):
    epochs = []
    cur = None
    with open(path, errors='replace') as f:
        for line in f:
            m = RE_RTKPOS.match(line)
            if m:
                cur = {'time': m.group(1), 'obs': {}, 'rs': {}, 'order': []}
                epochs.append(cur)
                continue
            if cur is None:
                continue
            m = RE_OBS.match(line)
            if m:
                prn = int(m.group(2))
                P1 = float(m.group(5))
                P2 = float(m.group(6))
                cur['obs'][prn] = (P1, P2)
                cur['order'].append(prn)
                continue
            m = RE_RS.match(line)
            if m:
                prn = int(m.group(2))
                cur['rs'][prn] = {
                    'ttx_str': m.group(1),
                    'x': float(m.group(3)), 'y': float(m.group(4)), 'z': float(m.group(5)),
                    'dts_ns': float(m.group(6)), 'svh': m.group(8),
                    'x_s': m.group(3), 'y_s': m.group(4), 'z_s': m.group(5), 'dts_s': m.group(6),
                }
    return epochs


def parse_nav(path):
    """RINEX 2 GPS nav -> list of eph dicts (times in absolute GPS seconds)."""
    ephs = []
    with open(path) as f:
        lines = f.readlines()
    i = 0
    while i < len(lines) and 'END OF HEADER' not in lines[i]:
        i += 1
    i += 1
    while i + 7 < len(lines) + 1 and i < len(lines):
        l0 = lines[i]
        if not l0.strip():
            i += 1
            continue
        prn = int(l0[0:2])
        yy = int(l0[3:5]); mo = int(l0[6:8]); dd = int(l0[9:11])
        hh = int(l0[12:14]); mi = int(l0[15:17]); ss = float(l0[17:22])
        year = yy + (2000 if yy < 80 else 1900)
        vals = [fnum(l0[22:41]), fnum(l0[41:60]), fnum(l0[60:79])]
        for k in range(1, 8):
            ln = lines[i + k].rstrip('\n').ljust(80)
            for c in range(4):
                vals.append(fnum(ln[3 + 19 * c:22 + 19 * c]))
        i += 8
        toc_dt = datetime(year, mo, dd, hh, mi, int(ss))
        d = toc_dt - GPS_EPOCH
        toc = d.days * 86400 + d.seconds + (ss - int(ss))
        af0, af1, af2 = vals[0:3]
        (iode, crs, deln, M0, cuc, e, cus, sqrtA, toes, cic, OMG0, cis,
         i0, crc, omg, OMGd, idot, codes, week, l2p, sva, svh, tgd, iodc,
         ttr, fit) = vals[3:29]
        toe = week * 604800 + toes
        while toe - toc > 302400: toe -= 604800   # adjweek(toe, toc)
        while toe - toc < -302400: toe += 604800
        ttrw = week * 604800 + ttr
        while ttrw - toc > 302400: ttrw -= 604800
        while ttrw - toc < -302400: ttrw += 604800
        ephs.append(dict(prn=prn, toc=toc, toe=toe, ttr=ttrw, toes=toes, f0=af0, f1=af1, f2=af2,
                         iode=int(iode), crs=crs, deln=deln, M0=M0, cuc=cuc, e=e, cus=cus,
                         A=sqrtA * sqrtA, cic=cic, OMG0=OMG0, cis=cis, i0=i0, crc=crc, omg=omg,
                         OMGd=OMGd, idot=idot, svh=int(svh), tgd=tgd, sva=sva))
    # RTKLIB uniqnav: sort by ttr, toe, sat; drop consecutive duplicates (sat, iode)
    ephs.sort(key=lambda q: (q['ttr'], q['toe'], q['prn']))
    out = []
    for q in ephs:
        if out and out[-1]['prn'] == q['prn'] and out[-1]['iode'] == q['iode']:
            continue
        out.append(q)
    return out


def seleph(ephs, prn, teph, wk0):
    j, tmin, tmax = None, 7201.0 + 1.0, 7201.0  # MAXDTOE=7200 (+1)
    for q in ephs:
        if q['prn'] != prn:
            continue
        t = abs((q['toe'] - wk0 * 604800) - teph)
        if t > tmax:
            continue
        if t <= tmin:
            j, tmin = q, t
    return j


def main():
    args = sys.argv[1:]
    every = 20
    report = False
    if '--every' in args:
        k = args.index('--every'); every = int(args[k + 1]); del args[k:k + 2]
    if '--report' in args:
        args.remove('--report'); report = True
    trace, navf, outcsv = args
    epochs = parse_trace(trace)
    ephs = parse_nav(navf)
    sel = list(range(0, len(epochs), every))
    if len(epochs) - 1 not in sel:
        sel.append(len(epochs) - 1)

    maxdtx = maxdpos = maxdclk = 0.0
    nchk = 0
    nopr = 0
    rows = []
    for idx, ep in enumerate(epochs):
        week, tow = cal2gps(ep['time'])
        for prn in ep['order']:
            if prn not in ep['rs']:
                continue
            r = ep['rs'][prn]
            P1, P2 = ep['obs'][prn]
            if P1 == 0.0 and P2 == 0.0:
                # no pseudorange: satposs() leaves time=0 (1970) and rs=0
                nopr += 1
                continue
            pr = P1 if P1 != 0.0 else P2
            q = seleph(ephs, prn, tow, week)       # teph = receiver time tag
            t1 = tow - pr / CLIGHT
            tx = t1 - eph2clk(t1, q, week)
            wtx, ttx_trace = cal2gps(r['ttx_str'])
            dtx = tx - (ttx_trace + (wtx - week) * 604800)
            maxdtx = max(maxdtx, abs(dtx))
            if abs(dtx) > 0.5e-6 + 1e-9:
                print('WARNING tx mismatch', ep['time'], prn, dtx, file=sys.stderr)
            if report:
                rs, dts = eph2pos(tx, q, week)
                dp = max(abs(rs[0] - r['x']), abs(rs[1] - r['y']), abs(rs[2] - r['z']))
                dc = abs(dts * 1e9 - r['dts_ns'])
                maxdpos = max(maxdpos, dp); maxdclk = max(maxdclk, dc); nchk += 1
            if idx in sel:
                if r['svh'] != '00' or (r['x'] == 0.0 and r['y'] == 0.0):
                    print('NOTE: svh/zero position', ep['time'], prn, r['svh'], file=sys.stderr)
                clk_s = '%.12f' % (r['dts_ns'] * 1e-9)
                rows.append('%d,%.7f,%d,%.10f,%s,%s,%s,%s' % (
                    week, tow, prn, tx, r['x_s'], r['y_s'], r['z_s'], clk_s))
    with open(outcsv, 'w') as f:
        f.write('week,tow_s,prn,tx_tow_s,x_m,y_m,z_m,clk_s\n')
        f.write('\n'.join(rows) + '\n')
    print('epochs in trace: %d, selected: %d, rows: %d' % (len(epochs), len(sel), len(rows)))
    print('sat-epochs skipped (no pseudorange, no RTKLIB position): %d' % nopr)
    print('max |tx(recomputed) - tx(trace, 1us)| = %.3e s' % maxdtx)
    if report:
        print('independent eph2pos check over %d sat-epochs: max |d pos| = %.4f m, '
              'max |d clk| = %.4f ns' % (nchk, maxdpos, maxdclk))


if __name__ == '__main__':
    main()
