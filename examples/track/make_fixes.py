#!/usr/bin/env python3
"""Writes the live-tracking example's inputs from an approval report (skylane approve --out DIR):
fixes.jsonl (one flight with a noisy fix, a PL excursion, a drift, a hover, a gap and bad lines)
and fixes.nmea (the first 20 s as GGA + GST + RMC sentences). Usage: make_fixes.py REPORT OUTDIR"""
import json
import math
import sys

report = json.load(open(sys.argv[1]))
out = sys.argv[2]
route = report["route"]
R = 6378137.0


def along(t):
    """lat, lon, h_ell on the approved route t seconds after departure."""
    for a, b in zip(route, route[1:]):
        if t <= b["eta_s"]:
            f = (t - a["eta_s"]) / (b["eta_s"] - a["eta_s"])
            return [a[k] + f * (b[k] - a[k]) for k in ("lat", "lon", "h_ell_m")]
    return [route[-1][k] for k in ("lat", "lon", "h_ell_m")]


# Left of the first segment, as a unit vector (east, north).
de = (route[1]["lon"] - route[0]["lon"]) * math.cos(math.radians(route[0]["lat"]))
dn = route[1]["lat"] - route[0]["lat"]
n = math.hypot(de, dn)
left = (-dn / n, de / n)


def offset(p, metres):
    lat, lon, h = p
    return [lat + math.degrees(metres * left[1] / R),
            lon + math.degrees(metres * left[0] / (R * math.cos(math.radians(lat)))), h]


def stamp(t):
    return "2020-01-01T14:%02d:%02dZ" % (t // 60, t % 60)


lines = []
drift_at = None
for t in range(0, 41):
    p = along(t)
    hpl, vpl = 0.5, 0.6  # an RTK + INS solution's onboard protection levels
    if t == 12:
        p = offset(p, 3.0)  # one noisy fix: a violation, no replan
    if 25 <= t <= 27:
        hpl = 2.0  # the PL alone exceeds HAL1 = 1.44 m: reported, not replanned
    if 30 <= t <= 32:
        p = offset(p, 6.0)  # pushed 6 m left by a gust: the third such fix (3 of 5) replans
        drift_at = p
    if t > 32:
        p = drift_at  # hovering where the new corridor starts, waiting for it
    lines.append(json.dumps({"flight": "zrh", "time": stamp(t), "lat": round(p[0], 8), "lon": round(p[1], 8),
                             "h_ell_m": round(p[2], 3), "hpl_m": hpl, "vpl_m": vpl}))
# a 6 s gap (the flight is reported stale), then bad records, each reported and skipped
p = drift_at
lines.append(json.dumps({"flight": "zrh", "time": stamp(47), "lat": p[0], "lon": p[1], "h_ell_m": p[2], "hpl_m": 0.5, "vpl_m": 0.6}))
lines.append(lines[-1])  # duplicated
lines.append(json.dumps({"flight": "zrh", "time": stamp(44), "lat": p[0], "lon": p[1], "h_ell_m": p[2], "hpl_m": 0.5, "vpl_m": 0.6}))
lines.append('{"flight": "zrh", "time": "2020-01-01T14:00:48Z", "lat": 47.37')  # truncated
lines.append(json.dumps({"flight": "zrh-2", "time": stamp(48), "lat": p[0], "lon": p[1], "h_ell_m": p[2], "hpl_m": 0.5, "vpl_m": 0.6}))
lines.append(json.dumps({"flight": "zrh", "time": stamp(49), "lat": p[0], "lon": p[1], "h_ell_m": p[2], "hpl_m": -1, "vpl_m": 0.6}))
with open(out + "/fixes.jsonl", "w") as f:
    f.write("\n".join(lines) + "\n")


def nmea(body):
    x = 0
    for ch in body:
        x ^= ord(ch)
    return "$%s*%02X" % (body, x)


def angle(deg, lat):
    a = abs(deg)
    d = int(a)
    text = ("%02d" if lat else "%03d") % d + "%010.7f" % ((a - d) * 60.0)
    return text + "," + ("N" if deg >= 0 else "S") if lat else text + "," + ("E" if deg >= 0 else "W")


GEOID = 47.35  # the receiver's geoid separation at Zurich (EGM96: about 47.4 m)
with open(out + "/fixes.nmea", "w") as f:
    for t in range(0, 20):
        lat, lon, h = along(t)
        hms = "14%02d%05.2f" % (t // 60, t % 60)
        f.write(nmea("GPRMC,%s,A,%s,%s,0.0,0.0,010120,,,D" % (hms, angle(lat, True), angle(lon, False))) + "\r\n")
        f.write(nmea("GPGGA,%s,%s,%s,4,14,0.7,%.3f,M,%.2f,M,1.0,0001" % (hms, angle(lat, True), angle(lon, False), h - GEOID, GEOID)) + "\r\n")
        f.write(nmea("GPGST,%s,0.6,0.070,0.050,35.0,0.060,0.055,0.110" % hms) + "\r\n")
        f.write(nmea("GPGSV,1,1,04,05,60,045,45,12,35,120,42,21,20,260,38,29,70,300,47") + "\r\n")
