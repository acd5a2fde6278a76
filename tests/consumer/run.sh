#!/usr/bin/env bash
# The installed package works for another project: installs skylane from BUILD_DIR into a
# scratch prefix, configures and builds tests/consumer against it (find_package(skylane)), runs
# the consumer on the example geometry and mission, and checks its numbers against the skylane
# command's own (`integrity pl --method araim`, `approve`) and the corridor margin HAL − HPL.
# Usage: tests/consumer/run.sh BUILD_DIR
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="$(cd "$1" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/skylane-consumer-XXXXXX")"
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
cmake -S "$here" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" -j 2 >/dev/null
geometry="$root/examples/predict/geometry.json"
mission="$root/examples/approve/mission.json"
"$work/build/consumer" "$geometry" "$mission" > "$work/consumer.json"
"$work/prefix/bin/skylane" integrity pl --geometry "$geometry" --method araim > "$work/pl.json"
set +e
"$work/prefix/bin/skylane" approve "$mission" > "$work/report.json" 2>/dev/null
approve_rc=$?
set -e
python3 - "$work/consumer.json" "$work/pl.json" "$work/report.json" "$approve_rc" <<'PY'
import json, sys
c = json.load(open(sys.argv[1])); pl = json.load(open(sys.argv[2])); report = json.load(open(sys.argv[3]))
print("consumer:", c)
assert abs(c["hpl_m"] - pl["hpl_m"]) < 1e-3, (c["hpl_m"], pl["hpl_m"])
assert abs(c["vpl_m"] - pl["vpl_m"]) < 1e-3, (c["vpl_m"], pl["vpl_m"])
assert abs(c["margin_h_m"] - (50.0 - c["hpl_m"])) < 1e-6, c
assert c["corridor"] == ("inside" if c["hpl_m"] < 50.0 and c["vpl_m"] < 50.0 else "outside"), c
assert c["approved"] == (report["decision"] == "approved") == (sys.argv[4] == "0"), (c, report["decision"])
print("consumer: the installed package gives the command's numbers")
PY
