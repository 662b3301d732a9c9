#!/usr/bin/env bash
# prefetch_kept.sh CXX SOURCE INCLUDE_DIR...: compiles SOURCE to assembly at -O2 and -O3 and
# fails unless every envmis_prefetch_* function in it holds a prefetch instruction.
set -euo pipefail
cxx=$1 source=$2
shift 2
includes=()
for dir in "$@"; do includes+=("-I$dir"); done
functions=$(grep -o 'envmis_prefetch_[a-z_]*' "$source" | sort -u)
if [ "$(wc -w <<<"$functions")" -ne 4 ]; then
  echo "expected 4 envmis_prefetch_* functions in $source, found: $functions" >&2
  exit 1
fi
failed=0
for level in -O2 -O3; do
  # Unwind tables mark each function's end (.cfi_endproc) on every target.
  asm=$("$cxx" -std=c++20 "$level" -DNDEBUG -fasynchronous-unwind-tables "${includes[@]}" -S -o - "$source")
  for f in $functions; do
    count=$(awk -v name="$f" '$1 == name ":" || $1 == "_" name ":" { inside = 1; next }
                              inside && /\.cfi_endproc/ { exit }
                              inside && /^[ \t]+prefetch/ { n++ }
                              END { print n + 0 }' <<<"$asm")
    if [ "$count" -eq 0 ]; then
      echo "$f ($level): no prefetch instruction left" >&2
      failed=1
    else
      echo "$f ($level): $count prefetch instructions"
    fi
  done
done
exit $failed
