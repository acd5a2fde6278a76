#!/usr/bin/env bash
# Build gshhg_crude_coastlines.txt (simple "> / lon lat" ring format) from
# GSHHG crude-resolution shorelines via GMT.
# Needs: apt-get install -y gmt gmt-gshhg-low
# Usage: ./make_coast.sh [MIN_AREA_KM2]   (default 5000)
set -euo pipefail
cd "$(dirname "$0")"

MIN_AREA=${1:-5000}
OUT=gshhg_crude_coastlines.txt  # the file cli/svg_plot.cpp draws (embedded at build time)

# 1. Dump level-1 (land/ocean) crude shorelines as multisegment ASCII.
#    GMT emits one piece per 20x20-degree storage bin.
DUMP_CMD="gmt coast -Rd -Dc -W -M -A${MIN_AREA}/1/1"
# 2. Re-join the bin pieces whose end points match (Cartesian lon/lat, so
#    pieces ending at lon=+180 and lon=-180 are NOT joined across the dateline).
JOIN_CMD="gmt connect -fc -T0.001"

$DUMP_CMD > raw.txt
$JOIN_CMD raw.txt > joined.txt

GSHHG_VER=$($DUMP_CMD -V 2>&1 >/dev/null | sed -n 's/.*GSHHG version \([0-9.]*\).*/\1/p' | head -1)
PKG_VER=$(dpkg-query -W -f='${Version}' gmt-gshhg-low)
GMT_VER=$(gmt --version)

{
  echo "# World coastlines from GSHHG (Global Self-consistent Hierarchical High-resolution Geography)"
  echo "# Authors: Paul Wessel and Walter H. F. Smith. https://www.soest.hawaii.edu/pwessel/gshhg/"
  echo "# License: LGPL-3.0-or-later"
  echo "# Source: GSHHG version ${GSHHG_VER}, Debian package gmt-gshhg-low version ${PKG_VER} (read with GMT ${GMT_VER})"
  echo "# Resolution: crude (c); level 1 only (land/ocean boundary, no lakes); min area ${MIN_AREA} km^2; Antarctica = ice front (GMT default)"
  echo "# Generated with: ${DUMP_CMD} | ${JOIN_CMD} | awk (make_coast.sh: round to 2 decimals, drop consecutive duplicates)"
  echo "# Format: a line '>' starts a new ring; then 'lon lat' per line, degrees, lon in [-180,180]."
  echo "# Rings cut by GMT at the dateline are open (both ends on lon=+180 or both on lon=-180);"
  echo "# Antarctica is one open line from lon=180 to lon=-180 (close via (-180,-90),(180,-90) to fill)."
} > "$OUT"

awk '
function fmt(v,   s) {
  s = sprintf("%.2f", v)
  sub(/0+$/, "", s); sub(/\.$/, "", s)
  if (s == "-0") s = "0"
  return s
}
function flush(   i) {
  if (n >= 2) { print ">"; for (i = 1; i <= n; i++) print X[i], Y[i] }
  else if (n == 1) dropped++
  n = 0
}
/^#/ { next }
/^>/ { flush(); next }
NF >= 2 {
  lon = $1 + 0; lat = $2 + 0
  while (lon > 180) lon -= 360
  while (lon < -180) lon += 360
  x = fmt(lon); y = fmt(lat)
  if (n > 0 && x == X[n] && y == Y[n]) next          # consecutive duplicate
  if (n > 0 && ((x - X[n]) > 180 || (X[n] - x) > 180)) { # dateline jump: split
    flush(); splits++
  }
  n++; X[n] = x; Y[n] = y
}
END {
  flush()
  printf "splits at >180 deg jumps: %d; degenerate rings dropped: %d\n", splits + 0, dropped + 0 > "/dev/stderr"
}' joined.txt >> "$OUT"

rings=$(grep -c '^>' "$OUT")
points=$(grep -vc -e '^>' -e '^#' "$OUT")
echo "$OUT: $(stat -c %s "$OUT") bytes, $rings rings, $points points" >&2
