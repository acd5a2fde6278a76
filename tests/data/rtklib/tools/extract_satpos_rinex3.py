#!/usr/bin/env python3
"""Extract RTKLIB 2.4.3 b34 (rnx2rtkp -x 4) GPS + Galileo satellite positions
and clocks from a trace file produced from a RINEX 3 obs/nav pair.

Usage:
  extract_satpos_rinex3.py TRACE NAVFILE(RINEX 3) OUT.csv [--report] [--obs OBSFILE]

Writes one CSV row per observed GPS/Galileo satellite and epoch (all epochs):

  sys,prn,week,tow_s,tx_tow_s,x_m,y_m,z_m,clk_s

  sys         : 'G' or 'E'.
  prn         : satellite number within the system.
  week, tow_s : receiver time tag of the epoch (RINEX epoch line, GPST), as
                RTKLIB's obs[i].time (NOT corrected for the receiver clock).
  tx_tow_s    : transmission time (GPST seconds of week), recomputed exactly as
                RTKLIB satposs() does:
                   t1 = tow_s - P/c       P = obs.P[0]: GPS C1C, Galileo C1C (E1)
                   dt = eph2clk(t1)       af0+af1*t+af2*t^2 (2-step iteration),
                                          no relativity, no TGD/BGD
                   tx = t1 - dt
                and checked against the microsecond-rounded time in the trace.
  x_m,y_m,z_m : rs[] from the trace (3 decimals), ECEF at transmission time,
                NO Earth-rotation (Sagnac) correction.
  clk_s       : dts[0] from the trace (ns with 3 decimals -> 1e-12 s):
                af0+af1*dt+af2*dt^2 - 2*sqrt(mu*A)*e*sinE/c^2, WITHOUT TGD/BGD.

The ephemeris is chosen by re-implementing RTKLIB 2.4.3 b34 uniqeph() + seleph()
(default ephemeris selection, i.e. Galileo I/NAV):
  * uniqeph: sort all GPS/GAL/QZS/BDS records by (ttr, toe, sat) and drop a
    record if the previous one in that order has the same sat and IODE/IODnav
    (the one with the later transmission time is dropped);
  * seleph(teph = receiver time tag, iode=-1): among the records of the sat,
    |toe - teph| <= tmax, Galileo additionally: data-sources bit 9 set
    (I/NAV clock, E5b/E1) and toe < teph (AOD > 0); the record with the
    smallest |toe - teph| wins, ties -> the later one in the sorted order.

With --report the broadcast orbit/clock is re-evaluated independently
(Galileo ICD / IS-GPS-200 with RTKLIB's constants: GPS mu=3.9860050e14,
Galileo mu=3.986004418e14, Earth rotation 7.2921151467e-5 for both) at
tx_tow_s and the max differences to the trace values are printed, together with
the ephemeris chosen for every satellite.  With --obs the pseudoranges in the
trace (P[0], P[1]) are matched against the RINEX 3 observation file to show
which observation code RTKLIB put in each slot.
"""
import math
import re
import sys
from datetime import datetime

from rtklib_eph import CLIGHT, GPS_EPOCH, cal2gps, eph2clk, eph2pos, fnum

MAXDTOE = 7200.0               # GPS: tmax = MAXDTOE + 1
MAXDTOE_GAL_MIN = 10800.0      # 10800 or 14400 depending on the 2.4.3 patch; not binding here
NSAT_GPS, NSAT_GLO = 32, 27    # RTKLIB sat numbering: G01=1, R01=33, E01=60

RE_RTKPOS = re.compile(r'^3 rtkpos  : time=(\S+ \S+) n=(\d+)')
RE_OBS = re.compile(r'^ \(\s*\d+\) (\S+ \S+) ([GE])(\d\d) rcv\d\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)')
RE_RS = re.compile(r'^4 (\S+ \S+) sat=\s*(\d+) rs=\s*(\S+)\s+(\S+)\s+(\S+) dts=\s*(\S+) var=\s*(\S+) svh=(\S+)')


def satno(sys_, prn):
    return prn if sys_ == 'G' else NSAT_GPS + NSAT_GLO + prn


