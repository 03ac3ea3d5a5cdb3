#!/usr/bin/env bash
# Installs the Debian packages PIC needs when they are missing (idempotent; needs root or sudo).
#   scripts/setup.sh            build + tests
#   scripts/setup.sh --bench    also the benchmark peers (OpenVDB, Google Benchmark)
#   scripts/setup.sh --fuzz     also clang and libFuzzer (make fuzz)
set -euo pipefail

pkgs=(cmake ninja-build g++ pkg-config libeigen3-dev libtbb-dev libassimp-dev libpng-dev zlib1g-dev
      libcli11-dev libgtest-dev chromium libcgal-dev)
# OpenSCAD's 2D nodes: Clipper for polygons and offset, FreeType/HarfBuzz/fontconfig for text
# (OpenSCAD's default font, Liberation Sans).
pkgs+=(libpolyclipping-dev libfreetype-dev libharfbuzz-dev libfontconfig-dev fonts-liberation2)
# `pic eval model.scad` runs OpenSCAD to export its CSG tree (tests skip the .scad case without it).
pkgs+=(openscad openscad-mcad)
# The `pic` Python module (pybind11) and its pytest suite; numpy arrays in and out.
pkgs+=(pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest)
if [[ "${1:-}" == "--bench" ]]; then
  # bench/any_input.py asks ../shared/tools/gwn.py (numpy, scipy) for exact winding numbers.
  pkgs+=(libbenchmark-dev libopenvdb-dev libboost-iostreams-dev python3 python3-scipy)
fi
if [[ "${1:-}" == "--fuzz" ]]; then
  pkgs+=(clang libclang-rt-14-dev)
fi

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# The HTML viewer bundles three.js with npm at build time; any node >= 18 with npm will do.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  missing+=(nodejs npm)
fi

if (( ${#missing[@]} )); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
echo "setup: all packages present"
