#!/usr/bin/env bash
# prefetch_kept.sh CXX INCLUDE_DIR SOURCE: compiles SOURCE to assembly at -O2 and -O3 and
# fails unless every envmis_prefetch_* function in it holds a prefetch instruction.
set -euo pipefail
cxx=$1 include=$2 source=$3
failed=0
for level in -O2 -O3; do
  asm=$("$cxx" -std=c++20 "$level" -DNDEBUG -I"$include" -S -o - "$source")
  for f in $(grep -o 'envmis_prefetch_[a-z_]*' "$source" | sort -u); do
    count=$(awk -v label="$f:" '$1 == label { inside = 1; next }
                                inside && /\.cfi_endproc/ { exit }
                                inside && /prefetch/ { n++ }
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
