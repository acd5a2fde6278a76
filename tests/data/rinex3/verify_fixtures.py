#!/usr/bin/env python3
"""Self-check of the RINEX 3 fixtures in this folder (stdlib only).

Not part of the build.  Run:  python3 verify_fixtures.py
It checks
  * the column layout of both files against RINEX 3.04
    (nav: SV/epoch line A1,I2.2,1X,I4,5(1X,I2.2),3D19.12 and data lines
    4X,4D19.12; obs: epoch line '>' ... and A3 + n*(F14.3,I1,I1)),
  * internal consistency of the observations (carrier phase vs Doppler,
    code vs carrier between consecutive 1 s epochs, SNR quantised to 1/32 dB),
  * toe == time of clock and week number of every GPS/Galileo record,
  * the broadcast orbits against the pseudoranges of the first epoch
    (residuals must look like uncorrected iono + troposphere only),
and prints the reference values quoted in README.md.
"""
import datetime as dt
import math
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
NAV = os.path.join(HERE, "base_20240624_MN.rnx")
OBS = os.path.join(HERE, "base_20240624_MO.rnx")
C = 299792458.0
GPS0 = dt.datetime(1980, 1, 6)


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


# ----------------------------------------------------------------- obs ----
def read_obs(path):
    lines = open(path).read().split("\n")
    if lines[-1] == "":
        lines.pop()
    types, cur, i, glo = {}, None, 0, {}
    while True:
        l = lines[i]
        if len(l) != 80:
            fail(f"obs header line {i+1} is {len(l)} chars")
        lab = l[60:].strip()
        if lab == "SYS / # / OBS TYPES":
            if l[0] != " ":
                cur = l[0]
                types[cur] = []
                declared = int(l[3:6])
            types[cur] += [l[7 + 4 * k:10 + 4 * k].strip() for k in range(13)
                           if l[7 + 4 * k:10 + 4 * k].strip()]
        if lab == "GLONASS SLOT / FRQ #":
            for k in range(8):
                s = l[4 + 7 * k:7 + 7 * k]
                if s.strip():
                    glo[s] = int(l[8 + 7 * k:10 + 7 * k])
        i += 1
        if lab == "END OF HEADER":
            break
    num = re.compile(r"^ *-?\d*\.\d{3}$")
    epochs = []
    while i < len(lines):
        l = lines[i]
        m = re.match(r"^> (\d{4}) (\d\d) (\d\d) (\d\d) (\d\d) ([ \d]\d\.\d{7})  (\d)([ \d]{3})$", l)
        if not m:
            fail(f"obs line {i+1}: bad epoch line {l!r}")
        ns = int(m.group(8))
        sats = {}
        for j in range(1, ns + 1):
            s = lines[i + j]
            sv, body = s[:3], s[3:]
            if not re.match(r"^[GRECJ]\d\d$", sv):
                fail(f"obs line {i+j+1}: bad SV {sv!r}")
            t = types[sv[0]]
            if body != body.rstrip() or len(body) > 16 * len(t):
                fail(f"obs line {i+j+1}: trailing blanks or too many fields")
            vals = {}
            for k, ot in enumerate(t):
                f = body[16 * k:16 * k + 16].ljust(16)
                if f[:14].strip():
                    if not num.match(f[:14]) or f[14] not in " 0123456789" or f[15] not in " 123456789":
                        fail(f"obs line {i+j+1}: field {ot} misaligned: {f!r}")
                    vals[ot] = float(f[:14])
                elif f[14:].strip():
                    fail(f"obs line {i+j+1}: flags without value in {ot}")
            sats[sv] = vals
        if len(sats) != ns:
            fail("duplicate satellite in epoch")
        epochs.append((l, sats))
        i += 1 + ns
    return types, glo, epochs


FREQ = {"G": {"1": 1575.42e6, "2": 1227.60e6, "5": 1176.45e6},
        "J": {"1": 1575.42e6, "2": 1227.60e6, "5": 1176.45e6},
        "E": {"1": 1575.42e6, "5": 1176.45e6, "7": 1207.14e6},
        "C": {"2": 1561.098e6, "7": 1207.14e6, "6": 1268.52e6}}


