#!/usr/bin/env bash
# Runs the main job on the bundled example with an already built skylane (no install, no build):
# integrity prediction at the GSI station 3040 (Japan) from a real almanac, RAIM single-point
# positioning on its real RINEX files, zones, the fence, the GNSS/INS simulation, preflight
# approval, live tracking and a GNSS/INS tracking rehearsal.
# Usage: scripts/run_example.sh [SKYLANE_BINARY] [OUT_DIR]   (defaults: build/skylane, examples/out)
set -euo pipefail
cd "$(dirname "$0")/.."
SKYLANE="${1:-./build/skylane}"
export OUT="${2:-examples/out}"
mkdir -p "$OUT"
EX=examples/predict
"$SKYLANE" integrity predict --almanac "$EX/alm01jan2020.txt" \
  --lat 35.132066 --lon 139.624302 --alt 75.8 \
  --start 2020-01-01T00:00:00Z --duration 24h --step 5m --mask-deg 5 \
  --output "$OUT"/predict.csv --plot "$OUT"/predict.svg
"$SKYLANE" integrity pl --geometry "$EX/geometry.json" --verbose > "$OUT"/pl.json
"$SKYLANE" integrity spp --obs tests/data/gnss/30400920.05o --nav tests/data/gnss/30400920.05n \
  --output "$OUT"/spp_3040.jsonl
"$SKYLANE" integrity availability --almanac tests/data/gnss/alm_gps_ed259.txt \
  --almanac tests/data/gnss/alm_gal_ed259.txt --grid-deg 5 --duration 24h --step 10m \
  --output "$OUT"/availability.csv --map "$OUT"/availability.svg
"$SKYLANE" zones validate examples/zones/geo-awareness-che-1.json > "$OUT"/zones_validate.txt
"$SKYLANE" zones at examples/zones/geo-awareness-che-1.json --lat 46.430758 --lon 6.913146 \
  --height-agl 50 --time 2022-06-18T18:00:00Z > "$OUT"/zones_at.json
"$SKYLANE" zones export examples/zones/geo-awareness-che-1.json --to geojson -o "$OUT"/zones.geojson
echo "--- one geometry ("$OUT"/pl.json):"
head -12 "$OUT"/pl.json
echo "--- prediction ("$OUT"/predict.csv, plot "$OUT"/predict.svg):"
head -4 "$OUT"/predict.csv
awk -F, 'NR>1{n++; a+=$9; if($7>m)m=$7} END{printf "%d epochs, %.1f %% available, max HPL %.1f m\n", n, 100*a/n, m}' "$OUT"/predict.csv
echo "--- single-point positioning with RAIM ("$OUT"/spp_3040.jsonl):"
wc -l < "$OUT"/spp_3040.jsonl
echo "--- geozones ("$OUT"/zones_validate.txt, zones_at.json, zones.geojson):"
tail -1 "$OUT"/zones_validate.txt
grep -E '"(zone|why)"' "$OUT"/zones_at.json
"$SKYLANE" skymask --lat 47.3769 --lon 8.5417 --height-agl 1.5 --ground-amsl 408 \
  --buildings examples/skymask/buildings.geojson --svg "$OUT"/skymask.svg > "$OUT"/skymask.json
echo "--- sky mask among buildings ("$OUT"/skymask.json, plot "$OUT"/skymask.svg):"
python3 -c 'import json, os; j=json.load(open(os.environ["OUT"] + "/skymask.json")); print(j["buildings"]["count"], "buildings; highest blocked elevation", j["max_blocked_elevation_deg"], "deg")'
"$SKYLANE" fence check --corridor examples/fence/corridor.json --zones examples/fence/zones_ed269.json \
  --ground-amsl 408 --buildings examples/skymask/buildings.geojson --fixes examples/fence/fixes.jsonl \
  > "$OUT"/fence.jsonl
echo "--- fence check ("$OUT"/fence.jsonl):"
python3 -c 'import json, os
for l in open(os.environ["OUT"] + "/fence.jsonl"):
    j = json.loads(l)
    print(j.get("id", "line %d" % j["line"]), j.get("verdict", j.get("event")), j.get("violated") or "")'
echo "--- GNSS/INS simulation, the fault-mode experiments of Zhao & Song 2024 ("$OUT"/simulate/<scenario>/: epochs.csv,"
echo "    errors_and_pls.svg, stanford_horizontal.svg, stanford_vertical.svg):"
for s in no_fault accel_fault sat_10sigma sat_20sigma combined; do
  "$SKYLANE" simulate examples/simulate/gnss_ins_$s.json --out "$OUT"/simulate/$s | grep -v '^skylane: simulate: wrote'
