#!/usr/bin/env bash
# docs/scale.md's cluster recipes, run as written on this machine (ctest cli.scale_recipes):
# its code blocks are read from the document itself, with two substitutions only: the
# library's folders (/shared/hdris, /shared/out) become temporary ones, and --spp 4096 a
# small study. Slurm is emulated by an `sbatch` that runs the array's tasks one after
# another as Slurm would start them (SLURM_ARRAY_TASK_ID, SLURM_CPUS_PER_TASK from the
# script's #SBATCH line, --export's variables, the --output file, failing where its folder
# is missing); GNU parallel runs for real, with ":" (this machine) as the only SSH host.
# The slices past MaxArraySize, which the page gives in prose, run as it says with smaller
# arrays. Each recipe must leave one JSON per map (two .exr and one .hdr: the list must
# take both) and a report of them. Exit 0 when every recipe does, 1 naming the first that does not.
# Usage: scripts/scale_recipes.sh [path/to/envmis]   (default build/apps/envmis)
set -euo pipefail
cd "$(dirname "$0")/.."
cli=$(realpath "${1:-build/apps/envmis}")
doc=$PWD/docs/scale.md
export OCIO=${OCIO:-$PWD/data/ocio/config.ocio}
command -v parallel > /dev/null || { echo "scale_recipes: GNU parallel is not installed" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The recipes call `envmis` by name, as on a cluster's PATH.
mkdir -p "$work/bin" "$work/hdris"
ln -s "$cli" "$work/bin/envmis"
export PATH=$work/bin:$PATH
for map in city.exr studio.exr; do
    envmis convert "data/envmaps/$map" -o "$work/hdris/${map%.*}.exr" --to equirect --size 48x24 > /dev/null
done
python3 - "$work/hdris/sky.hdr" <<'PY'
import math, sys
width, height = 48, 24
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width))
    for y in range(height):
        for x in range(width):
            v = 0.1 + y / height + (50.0 if (x, y) == (10, 6) else 0.0)
            m, e = math.frexp(v)
            f.write(bytes([int(m * 256), int(m * 230), int(m * 200), e + 128]))
PY

# The n-th ```sh block under the heading that starts with `section`, the substitutions made.
block() {
    awk -v section="$1" -v n="$2" '
        /^## / { inside = index($0, section) == 1; count = 0 }
        inside && /^```sh$/ { if (++count == n) { printing = 1; next } }
        printing && /^```$/ { exit }
        printing { print }' "$doc" |
        sed -e "s|/shared/hdris|$work/hdris|g" -e "s|/shared/out|$work/shared/out|g" -e 's|--spp 4096|--spp 16 --points 2|g'
}

# Slurm's sbatch for job arrays, emulated: the tasks of --array=FIRST-LAST[%N] in turn.
sbatch() {
    local array="" exports="" script=""
    for argument in "$@"; do
        case $argument in
            --array=*) array=${argument#--array=} ;;
            --export=ALL,*) exports=${argument#--export=ALL,} && exports=${exports//,/ } ;;
            *) script=$argument ;;
        esac
    done
    local range=${array%%\%*} cpus output
    cpus=$(sed -n 's/^#SBATCH --cpus-per-task=//p' "$script")
    output=$(sed -n 's/^#SBATCH --output=//p' "$script")
    for ((id = ${range%-*}; id <= ${range#*-}; id++)); do
        local log=${output//%A/4242}
        log=${log//%a/$id}
        [[ -d $(dirname "$log") ]] || { echo "task $id: no folder for its output $log" >&2; return 1; }
        env SLURM_ARRAY_TASK_ID="$id" SLURM_CPUS_PER_TASK="$cpus" $exports bash "$script" > "$log" 2>&1 ||
            { echo "task $id failed:" >&2; cat "$log" >&2; return 1; }
    done
}

# `folder` holds one JSON per map and `report` reports them all.
expect_results() {
    local name=$1 folder=$2 report=$3 count
    count=$(find "$folder" -name '*.json' | wc -l)
    if ((count != 3)) || ! grep -q "sky" "$report" || ! grep -q "studio" "$report"; then
        echo "scale_recipes: $name: $count JSON files in $folder (expected 3), or a report without every map" >&2
        exit 1
    fi
    echo "scale_recipes: $name: 3 maps, one JSON each, reported"
}

# Slurm: the list and submission, the task script, the merge.
mkdir "$work/slurm"
(
    cd "$work/slurm"
    block "## A Slurm job array" 2 > compare.sbatch
    eval "$(block "## A Slurm job array" 1)"
    eval "$(block "## A Slurm job array" 3)"
)
expect_results "Slurm job array" "$work/slurm/out" "$work/slurm/report.md"

# Slurm past MaxArraySize: the same list in two slices, the second with its offset.
mkdir -p "$work/slices/logs" "$work/slices/out"
(
    cd "$work/slices"
    cp "$work/slurm/maps.txt" "$work/slurm/compare.sbatch" .
    sbatch --array=1-2%64 compare.sbatch
    sbatch --array=1-1%64 --export=ALL,OFFSET=2 compare.sbatch
    envmis report out/*.json -o report.md > /dev/null
)
expect_results "Slurm job array in slices (OFFSET)" "$work/slices/out" "$work/slices/report.md"

# GNU parallel over SSH hosts, this machine the only one: shared filesystem, then none.
for n in 1 2; do
    mkdir "$work/parallel$n"
    (
        cd "$work/parallel$n"
        echo ":" > hosts.txt
        [[ -f maps.txt ]] || cp "$work/slurm/maps.txt" .
        eval "$(block "## GNU parallel over SSH hosts" "$n")" > /dev/null
    )
done
expect_results "GNU parallel, shared filesystem" "$work/shared/out" "$work/parallel1/report.md"
expect_results "GNU parallel, files transferred" "$work/parallel2" "$work/parallel2/report.md"
