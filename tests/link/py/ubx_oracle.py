#!/usr/bin/python3
"""The independent side of skylane's UBX tests: frames built with gpsd's own UBX module
(python3-gps: gps.ubx.make_pkt, checksum) from payloads packed here field by field as the u-blox
interface description lays out UBX-NAV-PVT (92 bytes) and UBX-NAV-PL (52 bytes); and NAV-PVT
payloads decoded by gps.ubx for frames skylane wrote.
  ubx_oracle.py encode    one JSON line per frame: {kind, fields, hex}
  ubx_oracle.py decode    hex frames on stdin (one per line) -> gps.ubx's NAV-PVT decoding as JSON
"""
import json
import re
import struct
import sys

import gps.ubx

PVT = '<LHBBBBBBLlBBBBllllLLlllllLLHHLlhH'   # 92 bytes
PL = '<BBbBBBBBBBBBLLLLLLLHHL4s'             # 52 bytes


def pvt(itow, when, nano, fix_type, flags, num_sv, lon, lat, height, hmsl, h_acc, v_acc, valid=0x07):
    y, mo, d, h, mi, s = when
    return struct.pack(PVT, itow, y, mo, d, h, mi, s, valid, 30, nano, fix_type, flags, 0, num_sv, lon, lat, height, hmsl,
                       h_acc, v_acc, 0, 0, 0, 0, 0, 0, 0, 150, 0, 0, 0, 0, 0)


def pl(itow, coeff, exp, valid, frame, pl1, pl2, pl3, reason=0):
    return struct.pack(PL, 1, coeff, exp, valid, frame, 0, 0, 0, reason, 0, 0, 0, itow, pl1, pl2, pl3, 0, 0, 0, 4500, 0, 0,
                       b'\0\0\0\0')


def encode():
    u = gps.ubx.ubx()
    frames = [
        ('pvt', dict(itow=518418000, when=(2020, 1, 1, 14, 0, 0), nano=0, fix_type=3, flags=0x01, num_sv=14, lon=85400000,
                     lat=473700000, height=515321, hmsl=468012, h_acc=350, v_acc=520)),
        ('pl', dict(itow=518418000, coeff=1, exp=-5, valid=1, frame=3, pl1=2100, pl2=1400, pl3=3300)),
        ('pl', dict(itow=518419000, coeff=5, exp=-3, valid=1, frame=1, pl1=900, pl2=1200, pl3=2500)),
        ('pl', dict(itow=518420000, coeff=1, exp=-5, valid=0, frame=0, pl1=0, pl2=0, pl3=0, reason=12)),
    ]
    for kind, f in frames:
        payload = pvt(**f) if kind == 'pvt' else pl(**f)
        pkt = u.make_pkt(0x01, 0x07 if kind == 'pvt' else 0x62, payload)
        f = dict(f)
        if 'when' in f:
            f['when'] = list(f['when'])
        print(json.dumps({'kind': kind, 'fields': f, 'hex': bytes(pkt).hex()}))


def decode():
    u = gps.ubx.ubx()
    for line in sys.stdin:
        raw = bytes.fromhex(line.strip())
        ck = u.checksum(raw[2:], len(raw) - 4)
        ok = list(raw[-2:]) == ck
        text = u.nav_pvt(raw[6:-2])
        nums = dict((k, int(v)) for k, v in re.findall(r'\b(iTOW|lon|lat|height|hMSL|hAcc|vAcc|fixType|numSV|nano) (-?\d+)', text))
        print(json.dumps({'checksum_ok': ok, 'fields': nums}))


if __name__ == '__main__':
    {'encode': encode, 'decode': decode}[sys.argv[1]]()
