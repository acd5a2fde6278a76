#!/bin/sh
# Regenerate the RTKLIB reference data in tests/data/rtklib/.
# Requires Debian package rtklib 2.4.3.b34 (rnx2rtkp) and python3 (no numpy).
# Traces (~1.5 MB / 37 MB) go to a scratch dir and are NOT kept in the repo.
# Set TIMING=1 to also run the hyperfine benchmark (needs `hyperfine`),
# KEEP_TRACES=1 to keep the scratch dir with the *.trace files.
set -eu
HERE=$(cd "$(dirname "$0")/.." && pwd)          # tests/data/rtklib
D=${RINEX_DIR:-/work/shared/data/gnss/rinex}
W=$(mktemp -d /tmp/rtklib_ref.XXXXXX)
CONF="$HERE/spp_brdc_saas.conf"
cd "$W"

# 1+2. SPP with broadcast Klobuchar iono + Saastamoinen tropo (via -k), ECEF output,
#      level-4 trace (satellite positions/clocks at transmission time).
rnx2rtkp -k "$CONF" -p 0 -e -x 4 -o "$W/spp_3040.pos" "$D/30400920.05o" "$D/30400920.05n" 2>/dev/null
rnx2rtkp -k "$CONF" -p 0 -e -x 4 -o "$W/spp_0759.pos" "$D/07590920.05o" "$D/07590920.05n" 2>/dev/null
rnx2rtkp -k "$CONF" -p 0 -e -x 4 -o "$W/spp_uslo.pos" "$D/Uslo3610.06O" "$D/Uslo3610.06N" 2>/dev/null
# USLO solutions kept in the repo only every 300 s (SPP is epoch-by-epoch, identical values)
rnx2rtkp -k "$CONF" -p 0 -e -ti 300 -o "$W/spp_uslo_300s.pos" "$D/Uslo3610.06O" "$D/Uslo3610.06N" 2>/dev/null

# Plain command-line defaults (NO iono, NO tropo correction in rnx2rtkp 2.4.3 b34!)
rnx2rtkp -p 0 -e -d 6 -o "$W/spp_3040_cli_default.pos" "$D/30400920.05o" "$D/30400920.05n" 2>/dev/null
rnx2rtkp -p 0 -e -d 6 -o "$W/spp_0759_cli_default.pos" "$D/07590920.05o" "$D/07590920.05n" 2>/dev/null

cp spp_3040.pos spp_0759.pos spp_uslo_300s.pos spp_3040_cli_default.pos spp_0759_cli_default.pos "$HERE/"

# Satellite positions/clocks from the traces (every 20th epoch = 10 min + last epoch;
# USLO every 120th epoch = 1 h + last epoch)
python3 "$HERE/tools/extract_satpos.py" --report spp_3040.pos.trace "$D/30400920.05n" "$HERE/sat_positions_3040.csv"
python3 "$HERE/tools/extract_satpos.py" --report spp_0759.pos.trace "$D/07590920.05n" "$HERE/sat_positions_0759.csv"
python3 "$HERE/tools/extract_satpos.py" --report --every 120 spp_uslo.pos.trace "$D/Uslo3610.06N" "$HERE/sat_positions_uslo.csv"

# SPP error summary vs RINEX header position
python3 "$HERE/tools/spp_summary.py" \
  3040 "$HERE/spp_3040.pos" "$D/30400920.05o" \
  0759 "$HERE/spp_0759.pos" "$D/07590920.05o" \
  "USLO (300 s subset)" "$HERE/spp_uslo_300s.pos" "$D/Uslo3610.06O" \
  "USLO (all 30 s epochs, file not kept)" "$W/spp_uslo.pos" "$D/Uslo3610.06O" \
  "3040 rnx2rtkp CLI defaults: NO iono/tropo" "$HERE/spp_3040_cli_default.pos" "$D/30400920.05o" \
  "0759 rnx2rtkp CLI defaults: NO iono/tropo" "$HERE/spp_0759_cli_default.pos" "$D/07590920.05o" \
  > "$HERE/spp_summary.txt"

if [ "${TIMING:-0}" = 1 ]; then
  hyperfine -N --warmup 5 --runs 100 --export-json "$W/hf.json" \
    -n 'rnx2rtkp -p 0 (CLI defaults)' "rnx2rtkp -p 0 -e -o $W/hf_a.pos $D/30400920.05o $D/30400920.05n" \
    -n 'rnx2rtkp -k spp_brdc_saas.conf -p 0' "rnx2rtkp -k $CONF -p 0 -e -o $W/hf_b.pos $D/30400920.05o $D/30400920.05n"
fi
if [ "${KEEP_TRACES:-0}" = 1 ]; then echo "scratch (traces kept): $W"; else rm -rf "$W"; fi
