#!/usr/bin/env bash
# Start-up of skylane's commands beside RTKLIB's rnx2rtkp, in one run: wall time (hyperfine,
# median) and peak resident memory (GNU time's %M, median), for each command that reads no
# raster, `integrity spp` on every RINEX pair in tests/data beside `rnx2rtkp -p 0` on the same
# files, and a short `fence check` of the bundled example.
#
# Needs: a built skylane, and Debian's packages hyperfine, rtklib (rnx2rtkp), time
# (/usr/bin/time) and python3.
#
# Usage: bench/startup.sh [SKYLANE [BASELINE_SKYLANE]]
#   SKYLANE            the binary to measure (default build/skylane)
#   BASELINE_SKYLANE   another build to measure side by side in the same run (e.g. main's)
# Environment: RUNS (hyperfine runs per command, default 30), RSS_RUNS (default 9).
set -euo pipefail
cd "$(dirname "$0")/.."
for tool in hyperfine rnx2rtkp /usr/bin/time python3; do
  command -v "$tool" >/dev/null || { echo "startup.sh: $tool is missing (apt-get install hyperfine rtklib time python3)" >&2; exit 2; }
done
SK=${1:-build/skylane}
BASE=${2:-}
RUNS=${RUNS:-30}
RSS_RUNS=${RSS_RUNS:-9}
OUT=$(mktemp -d /tmp/skylane_startup.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
D=tests/data

# name | arguments (skylane's, or rnx2rtkp's for the rtklib rows)
ROWS=(
  "--help|--help"
  "--version|--version"
  "approve --help|approve --help"
  "track --help|track --help"
  "serve --help|serve --help"
  "integrity spp 0759|integrity spp --obs $D/gnss/07590920.05o --nav $D/gnss/07590920.05n -o $OUT/spp.jsonl"
  "integrity spp 3040|integrity spp --obs $D/gnss/30400920.05o --nav $D/gnss/30400920.05n -o $OUT/spp.jsonl"
  "integrity spp rinex3|integrity spp --obs $D/rinex3/base_20240624_MO.rnx --nav $D/rinex3/base_20240624_MN.rnx -o $OUT/spp.jsonl"
  "zones validate|zones validate examples/fence/zones_ed269.json"
  "fence check (example)|fence check --corridor examples/fence/corridor.json --zones examples/fence/zones_ed269.json --ground-amsl 408 --fixes examples/fence/fixes.jsonl"
)
RTK_ROWS=(
  "rnx2rtkp -? (help)|-?"
  "rnx2rtkp -p 0 0759|-p 0 -o $OUT/rtk.pos $D/gnss/07590920.05o $D/gnss/07590920.05n"
  "rnx2rtkp -p 0 3040|-p 0 -o $OUT/rtk.pos $D/gnss/30400920.05o $D/gnss/30400920.05n"
  "rnx2rtkp -p 0 rinex3|-p 0 -o $OUT/rtk.pos $D/rinex3/base_20240624_MO.rnx $D/rinex3/base_20240624_MN.rnx"
)

# Every command line, labelled "<binary label>: <row name>".
labels=() cmds=()
for row in "${ROWS[@]}"; do
  name=${row%%|*} args=${row#*|}
  labels+=("skylane: $name") cmds+=("$SK $args")
  if [[ -n $BASE ]]; then labels+=("baseline: $name") cmds+=("$BASE $args"); fi
done
for row in "${RTK_ROWS[@]}"; do
  labels+=("${row%%|*}") cmds+=("rnx2rtkp ${row#*|}")
done

# Peak RSS, the commands interleaved run by run (GNU time writes %M in KiB to its -o file).
for ((r = 0; r < RSS_RUNS; ++r)); do
  for i in "${!cmds[@]}"; do
    # shellcheck disable=SC2086
    /usr/bin/time -f %M -a -o "$OUT/rss_$i" ${cmds[$i]} >/dev/null 2>&1 || true
  done
done

# Wall time: one hyperfine run over every command (-N: no shell in between).
hf_args=()
for i in "${!cmds[@]}"; do hf_args+=(-n "${labels[$i]}" "${cmds[$i]}"); done
hyperfine -N -i --warmup 3 --runs "$RUNS" --export-json "$OUT/times.json" "${hf_args[@]}" >/dev/null 2>"$OUT/hyperfine.err" ||
  { cat "$OUT/hyperfine.err" >&2; exit 1; }

echo "Machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) vCPU; load average $(cut -d' ' -f1-3 /proc/loadavg); $(date -u +%Y-%m-%dT%H:%MZ)"
echo "skylane: $SK${BASE:+; baseline: $BASE}; $RUNS hyperfine runs, $RSS_RUNS RSS runs per command"
python3 - "$OUT" "${#cmds[@]}" <<'PY'
import json, statistics, sys
out, n = sys.argv[1], int(sys.argv[2])
res = json.load(open(f"{out}/times.json"))["results"]
print("| command | wall median [ms] | min [ms] | peak RSS median [MiB] |")
print("|---|---|---|---|")
for i in range(n):
    r = res[i]
    try:
        rss = [int(x) for x in open(f"{out}/rss_{i}").read().split() if x.isdigit()]
    except FileNotFoundError:
        rss = []
    rss_mib = f"{statistics.median(rss) / 1024:.1f}" if rss else "?"
    print(f"| {r['command']} | {r['median'] * 1e3:.1f} | {r['min'] * 1e3:.1f} | {rss_mib} |")
PY
