#!/usr/bin/env bash
# Quick start, command 1: set up, build and run the showcase (the main job). The report lands in
# out/report.md. Extra arguments go to `voxfield showcase` (try --help).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/install-bench-deps.sh  # the peers the report sets voxfield beside
cmake --preset release >/dev/null
cmake --build --preset release
out=""
prev=""
for a in "$@"; do
  if [ "$prev" = "--out" ]; then out=$a; fi
  case "$a" in --out=*) out=${a#--out=} ;; esac
  prev=$a
done
if [ -z "$out" ]; then  # the report's directory: out/ unless the arguments name one
  out=out
  set -- --out out "$@"
fi
./build/release/bin/voxfield showcase "$@"
bash scripts/showcase_mpi.sh "$out"  # the same terrain's field over MPI ranks, identical to one process
# voxfield.ndimage beside scipy.ndimage on a real MRI scan: the same float64 bits, and how much faster
PYTHONPATH=build/release/python /usr/bin/python3 scripts/showcase_python.py "$out"
node web/build-report.mjs "$out"      # report.html beside report.md, the terrain orbitable in the page
