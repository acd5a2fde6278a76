#!/usr/bin/env bash
# Installs, builds and runs the main job on the bundled example: integrity prediction at the
# GSI station 3040 (Japan) from a real almanac, and RAIM single-point positioning on the
# station's real RINEX files. Results go to examples/out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p examples/out
EX=examples/predict
./build/skylane integrity predict --almanac "$EX/alm01jan2020.txt" \
  --lat 35.132066 --lon 139.624302 --alt 75.8 \
  --start 2020-01-01T00:00:00Z --duration 24h --step 5m --mask-deg 5 \
  --output examples/out/predict.csv --plot examples/out/predict.svg
./build/skylane integrity pl --geometry "$EX/geometry.json" --verbose > examples/out/pl.json
./build/skylane integrity spp --obs tests/data/gnss/30400920.05o --nav tests/data/gnss/30400920.05n \
  --output examples/out/spp_3040.jsonl
./build/skylane integrity availability --almanac tests/data/gnss/alm_gps_ed259.txt \
  --almanac tests/data/gnss/alm_gal_ed259.txt --grid-deg 5 --duration 24h --step 10m \
  --output examples/out/availability.csv --map examples/out/availability.svg
./build/skylane zones validate examples/zones/geo-awareness-che-1.json > examples/out/zones_validate.txt
./build/skylane zones at examples/zones/geo-awareness-che-1.json --lat 46.430758 --lon 6.913146 \
  --height-agl 50 --time 2022-06-18T18:00:00Z > examples/out/zones_at.json
./build/skylane zones export examples/zones/geo-awareness-che-1.json --to geojson -o examples/out/zones.geojson
echo "--- one geometry (examples/out/pl.json):"
head -12 examples/out/pl.json
echo "--- prediction (examples/out/predict.csv, plot examples/out/predict.svg):"
head -4 examples/out/predict.csv
awk -F, 'NR>1{n++; a+=$9; if($7>m)m=$7} END{printf "%d epochs, %.1f %% available, max HPL %.1f m\n", n, 100*a/n, m}' examples/out/predict.csv
echo "--- single-point positioning with RAIM (examples/out/spp_3040.jsonl):"
wc -l < examples/out/spp_3040.jsonl
echo "--- geozones (examples/out/zones_validate.txt, zones_at.json, zones.geojson):"
tail -1 examples/out/zones_validate.txt
grep -E '"(zone|why)"' examples/out/zones_at.json
./build/skylane skymask --lat 47.3769 --lon 8.5417 --height-agl 1.5 --ground-amsl 408 \
  --buildings examples/skymask/buildings.geojson --svg examples/out/skymask.svg > examples/out/skymask.json
echo "--- sky mask among buildings (examples/out/skymask.json, plot examples/out/skymask.svg):"
python3 -c 'import json; j=json.load(open("examples/out/skymask.json")); print(j["buildings"]["count"], "buildings; highest blocked elevation", j["max_blocked_elevation_deg"], "deg")'
./build/skylane fence check --corridor examples/fence/corridor.json --zones examples/fence/zones_ed269.json \
  --ground-amsl 408 --buildings examples/skymask/buildings.geojson --fixes examples/fence/fixes.jsonl \
  > examples/out/fence.jsonl
echo "--- fence check (examples/out/fence.jsonl):"
python3 -c 'import json
for l in open("examples/out/fence.jsonl"):
    j = json.loads(l)
    print(j.get("id", "line %d" % j["line"]), j.get("verdict", j.get("event")), j.get("violated") or "")'
echo "--- GNSS/INS simulation, seed 001's experiments (examples/out/simulate/<scenario>/: epochs.csv,"
echo "    errors_and_pls.svg, stanford_horizontal.svg, stanford_vertical.svg):"
for s in no_fault accel_fault sat_10sigma sat_20sigma combined; do
  ./build/skylane simulate examples/simulate/seed001_$s.json --out examples/out/simulate/$s | grep -v '^skylane: simulate: wrote'
