#!/usr/bin/env bash
# Packages only the benchmarks need: the peers voxfield is compared with, and plotting.
set -euo pipefail
packages=(python3-scipy python3-matplotlib libopenvdb-dev libdynamicedt3d-dev
          python3-vtk9 python3-skimage  # meshing peers: VTK's flying edges, scikit-image's marching cubes
          mricron-data python3-nibabel)  # a real MRI volume (ch2better, 301 x 370 x 316) and its reader
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
