#!/usr/bin/env bash
# The project's main job (README): installs missing packages, builds envmis and runs the
# variance comparison on a bundled sunny map, printing its table and writing its pictures
# to out/ (montage: out/montage.png). Extra arguments go to `envmis compare`.
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=${ENVMIS_BUILD_DIR:-build}

bash scripts/setup.sh
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build_dir" -j"$(nproc)" --target envmis
# compare writes into folders that exist (it creates only the --images one itself).
mkdir -p out
"$build_dir/apps/envmis" compare data/envmaps/rooitou_park_1k.hdr --images out --json out/results.json \
  --csv out/results.csv "$@"