done
echo "--- preflight approval (examples/out/approve/: report.json, route.geojson, operational_intent.json, map.svg, pl.svg):"
./build/skylane approve examples/approve/mission.json --out examples/out/approve > /dev/null
python3 -c 'import json; j=json.load(open("examples/out/approve/report.json")); print(j["decision"], "-", round(j["planner"]["length_m"]), "m,", len(j["predicted"]), "samples, max HPL", max(p["hpl_m"] for p in j["predicted"]), "m, zones:", ", ".join("%s %.0f m" % (z["id"], z["min_clearance_m"]) for z in j["zones"]))'
echo "--- a mission that is rejected (examples/out/approve_rejected/):"
./build/skylane approve examples/approve/mission_rejected.json --out examples/out/approve_rejected > /dev/null || true
python3 -c 'import json; j=json.load(open("examples/out/approve_rejected/report.json")); print(j["decision"], "-", j["reasons"][0]["message"])'
echo "--- live corridor tracking of the approved flight (examples/out/track/: events.jsonl, track.svg, track.sqlite):"
mkdir -p examples/out/track
rm -f examples/out/track/track.sqlite*
python3 examples/track/make_fixes.py examples/out/approve/report.json examples/out/track
./build/skylane track --approval zrh=examples/out/approve/report.json --input examples/out/track/fixes.jsonl \
  --db examples/out/track/track.sqlite --map examples/out/track/track.svg > examples/out/track/events.jsonl 2> examples/out/track/stderr.txt
tail -1 examples/out/track/stderr.txt
python3 -c 'import json
for l in open("examples/out/track/events.jsonl"):
    e = json.loads(l)
    if e["event"] == "fix": continue
    print(" ", e["event"], "line", e.get("line", "-"), e.get("level", e.get("trigger", "")), e.get("cause", e.get("decision", "")), (e.get("error") or "")[:70])'
./build/skylane track --approval zrh=examples/out/approve/report.json --format nmea --input examples/out/track/fixes.nmea \
  > examples/out/track/events_nmea.jsonl 2> /dev/null
echo "  NMEA (GGA + GST + RMC) replay: $(grep -c '"verdict":"inside"' examples/out/track/events_nmea.jsonl) of $(wc -l < examples/out/track/events_nmea.jsonl) fixes inside"
echo "--- GNSS/INS tracking rehearsal: a 40 m survey drone flown by the simulator (skylane fly: tactical IMU, a 60 m step on G20 at 60-120 s,"
echo "    an accelerometer step at 140 s), tracked from its raw pseudoranges and IMU increments (examples/out/track_gnss_ins/):"
mkdir -p examples/out/track_gnss_ins
./build/skylane approve examples/track/gnss_ins/mission.json --out examples/out/track_gnss_ins/approve > /dev/null
./build/skylane fly examples/out/track_gnss_ins/approve/report.json --out examples/out/track_gnss_ins/fixes.jsonl --imu tactical \
  --faults examples/track/gnss_ins/faults.json --seed 3 --flight uav --truth examples/out/track_gnss_ins/truth.csv
./build/skylane track --approval uav=examples/out/track_gnss_ins/approve/report.json --input examples/out/track_gnss_ins/fixes.jsonl \
  --map examples/out/track_gnss_ins/track.svg > examples/out/track_gnss_ins/events.jsonl 2> /dev/null
python3 - <<'PY'
import csv, json, math
d = "examples/out/track_gnss_ins/"
truth = {int(r["line"]): r for r in csv.DictReader(open(d + "truth.csv"))}
fixes = [e for e in map(json.loads, open(d + "events.jsonl")) if e["event"] == "fix"]
def ratio(e):
    t = truth[e["line"]]
    n = math.radians(e["lat"] - float(t["lat_deg"])) * 6371000.0
    east = math.radians(e["lon"] - float(t["lon_deg"])) * 6371000.0 * math.cos(math.radians(e["lat"]))
    return max(math.hypot(n, east) / e["hpl_m"], abs(e["h_ell_m"] - float(t["h_ell_m"])) / e["vpl_m"])
src = {}
for e in fixes: src[e["pl_source"]] = src.get(e["pl_source"], 0) + 1
print("  %d fixes %s; inside: %d; G20 excluded at %d; GNSS alone after the IMU fault at %d; worst error/PL %.2f"
      % (len(fixes), src, sum(e["verdict"] == "inside" for e in fixes), sum("G20" in e.get("excluded", []) for e in fixes),
         sum(e.get("ins_degraded", False) for e in fixes), max(map(ratio, fixes))))
PY
