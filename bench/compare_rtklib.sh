#!/usr/bin/env bash
# Times `skylane integrity spp` against RTKLIB's `rnx2rtkp -p 0` on the same station-3040
# files in one hyperfine run (needs Debian's rtklib and hyperfine packages and a built skylane).
set -euo pipefail
cd "$(dirname "$0")/.."
D=tests/data/gnss
hyperfine -N --warmup 5 --runs 100 \
  "build/skylane integrity spp --obs $D/30400920.05o --nav $D/30400920.05n -o /tmp/skylane_spp.jsonl" \
  "rnx2rtkp -p 0 -o /tmp/rtklib_spp.pos $D/30400920.05o $D/30400920.05n"
