#!/usr/bin/env bash
# Runs the skylane libFuzzer targets on scratch copies of their seed corpora.
#
#   fuzz/run_fuzzers.sh [build-dir] [seconds-per-target] [target ...]
#
# Defaults: build-fuzz, 60 s, every target. Work files go to $SKYLANE_FUZZ_WORK
# (default /tmp/skylane-fuzz): <target>/corpus (grows), <target>/artifacts (crash-*, timeout-*,
# oom-*), <target>/log. The repository is only read. Exits non-zero if any target found something
# or is missing; a target whose seed files are missing runs from an empty corpus (said on stderr)
# and never stops the targets after it.
# Extra libFuzzer flags can be passed in $SKYLANE_FUZZ_ARGS (e.g. "-jobs=2 -workers=2").
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build-fuzz}"
seconds="${2:-60}"
shift $(( $# > 2 ? 2 : $# ))
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(yuma sem rinex_nav rinex_obs geometry text_fields zones buildings fence scenario mission nmea track mavlink ubx service nats)
work="${SKYLANE_FUZZ_WORK:-/tmp/skylane-fuzz}"
data="$root/tests/data"
shopt -s nullglob  # a pattern that matches nothing is no file (not the pattern itself)

# Copies the files given (those that exist) into the corpus folder; says so when there is none.
copy_seeds() {  # corpus-dir file...
  local c="$1" f n=0
  shift
  for f in "$@"; do
    [ -f "$f" ] || continue
    cp "$f" "$c"/
    n=$((n + 1))
  done
  [ $n -gt 0 ] || echo "   note: no seed files for $(basename "$(dirname "$c")"); it starts from an empty corpus" >&2
}

note_if_empty() {  # corpus-dir
  [ -n "$(ls -A "$1")" ] || echo "   note: no seed files for $(basename "$(dirname "$1")"); it starts from an empty corpus" >&2
}

# Header plus the first `records` lines after END OF HEADER: small seeds mutate faster.
head_after_header() {  # file lines-after-header
  local n
  n=$(grep -n "END OF HEADER" "$1" | head -1 | cut -d: -f1 || true)
  [ -n "$n" ] || return 0
  head -n $(( n + $2 )) "$1"
}

seed() {  # target corpus-dir
  local t="$1" c="$2" f
  case "$t" in
    # The almanac and RINEX files are seeded cut short only (the whole files are replayed by the
    # fuzz_replay tests): libFuzzer takes -max_len from the largest seed and mutates and re-parses
    # whole inputs, so one 270 kB navigation file held fuzz_rinex_nav at ~100 exec/s (cov 702 after
    # 20 s) where the cut seeds alone run ~7,000 exec/s (cov 768 after 20 s); likewise rinex_obs
    # (118 kB) and yuma (18 kB). The cut files keep every header line.
    yuma)
      for f in "$data"/gnss/*.txt; do head -n 28 "$f" > "$c/2rec_$(basename "$f")"; done
      note_if_empty "$c" ;;
    rinex_nav)
      for f in "$data"/gnss/*.05n "$data"/gnss/*.06N "$data"/gnss/*.10n "$data"/rinex3/*MN.rnx; do
        head_after_header "$f" 24 > "$c/3rec_$(basename "$f")"
      done
      note_if_empty "$c" ;;
    rinex_obs)
      for f in "$data"/gnss/*.05o "$data"/rinex3/*MO.rnx; do
        head_after_header "$f" 40 > "$c/short_$(basename "$f")"
      done
      note_if_empty "$c" ;;
    zones) copy_seeds "$c" "$data"/geozones/*.json "$data"/geozones/*.geojson "$data"/geozones/*.plan ;;
    buildings) copy_seeds "$c" "$root"/fuzz/corpus/buildings/* "$root"/examples/skymask/*.geojson ;;
    sem | geometry | text_fields | fence | scenario | nmea | mission | track | mavlink | ubx | service | nats)
      copy_seeds "$c" "$root"/fuzz/corpus/"$t"/* ;;
    *) echo "unknown target $t" >&2; return 1 ;;
  esac
}

status=0
for t in "${targets[@]}"; do
  exe="$build/fuzz/fuzz_$t"
  if [ ! -x "$exe" ]; then
    echo "== fuzz_$t: missing $exe (build it first); the other targets go on" >&2
    status=1
    continue
  fi
  rm -rf "${work:?}/$t"
  mkdir -p "$work/$t/corpus" "$work/$t/artifacts"
  if ! seed "$t" "$work/$t/corpus"; then
    status=1
    continue
  fi
  echo "== fuzz_$t: $seconds s, $(find "$work/$t/corpus" -type f | wc -l) seeds"
  extra=()
  [ "$t" = geometry ] && extra+=(-dict="$root/fuzz/geometry.dict")
  set +e
  # shellcheck disable=SC2086  # SKYLANE_FUZZ_ARGS is a list of flags
  "$exe" "$work/$t/corpus" -max_total_time="$seconds" -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$work/$t/artifacts/" "${extra[@]}" ${SKYLANE_FUZZ_ARGS:-} > "$work/$t/log" 2>&1
  rc=$?
  set -e
  grep -E "^#[0-9]+[[:space:]]+(DONE|NEW|REDUCE|pulse)" "$work/$t/log" | tail -1 || true
  grep -E "^stat::(number_of_executed_units|average_exec_per_sec)" "$work/$t/log" || true
  if [ $rc -ne 0 ]; then
    status=1
    echo "   FINDING (exit $rc): $(ls "$work/$t/artifacts")"
    grep -m3 -E "ERROR: |runtime error|skylane fuzz:" "$work/$t/log" || true
  fi
done
exit $status
