#!/usr/bin/env bash
# Lists the functions longer than MAX lines (default 80) in the library folders and cli/,
# longest first, one per line as `LINES path:line Class::name`; exits 1 if there is any.
# A lambda counts toward the function that encloses it (ctags tags only named functions,
# and their line span covers the lambda's body).
# Needs universal-ctags (scripts/setup.sh installs it).
# Usage: scripts/long_functions.sh [MAX]
set -euo pipefail
cd "$(dirname "$0")/.."

max="${1:-80}"
if ! [[ "$max" =~ ^[0-9]+$ ]]; then
  echo "long_functions: MAX must be a whole number of lines, got '$max'" >&2
  exit 2
fi
if ! ctags --version 2>/dev/null | grep -q "Universal Ctags"; then
  echo "long_functions: needs universal-ctags (apt-get install universal-ctags)" >&2
  exit 2
fi

dirs=()
for d in maps airspace integrity geofence planner link service cli; do
  [ -d "$d" ] && dirs+=("$d")
done
[ ${#dirs[@]} -eq 0 ] && exit 0

# u-ctags lines with --excmd=number read:
#   name<TAB>path<TAB>line;"<TAB>f<TAB>line:N<TAB>[scope:...]<TAB>...<TAB>end:M
# A function defined out of its class carries `class:ns::Class` (or struct/union); only the
# type part is kept: namespaces are lower case and types PascalCase (STYLE.md, Naming).
offenders="$(
  ctags -R --languages=C++ --kinds-C++=f --fields=+neZ --excmd=number --sort=no \
        --output-format=u-ctags -f - "${dirs[@]}" |
  awk -F'\t' -v max="$max" '
    /^!_/ { next }
    $1 ~ /^__anon/ { next }   # a lambda: its lines already count toward its function
    {
      name = $1; path = $2; start = 0; stop = 0; owner = ""
      for (i = 4; i <= NF; i++) {
        if ($i ~ /^line:[0-9]+$/) start = substr($i, 6) + 0
        else if ($i ~ /^end:[0-9]+$/) stop = substr($i, 5) + 0
        else if ($i ~ /^scope:(class|struct|union):/) {
          owner = $i
          sub(/^scope:(class|struct|union):/, "", owner)
          n = split(owner, part, "::")
          owner = ""
          for (j = 1; j <= n; j++) {
            if (owner == "" && part[j] !~ /^[A-Z]/) continue
            owner = owner part[j] "::"
          }
        }
      }
      if (start == 0 || stop == 0) next
      lines = stop - start + 1
      if (lines > max) printf "%d %s:%d %s%s\n", lines, path, start, owner, name
    }' |
  LC_ALL=C sort -k1,1nr -k2,2
)"

if [ -n "$offenders" ]; then
  printf '%s\n' "$offenders"
  exit 1
fi
exit 0
