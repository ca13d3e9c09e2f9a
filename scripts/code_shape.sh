#!/usr/bin/env bash
# The shape of the code, as issue 26 measures it: lines per folder, the largest files, the
# functions over 60 and over 100 lines (lib/, tools/, procs/, logger/; tests and benches apart),
# the files in lib/ over 700 lines, and where library code reads the environment.
#
#   scripts/code_shape.sh [CHECKOUT]        (default: this checkout)
#
# Function lengths come from Universal Ctags (package universal-ctags): the lines from a
# function's first line to its closing brace, lambdas counted in the function that holds them.
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root"
command -v ctags >/dev/null || { echo "code_shape.sh: ctags not found (apt-get install universal-ctags)" >&2; exit 2; }

src_dirs="lib tools procs logger"
echo "## Lines per folder (.h and .cpp)"
for d in lib/* tools procs logger tests bench fuzz examples; do
  [ -d "$d" ] || continue
  n=$(find "$d" -name '*.h' -o -name '*.cpp' | xargs -r cat | wc -l)
  printf '%-22s %7d\n' "$d" "$n"
done
printf '%-22s %7d\n' "lib (all)" "$(find lib -name '*.h' -o -name '*.cpp' | xargs cat | wc -l)"

echo
echo "## The 15 largest files (lib, tools, procs, logger)"
find $src_dirs -name '*.h' -o -name '*.cpp' 2>/dev/null | xargs wc -l | grep -v ' total$' | sort -rn | head -15

echo
echo "## Files in lib/ over 700 lines"
find lib -name '*.h' -o -name '*.cpp' | xargs wc -l | grep -v ' total$' | awk '$1 > 700' | sort -rn || true

functions() {  # length file:line name, for every function with a known end
  find "$@" -name '*.h' -o -name '*.cpp' 2>/dev/null |
    xargs ctags --kinds-c++=f --fields=+ne -o - 2>/dev/null |
    awk -F'\t' '{ line = ""; end = "";
                  for (i = 4; i <= NF; i++) { if ($i ~ /^line:/) line = substr($i, 6); if ($i ~ /^end:/) end = substr($i, 5) }
                  if (line != "" && end != "") print end - line + 1, $2 ":" line, $1 }' |
    sort -rn
}
echo
echo "## Functions over 60 lines (lib, tools, procs, logger)"
all=$(functions $src_dirs)
over60=$(echo "$all" | awk '$1 > 60')
echo "$over60"
echo "count over 60: $(echo "$over60" | grep -c . || true); over 100: $(echo "$all" | awk '$1 > 100' | grep -c . || true)"
echo "  of them in lib/: over 60 $(echo "$over60" | grep -c ' lib/' || true), over 100 $(echo "$all" | awk '$1 > 100' | grep -c ' lib/' || true)"

echo
echo "## getenv in lib/"
grep -rn 'getenv' lib || echo "(none)"
