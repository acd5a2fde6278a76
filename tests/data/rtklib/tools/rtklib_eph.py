"""Broadcast-ephemeris arithmetic as RTKLIB 2.4.3 does it, shared by extract_satpos.py (RINEX 2,
GPS) and extract_satpos_rinex3.py (RINEX 3, GPS + Galileo)."""
import math
from datetime import datetime

CLIGHT = 299792458.0
MU_GPS = 3.9860050E14
MU_GAL = 3.986004418E14
OMGE = 7.2921151467E-5         # RTKLIB OMGE (GPS) == OMGE_GAL
GPS_EPOCH = datetime(1980, 1, 6)


def cal2gps(s):
    """'YYYY/MM/DD hh:mm:ss.ffff' -> (week, tow) with exact decimal parsing."""
    d, t = s.split()
    y, mo, dd = (int(v) for v in d.split('/'))
    hh, mm, ss = t.split(':')
    sec_int, _, frac = ss.partition('.')
    delta = datetime(y, mo, dd, int(hh), int(mm), int(sec_int)) - GPS_EPOCH
    secs = delta.days * 86400 + delta.seconds
    week = secs // 604800
    return week, secs - week * 604800 + (float('0.' + frac) if frac else 0.0)


def fnum(s):
    s = s.strip().replace('D', 'E').replace('d', 'e')
    return float(s) if s else 0.0


# All evaluation in seconds of week of the epoch (wk0). Absolute GPS seconds (~8e8) must not
# carry fractions in a double (ulp ~1.2e-7 s); eph toc/toe/ttr are integers, so
# (toc - wk0*604800) is exact and 1e-10 s resolution is kept.
def eph2clk(t, q, wk0):
    # verbatim RTKLIB 2.4.3 eph2clk(): t -= f0+f1*t+f2*t^2 twice (cumulative),
    # then evaluate; the result equals af0+af1*t+af2*t^2 to <1e-17 s.
    tt = t - (q['toc'] - wk0 * 604800)
    for _ in range(2):
        tt -= q['f0'] + q['f1'] * tt + q['f2'] * tt * tt
    return q['f0'] + q['f1'] * tt + q['f2'] * tt * tt


def eph2pos(t, q, wk0):
    """RTKLIB eph2pos(): ECEF position and clock (with the relativistic term) at t; the
    gravitational constant by system (q['sys'], GPS when absent)."""
    mu = MU_GAL if q.get('sys', 'G') == 'E' else MU_GPS
    tk = t - (q['toe'] - wk0 * 604800)
    A, e = q['A'], q['e']
    M = q['M0'] + (math.sqrt(mu / (A * A * A)) + q['deln']) * tk
    E, Ek, n = M, 0.0, 0
    while abs(E - Ek) > 1e-13 and n < 30:
        Ek = E
        E -= (E - e * math.sin(E) - M) / (1.0 - e * math.cos(E))
        n += 1
    sinE, cosE = math.sin(E), math.cos(E)
    u = math.atan2(math.sqrt(1.0 - e * e) * sinE, cosE - e) + q['omg']
    r = A * (1.0 - e * cosE)
    i = q['i0'] + q['idot'] * tk
    sin2u, cos2u = math.sin(2 * u), math.cos(2 * u)
    u += q['cus'] * sin2u + q['cuc'] * cos2u
    r += q['crs'] * sin2u + q['crc'] * cos2u
    i += q['cis'] * sin2u + q['cic'] * cos2u
    x, y, cosi = r * math.cos(u), r * math.sin(u), math.cos(i)
    O = q['OMG0'] + (q['OMGd'] - OMGE) * tk - OMGE * q['toes']
    sinO, cosO = math.sin(O), math.cos(O)
    rs = (x * cosO - y * cosi * sinO, x * sinO + y * cosi * cosO, y * math.sin(i))
    tc = t - (q['toc'] - wk0 * 604800)
    dts = q['f0'] + q['f1'] * tc + q['f2'] * tc * tc
    dts -= 2.0 * math.sqrt(mu * A) * e * sinE / (CLIGHT * CLIGHT)
    return rs, dts
