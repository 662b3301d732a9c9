#!/usr/bin/env bash
# How fast single samples could be on this CPU (issue 20's targets "single-call sample >=
# 5x the textbook" and "equal-area sampling <= 1.25x the time of equirect"): builds
# scripts/sample_floor.cpp against the library's headers as they are and against copies
# with parts of the sample taken out, then runs the binaries in turns and prints each
# one's median ratio. Against the textbook sampler (8k sky):
#
#   as-is          the library's sample
#   control        the same, compiled with its code aligned otherwise: how far two builds of
#                  the same code differ (code placement), the noise floor of the comparison
#   no-azimuth     the azimuth's sine and cosine (turn table) replaced by the point's
#                  coordinates: what computing them costs beyond the rest
#   no-polar       the same for the polar angle (whose sine the solid-angle pdf divides by)
#   no-direction   both: the sample without its trigonometry, the two inversions (table
#                  reads, searches, divisions), point placement, pdf and radiance alone
#
# With --equal-area, the equal-area sky (5792^2) against the equirect one (8192 x 4096):
#
#   as-is                  the library's samples
#   control                the same, compiled with its code aligned otherwise
#   equirect-direction     the equal-area direction and pdf computed as the equirect ones are
#                          (two turn-table lookups of the point, a division by sin theta):
#                          their cost in the same place
#
# The variants' results are wrong (only their timing means something). Needs a Release
# build with static libraries (bash scripts/test.sh) in build/ or ENVMIS_BUILD_DIR;
# compiles with CXX, else the build's compiler.
# ctest runs one round of each mode (scripts.sample_floor.*), so that it keeps up with
# the library's code. Usage:
#   bash scripts/sample_floor.sh [--no-compensate] [--equal-area] [rounds]   (rounds: default 5)
set -euo pipefail
cd "$(dirname "$0")/.."

flags=()
while [[ "${1:-}" == --* ]]; do
    case $1 in
        --no-compensate | --equal-area) flags+=("$1") ;;
        *) echo "sample_floor.sh: unknown option $1" >&2; exit 2 ;;
    esac
    shift
done
(($# <= 1)) || { echo "sample_floor.sh: options go before the rounds; got '$*'" >&2; exit 2; }
rounds=${1:-5}
build_dir=${ENVMIS_BUILD_DIR:-build}
[[ "$rounds" =~ ^[1-9][0-9]?$ ]] || { echo "sample_floor.sh: rounds must be 1 to 99, got '$rounds'" >&2; exit 2; }
libs=("$build_dir/apps/libenvmis_reference.a" "$build_dir/lib/libenvmis_study.a" "$build_dir/lib/libenvmis_core.a")
for lib in "${libs[@]}"; do
    [ -f "$lib" ] || { echo "sample_floor.sh: $lib is missing: build first (bash scripts/test.sh)" >&2; exit 2; }
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Copies lib/core/include to $work/$1 and replaces, in file $2 there, the text $3 by $4;
# fails if $3 is not found exactly once (the library changed: update this script).
variant() {
    cp -r lib/core/include "$work/$1"
    local file="$work/$1/envmis/$2" text
    text=$(<"$file")
    local without="${text//"$3"/}"
    if (((${#text} - ${#without}) != ${#3})); then
        echo "sample_floor.sh: lib/core/include/envmis/$2 no longer holds '$3' once: update the script" >&2
        exit 2
    fi
    printf '%s\n' "${text/"$3"/"$4"}" >"$file"
}
cp -r lib/core/include "$work/as-is"
cp -r lib/core/include "$work/control"
if [[ " ${flags[*]} " == *" --equal-area "* ]]; then
    variant equirect-direction sampling/envmap.h \
        "return {to_world(axes, equal_area_direction(p)), image_pdf * (1 / kFourPi), radiance[texel], p};" \
        "const SinCos theta = sincos_half_turns(turns, p.y), phi = sincos_turns(turns, p.x);
        const Vec3 d{theta.sin * phi.cos, theta.sin * phi.sin, theta.cos};
        return {to_world(axes, d), solid_angle_pdf(image_pdf, theta.sin), radiance[texel], p};"
    names=(as-is control equirect-direction)
    what="equal-area ns / equirect ns"
else
    line="const SinCos theta = sincos_half_turns(turns, p.y), phi = sincos_turns(turns, p.x);"
    variant no-azimuth sampling/envmap.h "$line" "const SinCos theta = sincos_half_turns(turns, p.y), phi{p.x + 1, p.x * 2};"
    variant no-polar sampling/envmap.h "$line" "const SinCos theta{p.y, p.y * 2}, phi = sincos_turns(turns, p.x);"
    variant no-direction sampling/envmap.h "$line" "const SinCos theta{p.y, p.y * 2}, phi{p.x + 1, p.x * 2};"
    names=(as-is control no-azimuth no-polar no-direction)
    what="textbook ns / guided ns"
fi

cxx=${CXX:-$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build_dir/CMakeCache.txt" 2>/dev/null)}
for name in "${names[@]}"; do
    align=()
    [ "$name" = control ] && align=(-falign-functions=64 -falign-loops=64 -falign-jumps=32)
    "${cxx:-g++}" -O3 -DNDEBUG -std=gnu++20 "${align[@]}" -I"$work/$name" -Ilib/study/include -Iapps/common \
        scripts/sample_floor.cpp "${libs[@]}" -lpthread -o "$work/$name.bin"
done

cpu_field() { lscpu | sed -n "s/^$1: *//p" | head -n 1; }
echo "cpu: $(cpu_field 'Model name') (family $(cpu_field 'CPU family'), model $(cpu_field 'Model')), $(nproc) cores"
for ((round = 1; round <= rounds; ++round)); do
    for name in "${names[@]}"; do
        result=$("$work/$name.bin" "${flags[@]}")
        echo "$name $result"
    done
done | tee "$work/runs.txt"
echo "medians over $rounds rounds (ratio: $what, a round's median of 7):"
for name in "${names[@]}"; do
    grep "^$name " "$work/runs.txt" | sed 's/.*ratio=//' | sort -n |
        awk -v n="$name" '{ r[NR] = $1 } END { printf "  %-19s %sx (of %d: %s to %s)\n", n, r[int((NR + 1) / 2)], NR, r[1], r[NR] }'
done
