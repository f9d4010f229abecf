#!/usr/bin/env bash
# Installs every Debian package hexpeel needs, builds it in Release and meshes an example surface.
#   scripts/setup.sh            install + build + mesh examples/stairs.obj into out/
#   scripts/setup.sh --no-install   skip apt-get (packages already there)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libtbb-dev libcli11-dev nlohmann-json3-dev zlib1g-dev liblbfgspp-dev libsuitesparse-dev
  libexodusii-dev libgmsh-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-numpy python3-vtk9 python3-meshio python3-netcdf4
  pybind11-dev python3-dev
  chromium  # only for the test of the HTML report (headless)
)

if [[ "${1:-}" != "--no-install" ]]; then
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${PACKAGES[@]}"
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --parallel
# The Python module: `python3 -c "import hexpeel"` finds it in build/python (docs/python.md).
site=$(/usr/bin/python3 -m site --user-site)
mkdir -p "$site" && echo "$PWD/build/python" > "$site/hexpeel.pth"

mkdir -p out
./build/hexpeel mesh examples/stairs.obj -o out/stairs.vtk --report out/stairs.json --html out/stairs.html
echo "wrote out/stairs.vtk (hex mesh), out/stairs.json and out/stairs.html (quality report)"
