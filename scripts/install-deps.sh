#!/usr/bin/env bash
# Installs voxfield's build and test dependencies from Debian 12 packages, only when something is
# missing (so repeated runs cost a second). Needs root or sudo for the install step.
# Why each package was chosen: docs/architecture.md, "Dependencies".
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config   # toolchain
  libtbb-dev                         # thread pool (oneTBB)
  zlib1g-dev                         # TDCZ models in .vox files
  libpng-dev                         # PNG frames from the renderer
  libcairo2-dev fonts-dejavu-core    # the benchmarks' PNG plots: shapes and text (cairo), a font for it
  libvulkan-dev libvulkan-volk-dev glslc   # the Vulkan backend: headers, run-time loader, GLSL -> SPIR-V
  glslang-dev glslang-tools libspirv-cross-c-shared-dev  # run-time GLSL -> SPIR-V (generated CSG shaders; glslang's CMake package needs its tools), SPIR-V reflection
  mesa-vulkan-drivers vulkan-validationlayers  # lavapipe (software Vulkan) and the validation layer, for tests
  libglfw3-dev libimgui-dev          # voxfield-demo: window and input (GLFW), the panel (Dear ImGui)
  xvfb xauth xdotool                 # a virtual display for the demo's tests (xvfb-run), input events
  nlohmann-json3-dev                 # JSON output of the CLI
  libcli11-dev                       # CLI parsing
  libmeshoptimizer-dev               # mesh simplification and vertex-cache ordering (voxfield mesh --simplify)
  libjemalloc-dev                    # the programs' allocator: jemalloc on transparent huge pages (apps/common/huge_page_allocator.cpp)
  libgtest-dev                       # tests
  clang libclang-rt-14-dev           # the asan-ubsan preset and the fuzz preset (libFuzzer)
  clang-format                       # the format check (scripts/check_format.sh, a test)
  python3 python3-numpy python3-scipy python3-pil # test oracles: NumPy reads and writes .npy, SciPy's distance transforms, Pillow reads PNG frames
  python3-skimage                    # test oracle: scikit-image's marching_cubes for the meshers
  openscad                           # test oracle: OpenSCAD's .csg and STL of its bundled examples (CSG import)
  python3-dev pybind11-dev python3-pytest  # the Python package (pybind11 bindings) and its tests
  python3-venv python3-setuptools python3-wheel  # pip install --no-build-isolation . (and its test)
  libopenmpi-dev openmpi-bin         # voxfield-mpi and the mpi layer: Open MPI, Debian's MPI
  libblosc-dev                       # Blosc, which .vdb files are compressed with (voxfield's own .vdb reader)
  libopenvdb-dev libboost-dev python3-openvdb  # .vdb files (OpenVDB; its headers need Boost's), and the tests' oracle (pyopenvdb)
  python3-mypy  # checks the package's type stubs against the module (mypy.stubtest) and a typed use of them
  chromium                           # the report page's test: headless Chromium opens it and screenshots the mesh viewer
)
# Node.js and npm for the report page's JavaScript (below): Debian's, unless the machine has its own.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "voxfield: installing missing packages: ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The report page's JavaScript from the npm registry, at the versions web/package-lock.json pins:
# three.js (the glTF viewer), marked (markdown to HTML), esbuild (bundles the viewer into one
# classic script, which a page opened from disk may load). Reinstalled only when the lock changed.
web="$(dirname "$0")/../web"
if [ ! -f "$web/node_modules/.package-lock.json" ] ||
  [ "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]; then
  echo "voxfield: installing the report page's npm packages (web/package-lock.json)" >&2
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error >&2)
fi

# The classic meshes the mesh-input oracle reads (Debian's packages, downloaded, never in the repo).
bash "$(dirname "$0")/fetch-test-meshes.sh"
