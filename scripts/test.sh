#!/usr/bin/env bash
# The project's test command (README): installs missing packages, builds a Release tree
# and runs the default set: every test but those labelled perf (tests/CMakeLists.txt lists
# the labels). ENVMIS_BUILD_DIR picks another build folder (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=${ENVMIS_BUILD_DIR:-build}
jobs=$(nproc)

bash scripts/setup.sh
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build_dir" -j"$jobs"
ctest --test-dir "$build_dir" --output-on-failure -j"$jobs" -LE '^perf$'
