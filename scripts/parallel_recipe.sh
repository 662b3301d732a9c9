#!/usr/bin/env bash
# The GNU parallel recipe of docs/scale.md, run on this machine with local jobs: the
# three bundled maps made small, one `envmis compare MAP --json` per map through
# `parallel -j2`, merged by `envmis report --no-timing`, must give the same report, byte
# for byte, as one library-mode run (`envmis compare maps/ --out-dir`). --no-timing leaves
# out the only figures that differ between runs (ns/estimate, efficiency, the allocation
# section): the variances depend only on the map, the flags and the seed, not on the
# process or its threads. Exit 0 when equal, 1 with the diff (at most 60 lines) when not.
# Usage: scripts/parallel_recipe.sh [path/to/envmis]   (default build/apps/envmis)
set -euo pipefail
cd "$(dirname "$0")/.."
cli=$(realpath "${1:-build/apps/envmis}")
export OCIO=${OCIO:-$PWD/data/ocio/config.ocio}
command -v parallel > /dev/null || { echo "parallel_recipe: GNU parallel is not installed" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/maps" "$work/sharded"
for map in city.exr studio.exr rooitou_park_1k.hdr; do
    stem=${map%.*}
    "$cli" convert "data/envmaps/$map" -o "$work/maps/$stem.exr" --to equirect --size 48x24 > /dev/null
done
study=(--spp 64 --points 4 --bsdf lambert,phong:50 --seed 7)

# The recipe: a list of maps, one task each, then one report.
ls "$work"/maps/*.exr > "$work/maps.txt"
parallel -j2 --halt now,fail=1 "$cli" compare {} "${study[@]}" --json "$work/sharded/{/.}.json" '>' /dev/null \
    :::: "$work/maps.txt"
"$cli" report "$work"/sharded/*.json -o "$work/sharded.md" --no-timing > /dev/null

# The same maps in one process, library mode.
"$cli" compare "$work/maps" --out-dir "$work/single" --jobs 2 "${study[@]}" > /dev/null
"$cli" report "$work"/single/*.json -o "$work/single.md" --no-timing > /dev/null 2>&1

if ! diff -u "$work/single.md" "$work/sharded.md" > "$work/diff"; then
    echo "parallel_recipe: the sharded report differs from the single-process one:"
    head -n 60 "$work/diff"
    exit 1
fi
echo "parallel_recipe: the merged report of $(wc -l < "$work/maps.txt") sharded runs equals the single-process one"