def parse_trace(path):
    epochs, cur = [], None
    with open(path, errors='replace') as f:
        for line in f:
            m = RE_RTKPOS.match(line)
            if m:
                cur = {'time': m.group(1), 'obs': [], 'rs': []}
                epochs.append(cur)
                continue
            if cur is None:
                continue
            m = RE_OBS.match(line)
            if m:
                cur['obs'].append((m.group(2), int(m.group(3)), float(m.group(6)), float(m.group(7))))
                continue
            m = RE_RS.match(line)
            if m and len(cur['rs']) < len(cur['obs']):
                cur['rs'].append({'ttx_str': m.group(1), 'sat': int(m.group(2)),
                                  'x': float(m.group(3)), 'y': float(m.group(4)), 'z': float(m.group(5)),
                                  'dts_ns': float(m.group(6)), 'var': m.group(7), 'svh': m.group(8),
                                  'x_s': m.group(3), 'y_s': m.group(4), 'z_s': m.group(5)})
    return epochs


def parse_obs3(path):
    """RINEX 3 obs -> {(tow_rounded_to_1e-7, sys, prn): {obstype: value}} for G and E."""
    types, out, cur, cursys = {}, {}, None, None
    with open(path) as f:
        lines = f.read().split('\n')
    i = 0
    while 'END OF HEADER' not in lines[i]:
        ln = lines[i]
        if ln[60:79].strip() == 'SYS / # / OBS TYPES':
            if ln[0] != ' ':
                cursys = ln[0]
                types[cursys] = []
            types[cursys] += ln[7:60].split()
        i += 1
    for ln in lines[i + 1:]:
        if ln.startswith('>'):
            y, mo, d, h, mi = (int(v) for v in ln[2:18].split())
            sec = float(ln[18:29])
            cur = round(gps_seconds(y, mo, d, h, mi, 0.0) % 604800 + sec, 7)
            continue
        if len(ln) < 3 or ln[0] not in 'GE':
            continue
        vals = {}
        for k, t in enumerate(types[ln[0]]):
            f = ln[3 + 16 * k:17 + 16 * k]
            if f.strip():
                vals[t] = float(f)
        out[(cur, ln[0], int(ln[1:3]))] = vals
    return out


def gps_seconds(y, mo, d, h, mi, s):
    delta = datetime(y, mo, d, h, mi, int(s)) - GPS_EPOCH
    return delta.days * 86400 + delta.seconds + (s - int(s))


def adjweek(t, t0):
    while t - t0 > 302400.0:
        t -= 604800.0
    while t - t0 < -302400.0:
        t += 604800.0
    return t


def parse_nav3(path):
    """RINEX 3 mixed nav -> list of GPS/GAL/BDS eph dicts (absolute GPS seconds;
    integers here, so exact). Galileo toc/toe are used as GPST (RTKLIB does the
    same: GST is not shifted)."""
    with open(path) as f:
        lines = f.read().split('\n')
    i = 0
    while 'END OF HEADER' not in lines[i]:
        i += 1
    i += 1
    ephs = []
    while i < len(lines):
        l0 = lines[i]
        if not l0.strip():
            i += 1
            continue
        sys_ = l0[0]
        nlines = 4 if sys_ in 'RS' else 8
        if sys_ not in 'GEC':
            i += nlines
            continue
        prn = int(l0[1:3])
        y, mo, d, h, mi, s = (int(l0[4:8]), int(l0[9:11]), int(l0[12:14]), int(l0[15:17]),
                              int(l0[18:20]), float(l0[21:23]))
        v = [fnum(l0[23 + 19 * k:42 + 19 * k]) for k in range(3)]
        for k in range(1, 8):
            ln = lines[i + k].ljust(80)
            v += [fnum(ln[4 + 19 * c:23 + 19 * c]) for c in range(4)]
        line_no = i + 1
        i += 8
        toc = gps_seconds(y, mo, d, h, mi, s)
        af0, af1, af2 = v[0:3]
        (iode, crs, deln, M0, cuc, e, cus, sqrtA, toes, cic, OMG0, cis,
         i0, crc, omg, OMGd, idot, codes, week, _x, sva, svh, tgd0, tgd1,
         ttr) = v[3:28]
        if sys_ == 'C':          # BDT -> GPST (+14 s), only needed for the sort order
            toc += 14.0
            toe = adjweek((week + 1356) * 604800 + toes + 14.0, toc)
            ttrw = adjweek((week + 1356) * 604800 + ttr + 14.0, toc)
        else:
            toe = adjweek(week * 604800 + toes, toc)
            ttrw = adjweek(week * 604800 + ttr, toc)
        ephs.append(dict(sys=sys_, prn=prn, sat=(satno(sys_, prn) if sys_ in 'GE' else 1000 + prn),
                         line=line_no, toc=toc, toe=toe, ttr=ttrw, toes=toes,
                         f0=af0, f1=af1, f2=af2, iode=int(iode), crs=crs, deln=deln, M0=M0,
                         cuc=cuc, e=e, cus=cus, A=sqrtA * sqrtA, cic=cic, OMG0=OMG0, cis=cis,
                         i0=i0, crc=crc, omg=omg, OMGd=OMGd, idot=idot, code=int(codes),
                         svh=int(svh), sva=sva, tgd0=tgd0, tgd1=tgd1))
    return ephs


