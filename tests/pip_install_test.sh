#!/usr/bin/env bash
# `pip install --no-build-isolation .` into a fresh virtual environment made with
# --system-site-packages (NumPy from Debian), offline, reusing the configured build tree so only the
# module is relinked (setup.py's VOXFIELD_CMAKE_BUILD_DIR); then the installed package is imported
# from outside the source tree and computes a field.
# Usage: pip_install_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1 build=$2
venv=$build/pip-install-test-venv
rm -rf "$venv"
/usr/bin/python3 -m venv --system-site-packages "$venv"
VOXFIELD_CMAKE_BUILD_DIR=$build "$venv/bin/pip" install --quiet --no-build-isolation --no-index "$src"
cd "$venv"
"$venv/bin/python" - <<'PY'
import numpy as np
import voxfield
from voxfield.world import World, distance_field

assert voxfield.__file__.startswith(__import__("sys").prefix), voxfield.__file__
a = np.zeros((5, 5, 5), np.uint8)
a[2, 2, 2] = 1
f = distance_field(World(a), metric="manhattan")
assert f.distances[0, 0, 0] == 6.0 and f.distances[2, 2, 2] == 0.0
print("pip install: ok,", voxfield.__file__)
PY
rm -rf "$venv"
