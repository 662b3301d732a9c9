#!/usr/bin/env bash
# scripts/check_layers.sh finds each kind of breach (ctest: layers.breaches_are_found): in a
# copy of the sources, a study file that includes a private header of envmis::core, a core
# math header that includes the later table stage, and envmis::build including study.
# Usage: bash breach_found.sh SOURCE_ROOT
set -euo pipefail
root=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/python"
cp -r "$root/lib" "$root/apps" "$work/"
cp -r "$root/python/src" "$work/python/"
mkdir -p "$work/scripts"
cp "$root/scripts/check_layers.sh" "$work/scripts/"
echo '#include "detail/mapped_file.h"' >>"$work/lib/study/src/shading/bsdf.cpp"
echo '#include "envmis/table/table.h"' >>"$work/lib/core/include/envmis/math/hash.h"
echo '#include "envmis/study/shading/bsdf.h"' >>"$work/lib/build/src/remap.cpp"
if output=$(bash "$work/scripts/check_layers.sh" "$work" 2>&1); then
    echo "check_layers.sh passed sources with three breaches:" && echo "$output" && exit 1
fi
for expected in "bsdf.cpp:.*a private header of envmis::core" \
    "hash.h:.*stage math includes the later stage table" \
    "remap.cpp:.*envmis::build does not link envmis::study"; do
    grep -qE "$expected" <<<"$output" || { echo "missing: $expected in:" && echo "$output" && exit 1; }
done
echo "check_layers.sh found all three breaches"