def uniqeph(ephs):
    """RTKLIB uniqeph(): sort by (ttr, toe, sat), drop consecutive (sat, iode) repeats."""
    s = sorted(ephs, key=lambda q: (math.floor(q['ttr']), math.floor(q['toe']), q['sat']))
    out, dropped = [], []
    for q in s:
        if out and out[-1]['sat'] == q['sat'] and out[-1]['iode'] == q['iode']:
            dropped.append((q, out[-1]))
            continue
        out.append(q)
    return out, dropped


def seleph(ephs, sys_, sat, teph_abs):
    tmax = MAXDTOE + 1.0 if sys_ == 'G' else MAXDTOE_GAL_MIN
    tmin, j = tmax + 1.0, None
    for q in ephs:
        if q['sat'] != sat:
            continue
        if sys_ == 'E':
            if not (q['code'] & (1 << 9)):     # default sel=0: I/NAV only
                continue
            if q['toe'] - teph_abs >= 0.0:     # AOD <= 0
                continue
        t = abs(q['toe'] - teph_abs)
        if t > tmax:
            continue
        if t <= tmin:
            j, tmin = q, t
    return j


def hms(tow):
    tow %= 86400
    return '%02d:%02d:%02d' % (tow // 3600, tow % 3600 // 60, tow % 60)


def main():
    args = sys.argv[1:]
    report = '--report' in args
    if report:
        args.remove('--report')
    obsd = None
    if '--obs' in args:
        k = args.index('--obs')
        obsd = parse_obs3(args[k + 1])
        del args[k:k + 2]
    pcheck = {}
    trace, navf, outcsv = args
    epochs = parse_trace(trace)
    allephs = parse_nav3(navf)
    ephs, dropped = uniqeph(allephs)

    rows, chosen = [], {}
    stat = {'G': [0, 0.0, 0.0, 0.0], 'E': [0, 0.0, 0.0, 0.0]}   # n, dtx, dpos, dclk(ns)
    alt = []
    for ep in epochs:
        week, tow = cal2gps(ep['time'])
        if len(ep['rs']) != len(ep['obs']):
            sys.exit('trace parse error at ' + ep['time'])
        for (sys_, prn, P1, P2), r in zip(ep['obs'], ep['rs']):
            if r['sat'] != satno(sys_, prn):
                sys.exit('obs/rs order mismatch at %s %s%02d' % (ep['time'], sys_, prn))
            if P1 == 0.0 and P2 == 0.0:
                continue
            if obsd is not None:
                o = obsd[(round(tow, 7), sys_, prn)]
                for slot, val in (('P[0]', P1), ('P[1]', P2)):
                    if val == 0.0:
                        continue
                    m = sorted(t for t, v in o.items() if t[0] == 'C' and abs(v - val) < 0.0006)
                    pcheck.setdefault((sys_, slot), set()).add(','.join(m) or 'NONE')
            pr = P1 if P1 != 0.0 else P2
            if P1 == 0.0:
                print('NOTE: %s%02d at %s: no P[0], tx time from P[1]' % (sys_, prn, ep['time']),
                      file=sys.stderr)
            q = seleph(ephs, sys_, r['sat'], week * 604800 + tow)
            if q is None:
                sys.exit('no ephemeris for %s%02d' % (sys_, prn))
            chosen.setdefault((sys_, prn), set()).add(q['line'])
            t1 = tow - pr / CLIGHT
            tx = t1 - eph2clk(t1, q, week)
            wtx, ttx_trace = cal2gps(r['ttx_str'])
            dtx = tx - (ttx_trace + (wtx - week) * 604800)
            if abs(dtx) > 0.5e-6 + 1e-9:
                print('WARNING tx mismatch', ep['time'], sys_, prn, dtx, file=sys.stderr)
            st = stat[sys_]
            st[0] += 1
            st[1] = max(st[1], abs(dtx))
            if report:
                rs, dts = eph2pos(tx, q, week)
                dp = max(abs(rs[0] - r['x']), abs(rs[1] - r['y']), abs(rs[2] - r['z']))
                st[2] = max(st[2], dp)
                st[3] = max(st[3], abs(dts * 1e9 - r['dts_ns']))
                # every other record of the same sat that seleph rejected / uniqeph dropped
                for o in allephs:
                    if o['sat'] == q['sat'] and o['line'] != q['line']:
                        tx_o = t1 - eph2clk(t1, o, week)
                        rs_o, dts_o = eph2pos(tx_o, o, week)
                        alt.append((sys_, prn, o['line'], o['code'],
                                    max(abs(rs_o[0] - r['x']), abs(rs_o[1] - r['y']), abs(rs_o[2] - r['z'])),
                                    abs(dts_o * 1e9 - r['dts_ns']), abs(tx_o - tx)))
            if r['svh'] != '00' or (r['x'] == 0.0 and r['y'] == 0.0):
                print('NOTE: svh/zero position', ep['time'], sys_, prn, r['svh'], file=sys.stderr)
            rows.append('%s,%d,%d,%.7f,%.10f,%s,%s,%s,%.12f' % (
                sys_, prn, week, tow, tx, r['x_s'], r['y_s'], r['z_s'], r['dts_ns'] * 1e-9))
    with open(outcsv, 'w') as f:
        f.write('sys,prn,week,tow_s,tx_tow_s,x_m,y_m,z_m,clk_s\n')
        f.write('\n'.join(rows) + '\n')

    print('epochs in trace: %d, rows written: %d (G %d, E %d)' % (
        len(epochs), len(rows), stat['G'][0], stat['E'][0]))
    for s in 'GE':
        print('%s: max |tx(recomputed) - tx(trace, 1 us)| = %.3e s' % (s, stat[s][1]))
    for (s_, slot), m in sorted(pcheck.items()):
        print('%s: trace %s equals RINEX obs type(s): %s' % (s_, slot, ' | '.join(sorted(m))))
    if not report:
        return
    print()
    print('uniqeph: %d GPS/GAL/BDS records read, %d kept' % (len(allephs), len(ephs)))
    for q, kept in dropped:
        print('  dropped: %s%02d nav line %d (data sources %d, ttr %d) - same sat/IOD as kept line %d '
              '(data sources %d, ttr %d)' % (q['sys'], q['prn'], q['line'], q['code'],
                                             q['ttr'] % 604800, kept['line'], kept['code'],
                                             kept['ttr'] % 604800))
    print()
    print('ephemeris used (same record at all epochs for every satellite):')
    print('  sat  navline  src  toe(sow)  toc(GPST/GST)  IOD  ttr     BGD_E5a/E1 / TGD   BGD_E5b/E1')
    byline = {q['line']: q for q in allephs}
    for key in sorted(chosen, key=lambda k: ('GE'.index(k[0]), k[1])):
        lines = chosen[key]
        for ln in sorted(lines):
            q = byline[ln]
            src = ('I/NAV' if q['code'] & (1 << 9) else 'F/NAV') if q['sys'] == 'E' else 'LNAV'
            print('  %s%02d  %5d  %5s %4s %8d  %s  %4d  %6d  %17.9e  %s' % (
                key[0], key[1], ln, src, q['code'] if q['sys'] == 'E' else '', q['toes'],
                hms(q['toc'] % 604800), q['iode'], q['ttr'] % 604800, q['tgd0'],
                '%.9e' % q['tgd1'] if q['sys'] == 'E' else ''))
        if len(lines) > 1:
            print('  WARNING: more than one record used for', key)
    print()
    print('independent eph2pos check (RTKLIB constants, chosen record, at tx_tow_s):')
    for s, name in (('G', 'GPS'), ('E', 'Galileo')):
        n, _, dp, dc = stat[s]
        print('  %-7s %3d sat-epochs: max |d pos| = %.4f m, max |d clk| = %.4f ns' % (name, n, dp, dc))
    if alt:
        print('records NOT used, evaluated the same way and compared with the trace '
              '(a wrong choice would be visible if min |d clk| >> 0.0005 ns):')
        seen = {}
        for sys_, prn, ln, code, dp, dc, dt in alt:
            k = (sys_, prn, ln, code)
            a = seen.setdefault(k, [0.0, 1e99, 0.0, 0.0])
            a[0], a[1], a[2], a[3] = max(a[0], dp), min(a[1], dc), max(a[2], dc), max(a[3], dt)
        for (sys_, prn, ln, code), (dp, dcmin, dcmax, dt) in sorted(seen.items()):
            print('  %s%02d nav line %d (data sources %d): max |d pos| = %.4f m, |d clk| = %.4f .. %.4f ns, '
                  'tx shift <= %.2e s' % (sys_, prn, ln, code, dp, dcmin, dcmax, dt))


if __name__ == '__main__':
    main()