done
echo "--- preflight approval ("$OUT"/approve/: report.json, route.geojson, operational_intent.json, mission.plan, map.svg, pl.svg):"
"$SKYLANE" approve examples/approve/mission.json --out "$OUT"/approve > /dev/null
python3 -c 'import json, os; j=json.load(open(os.environ["OUT"] + "/approve/report.json")); print(j["decision"], "-", round(j["planner"]["length_m"]), "m,", len(j["predicted"]), "samples, max HPL", max(p["hpl_m"] for p in j["predicted"]), "m, zones:", ", ".join("%s %.0f m" % (z["id"], z["min_clearance_m"]) for z in j["zones"]))'
echo "--- a mission that is rejected ("$OUT"/approve_rejected/):"
"$SKYLANE" approve examples/approve/mission_rejected.json --out "$OUT"/approve_rejected > /dev/null || true
python3 -c 'import json, os; j=json.load(open(os.environ["OUT"] + "/approve_rejected/report.json")); print(j["decision"], "-", j["reasons"][0]["message"])'
echo "--- the same run inside the operator's QGroundControl site fence, a keep-in zone ("$OUT"/approve_keep_in/):"
"$SKYLANE" approve examples/approve/mission_keep_in.json --out "$OUT"/approve_keep_in > /dev/null
python3 -c 'import json, os; j=json.load(open(os.environ["OUT"] + "/approve_keep_in/report.json")); print(j["decision"], "-", round(j["planner"]["length_m"]), "m round the fence corner at", ", ".join("(%.5f, %.5f)" % (p["lat"], p["lon"]) for p in j["route"][1:-1]))'
echo "--- the same run for an operator whose policy requires the corridor held at 95 % of the route ("$OUT"/approve_level1_policy/):"
"$SKYLANE" approve examples/approve/mission_level1_policy.json --out "$OUT"/approve_level1_policy > /dev/null 2>&1 || true
python3 -c 'import json, os; j=json.load(open(os.environ["OUT"] + "/approve_level1_policy/report.json")); print(j["decision"], "-", j["reasons"][0]["message"])'
echo "--- live corridor tracking of the approved flight ("$OUT"/track/: events.jsonl, track.svg, track.sqlite):"
mkdir -p "$OUT"/track
rm -f "$OUT"/track/track.sqlite*
python3 examples/track/make_fixes.py "$OUT"/approve/report.json "$OUT"/track
"$SKYLANE" track --approval zrh="$OUT"/approve/report.json --input "$OUT"/track/fixes.jsonl \
  --db "$OUT"/track/track.sqlite --map "$OUT"/track/track.svg > "$OUT"/track/events.jsonl 2> "$OUT"/track/stderr.txt
tail -1 "$OUT"/track/stderr.txt
python3 -c 'import json, os
for l in open(os.environ["OUT"] + "/track/events.jsonl"):
    e = json.loads(l)
    if e["event"] == "fix": continue
    print(" ", e["event"], "line", e.get("line", "-"), e.get("level", e.get("trigger", "")), e.get("cause", e.get("decision", "")), (e.get("error") or "")[:70])'
"$SKYLANE" track --approval zrh="$OUT"/approve/report.json --format nmea --input "$OUT"/track/fixes.nmea \
  > "$OUT"/track/events_nmea.jsonl 2> /dev/null
echo "  NMEA (GGA + GST + RMC) replay: $(grep -c '"verdict":"inside"' "$OUT"/track/events_nmea.jsonl) of $(wc -l < "$OUT"/track/events_nmea.jsonl) fixes inside"
echo "--- GNSS/INS tracking rehearsal: a 40 m survey drone flown by the simulator (skylane fly: tactical IMU, a 60 m step on G20 at 60-120 s,"
echo "    an accelerometer step at 140 s), tracked from its raw pseudoranges and IMU increments ("$OUT"/track_gnss_ins/):"
mkdir -p "$OUT"/track_gnss_ins
"$SKYLANE" approve examples/track/gnss_ins/mission.json --out "$OUT"/track_gnss_ins/approve > /dev/null
"$SKYLANE" fly "$OUT"/track_gnss_ins/approve/report.json --out "$OUT"/track_gnss_ins/fixes.jsonl --imu tactical \
  --faults examples/track/gnss_ins/faults.json --seed 3 --flight uav --truth "$OUT"/track_gnss_ins/truth.csv
"$SKYLANE" track --approval uav="$OUT"/track_gnss_ins/approve/report.json --input "$OUT"/track_gnss_ins/fixes.jsonl \
  --map "$OUT"/track_gnss_ins/track.svg > "$OUT"/track_gnss_ins/events.jsonl 2> /dev/null
python3 - <<'PY'
import csv, json, math, os
d = os.environ["OUT"] + "/track_gnss_ins/"
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