def wavelength(sv, band, glo):
    if sv[0] == "R":
        k = glo[sv]
        return C / (1602e6 + k * 0.5625e6 if band == "1" else 1246e6 + k * 0.4375e6)
    return C / FREQ[sv[0]][band]


def check_obs_physics(epochs, glo):
    worst_ld, worst_cl, n = 0.0, 0.0, 0
    for (_, a), (_, b) in zip(epochs, epochs[1:]):
        for sv in a:
            for t in a[sv]:
                if t[0] != "L" or sv not in b or t not in b[sv]:
                    continue
                dL = b[sv][t] - a[sv][t]
                D, Cc = "D" + t[1:], "C" + t[1:]
                if D in a[sv] and D in b[sv]:
                    worst_ld = max(worst_ld, abs(dL + (a[sv][D] + b[sv][D]) / 2)); n += 1
                if Cc in a[sv] and Cc in b[sv]:
                    r = (b[sv][Cc] - a[sv][Cc]) - dL * wavelength(sv, t[1], glo)
                    worst_cl = max(worst_cl, abs(r)); n += 1
    chans = {}
    for _, e in epochs:
        for sv, v in e.items():
            chans.setdefault(sv, set()).add(v.get("X1"))
    if any(len(c) != 1 for c in chans.values()):
        fail("X1 (channel number) changes within the file")
    snr_bad = [(sv, t) for _, e in epochs for sv, v in e.items() for t, x in v.items()
               if t[0] == "S" and abs(round(x * 32) / 32 - x) > 6e-4]
    print(f"obs: {n} epoch-to-epoch checks, max |dL+D| = {worst_ld:.2f} cycles, "
          f"max |dC-lambda*dL| = {worst_cl:.2f} m, SNR not k/32: {len(snr_bad)}, X1 constant per SV")
    if worst_ld > 2 or worst_cl > 5 or snr_bad:
        fail("observation consistency")


# ----------------------------------------------------------------- nav ----
D19 = r"[ -]\d\.\d{12}[ED][+-]\d\d"


