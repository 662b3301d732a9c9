#!/usr/bin/env bash
# Makes docs/results.md and its plots (docs/images/results/MAP/): every technique on
# every bundled map for the default BSDFs (compensated at the automatic alpha; the normal-
# aware bins at their per-bin choice), the
# compensation-strength sweep (exact variances) against `--alpha auto`, and the
# sample-allocation sweep. About 3 minutes on 2 cores after the build. The single
# techniques (env, bsdf) are given exactly (--exact): measured, they miss their rare samples.
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=${ENVMIS_BUILD_DIR:-build}
bash scripts/setup.sh
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build_dir" -j"$(nproc)" --target envmis
envmis="$build_dir/apps/envmis"

techniques=env,bsdf,mis-balance,mis-power,mis-optimal,mis-var,one-sample,mis-balance-comp,mis-power-comp
techniques+=,mis-optimal-comp,mis-var-comp,one-sample-comp,mis-balance-all,mis-optimal-all
techniques+=,mis-balance-bins,mis-power-bins,mis-optimal-bins

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
plots=docs/images/results
results=()
for map in rooitou_park_1k.hdr city.exr studio.exr; do
  name=${map%.*}
  echo "== $map" >&2
  common=(--points 16 --alpha auto --plots "$plots/$name")
  "$envmis" compare "data/envmaps/$map" "${common[@]}" --techniques "$techniques" --spp 4096 --exact --json "$work/$name.json"
  "$envmis" compare "data/envmaps/$map" "${common[@]}" --alpha-sweep 0:3:0.25 --exact --spp 1024 \
    --json "$work/$name-alpha.json" > /dev/null
  "$envmis" compare "data/envmaps/$map" "${common[@]}" --allocation-sweep 4 \
    --techniques mis-balance,mis-balance-comp,mis-optimal-comp,mis-balance-bins --spp 2048 --json "$work/$name-allocation.json" > /dev/null
  results+=("$work/$name.json" "$work/$name-alpha.json" "$work/$name-allocation.json")
done
"$envmis" report "${results[@]}" -o docs/results.md --title "envmis results: every technique on the bundled maps" \
  --command "bash scripts/results.sh" --plots images/results
