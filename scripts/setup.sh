#!/usr/bin/env bash
# Installs the Debian packages envmis needs to build and test. Safe to re-run: apt is
# only touched when something is missing, so CI and developers pay nothing on a warm box.
set -euo pipefail

# The one list of build dependencies (clang and libclang-rt-14-dev: the libFuzzer build;
# clang-format: the style check in CI; the python3-* and pybind11: the Python package, its
# tests and examples, for /usr/bin/python3; parallel: the cluster recipe's test).
packages=(
  cmake g++ pkg-config
  libopenimageio-dev libopencolorio-dev libopenexr-dev libeigen3-dev
  libcli11-dev nlohmann-json3-dev libgtest-dev libbenchmark-dev
  libembree-dev libtinyobjloader-dev
  clang libclang-rt-14-dev clang-format
  python3-dev python3-numpy python3-pytest python3-matplotlib pybind11-dev parallel
)

missing=()
for p in "${packages[@]}"; do
  # dpkg-query fails for unknown packages and prints other states for removed ones.
  if [[ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)" != "install ok installed" ]]; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo=()
if ((EUID != 0)) && command -v sudo >/dev/null; then
  sudo=(sudo)
fi
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