def read_nav(path):
    L = open(path).read().split("\n")
    if L[-1] == "":
        L.pop()
    i = 0
    while "END OF HEADER" not in L[i]:
        if len(L[i]) != 80:
            fail(f"nav header line {i+1} is {len(L[i])} chars")
        i += 1
    i += 1
    recs = []
    while i < len(L):
        m = re.match(r"^([GERCJ]\d\d) (\d{4}) (\d\d) (\d\d) (\d\d) (\d\d) (\d\d)(" + D19 + ")(" + D19 + ")(" + D19 + ")$", L[i])
        if not m:
            fail(f"nav line {i+1}: bad SV/epoch line")
        sv = m.group(1)
        nl = 3 if sv[0] == "R" else 7
        rows = [[float(m.group(k).replace("D", "E")) for k in (8, 9, 10)]]
        for j in range(1, nl + 1):
            o = L[i + j]
            body = o[4:]
            if o[:4] != "    " or len(body) % 19 or not 1 <= len(body) // 19 <= 4:
                fail(f"nav line {i+j+1}: not 4X,nD19.12 ({len(o)} chars)")
            row = []
            for k in range(len(body) // 19):
                f = body[19 * k:19 * k + 19]
                if not re.fullmatch(D19, f):
                    fail(f"nav line {i+j+1}: bad field {f!r}")
                row.append(float(f.replace("D", "E")))
            rows.append(row)
        toc = dt.datetime(*[int(m.group(k)) for k in range(2, 8)])
        recs.append((sv, toc, rows, i + 1))
        i += 1 + nl
    return recs


def satpos(rows, t, sysc):
    """IS-GPS-200 / Galileo OS SIS ICD user algorithm; rows indexed by line."""
    mu = 3.986005e14 if sysc == "G" else 3.986004418e14
    we = 7.2921151467e-5
    af0, af1, af2 = rows[0]
    _, crs, dn, m0 = rows[1]
    cuc, e, cus, sqa = rows[2]
    toe, cic, om0, cis = rows[3]
    i0, crc, w, omd = rows[4]
    idot = rows[5][0]
    A = sqa * sqa
    tk = t - toe
    E = M = m0 + (math.sqrt(mu / A ** 3) + dn) * tk
    for _ in range(30):
        E = M + e * math.sin(E)
    nu = math.atan2(math.sqrt(1 - e * e) * math.sin(E), math.cos(E) - e)
    phi = nu + w
    s2, c2 = math.sin(2 * phi), math.cos(2 * phi)
    u = phi + cus * s2 + cuc * c2
    r = A * (1 - e * math.cos(E)) + crs * s2 + crc * c2
    inc = i0 + cis * s2 + cic * c2 + idot * tk
    om = om0 + (omd - we) * tk - we * toe
    x, y = r * math.cos(u), r * math.sin(u)
    X = x * math.cos(om) - y * math.cos(inc) * math.sin(om)
    Y = x * math.sin(om) + y * math.cos(inc) * math.cos(om)
    Z = y * math.sin(inc)
    dts = af0 + af1 * tk + af2 * tk * tk - 4.442807633e-10 * e * sqa * math.sin(E)
    return X, Y, Z, dts


def main():
    types, glo, epochs = read_obs(OBS)
    print("obs:", len(epochs), "epochs,", {k: len(v) for k, v in types.items()}, "obs types")
    check_obs_physics(epochs, glo)

    recs = read_nav(NAV)
    print("nav:", len(recs), "records:", " ".join(r[0] for r in recs))
    for sv, toc, rows, ln in recs:
        if sv[0] in "GE":
            wk, sow = divmod((toc - GPS0).total_seconds(), 604800)
            if rows[3][0] != sow or int(rows[5][2]) != int(wk):
                fail(f"{sv} line {ln}: toe/week do not match toc")
    print("nav: toe == toc and week field == GPS week for all GPS/Galileo records")

    rx = (-3817680.7270, 3562839.5216, 3650159.2407)       # APPROX POSITION XYZ
    lat = math.atan2(rx[2], math.hypot(rx[0], rx[1]) * (1 - 0.00669438))
    lon = math.atan2(rx[1], rx[0])
    up = (math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat))
    t0 = 86400 + 8 * 3600 + 20 * 60                           # 2024-06-24 08:20:00 GPST (SOW)
    first = epochs[0][1]
    res = []
    for sv, toc, rows, ln in recs:
        if sv[0] not in "GE" or sv not in first or (sv[0] == "E" and rows[5][1] != 517):
            continue
        pr = first[sv]["C1C"]
        X, Y, Z, dts = satpos(rows, t0 - pr / C, sv[0])
        a = 7.2921151467e-5 * pr / C                            # Sagnac rotation
        X, Y = X * math.cos(a) + Y * math.sin(a), -X * math.sin(a) + Y * math.cos(a)
        rng = math.dist((X, Y, Z), rx)
        el = math.degrees(math.asin(sum(u * (s - r) for u, s, r in zip(up, (X, Y, Z), rx)) / rng))
        res.append((sv, pr - rng + C * dts, el))
    med = sorted(r[1] for r in res)[len(res) // 2]
    print("first epoch: C1C - range + c*dts - median  (median = rx clock %.1f m)" % med)
    for sv, r, el in res:
        print(f"   {sv}  el {el:5.1f} deg  {r - med:7.1f} m")
    if max(abs(r - med) for _, r, _ in res) > 100:
        fail("broadcast orbit / pseudorange mismatch")

    for sv, toc, rows, ln in recs:
        if (sv, ln) in (("G06", 19), ("E04", 119)):
            X, Y, Z, dts = satpos(rows, rows[3][0], sv[0])
            print(f"{sv} (line {ln}) at t=toe={rows[3][0]:.0f}: X={X:.3f} Y={Y:.3f} Z={Z:.3f} m, dts={dts:.6e} s")
    print("OK")


if __name__ == "__main__":
    main()
