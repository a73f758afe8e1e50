#!/bin/sh
# Installs what ExplicitDeformableModel needs on Debian 12 (as root, with
# apt-get), then configures and builds it into build/.
# Usage: scripts/build.sh [extra CMake arguments]
set -eu
cd "$(dirname "$0")/.."

# ITK core, tests and benchmarks; VTK 9.1 with its Python for the VTK module,
# the edmodel Python package and rendering (xvfb for headless tests); qemu-user
# to test the portable build on an x86-64 processor without AVX.
packages="cmake make g++ libinsighttoolkit5-dev libgtest-dev libbenchmark-dev
  libvtk9-dev python3-vtk9 xvfb xauth qemu-user mricron-data"
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "Installing:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $missing
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build -j2
