#!/usr/bin/env bash
# `skylane fence check` end to end: JSON lines in, verdict JSON lines out, at 1,000 zones
# (issue 22). Generates a 10 km corridor with 1,000 circular ED-269 zones beside it and N fixes
# along it (seeded, so both binaries read the same bytes), then runs each binary ROUNDS times,
# interleaved (A B A B …), reading the fixes from a file and writing the verdicts to a file, and
# prints fixes per second of wall time and of CPU time (user + sys) for each run and the median.
# The verdict files of the two binaries are compared: they must be identical.
# Usage: bench/fence_check_stream.sh BINARY_A [BINARY_B] [N_FIXES=200000] [ROUNDS=5]
set -euo pipefail
A="$1"
B="${2:-}"
N="${3:-200000}"
ROUNDS="${4:-5}"
WORK="${TMPDIR:-/tmp}/skylane-fence-stream"
mkdir -p "$WORK"

python3 - "$WORK" "$N" <<'EOF'
import json, math, random, sys
work, n = sys.argv[1], int(sys.argv[2])
rng = random.Random(2026)
lat0, lon0 = 47.30, 8.45
dlat = lambda m: m / 111195.0
dlon = lambda m: m / (111195.0 * math.cos(math.radians(lat0)))
# Corridor: 10 km west-east with a dog-leg every 2 km, 500-560 m ellipsoidal.
path = [{"lat": lat0 + dlat(150 * (i % 2)), "lon": lon0 + dlon(2000 * i), "h_ell_m": 520.0 + 10 * (i % 3)} for i in range(6)]
json.dump({"path": path, "vehicle": {"lateral_m": 1.5, "longitudinal_m": 1.2, "height_m": 0.5}, "k1": 1.2, "k2": 300,
           "operating_limits": {"floor_h_ell_m": 450.0, "ceiling_h_ell_m": 650.0}}, open(f"{work}/corridor.json", "w"))
zones = []
for i in range(1000):
    x, y = rng.uniform(-500, 10500), rng.uniform(-1500, 1500)
    zones.append({"identifier": f"BENCH-{i}", "country": "CHE", "name": f"zone {i}", "type": "COMMON",
                  "restriction": "PROHIBITED", "reason": ["OTHER"], "applicability": [{"permanent": "YES"}],
                  "geometry": [{"uomDimensions": "M", "lowerLimit": 0, "lowerVerticalReference": "AGL", "upperLimit": 150,
                                "upperVerticalReference": "AGL",
                                "horizontalProjection": {"type": "Circle", "center": [lon0 + dlon(x), lat0 + dlat(y)],
                                                         "radius": rng.uniform(20, 80)}}]})
json.dump({"formatVersion": "1.0.0", "UASZoneList": zones}, open(f"{work}/zones.json", "w"))
with open(f"{work}/fixes.jsonl", "w") as f:
    for k in range(n):
        s = 10000.0 * k / n
        leg = min(int(s // 2000), 4)
        t = (s - 2000 * leg) / 2000
        y = 150 * ((leg % 2) * (1 - t) + ((leg + 1) % 2) * t) + rng.gauss(0, 3)
        sec = k // 10
        f.write(json.dumps({"id": k, "time": f"2026-11-23T12:{(sec // 60) % 60:02d}:{sec % 60:02d}.{(k % 10) * 100:03d}Z",
                            "lat": round(lat0 + dlat(y), 8), "lon": round(lon0 + dlon(s + rng.gauss(0, 3)), 8),
                            "h_ell_m": round(525 + rng.gauss(0, 2), 3), "hpl_m": round(rng.uniform(0.5, 3), 3),
                            "vpl_m": round(rng.uniform(0.5, 3), 3)}, separators=(",", ":")) + "\n")
EOF

run() {  # binary out_file → "wall_s cpu_s"
  local start end
  # The previous run's 180 MB of verdicts are written back to disk first (untimed), so that the
  # kernel's writeback does not take a core from this run.
  sync
  start=$(date +%s.%N)
  /usr/bin/time -o "$WORK/time" -f "%U %S" "$1" fence check --corridor "$WORK/corridor.json" --zones "$WORK/zones.json" \
    --ground-amsl 400 --fixes "$WORK/fixes.jsonl" >"$2" 2>/dev/null
  end=$(date +%s.%N)
  echo "$(echo "$end - $start" | bc) $(awk '{print $1 + $2}' "$WORK/time")"
}

declare -A WALL CPU
for r in $(seq 1 "$ROUNDS"); do
  for who in A B; do
    bin="${!who}"
    [ -z "$bin" ] && continue
    read -r w c < <(run "$bin" "$WORK/out_$who.jsonl")
    WALL[$who]+="$w "
    CPU[$who]+="$c "
    printf '%s round %d: %8.0f fixes/s wall, %8.0f fixes/s CPU\n' "$who" "$r" "$(echo "$N / $w" | bc -l)" "$(echo "$N / $c" | bc -l)"
  done
done
median() { tr ' ' '\n' | grep -v '^$' | sort -g | awk '{a[NR]=$1} END {print a[int((NR + 1) / 2)]}'; }
for who in A B; do
  bin="${!who}"
  [ -z "$bin" ] && continue
  w=$(echo "${WALL[$who]}" | median)
  c=$(echo "${CPU[$who]}" | median)
  printf '%s %s: median %8.0f fixes/s wall, %8.0f fixes/s CPU (%d fixes, 1,000 zones)\n' "$who" "$bin" \
    "$(echo "$N / $w" | bc -l)" "$(echo "$N / $c" | bc -l)" "$N"
done
if [ -n "$B" ]; then
  if cmp -s "$WORK/out_A.jsonl" "$WORK/out_B.jsonl"; then echo "verdicts identical"; else echo "verdicts DIFFER"; exit 1; fi
fi
