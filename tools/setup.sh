#!/usr/bin/env bash
# Shared setup for quickstart.sh and test.sh: install the Debian packages that are
# missing (Debian 12, as root), then configure and build (Release) into build/.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config git
  libcgal-dev libgmp-dev libmpfr-dev
  libceres-dev libsuitesparse-dev
  libeigen3-dev libcli11-dev
  googletest libgtest-dev
  libtomlplusplus-dev nlohmann-json3-dev libfmt-dev
  gnuplot-nox python3 python3-vtk9 python3-numpy
  libopenmpi-dev openmpi-bin
)
missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "missing Debian packages: ${missing[*]}" >&2
    echo "run as root, or: sudo apt-get install ${missing[*]}" >&2
    exit 1
  fi
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build_type=${BUILD_TYPE:-Release}
werror=${SPECIMEN_WERROR:-OFF}
cmake -S . -B build -DCMAKE_BUILD_TYPE="$build_type" -DSPECIMEN_WERROR="$werror" >/dev/null
cmake --build build -j"$(nproc)"
