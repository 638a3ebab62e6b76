# Shared by the bench/run_*.sh scripts (sourced from the repository root).
#
# bench_prepare [--peers]   installs voxfield's dependencies (and the peers' with --peers) and
#                           builds the release preset.
# bench_results NAME        creates bench/results/NAME-DATE, records the machine, the time and the
#                           commit in its machine.txt (also printed), and sets $out to it.

bench_prepare() {
  bash scripts/install-deps.sh
  if [ "${1:-}" = "--peers" ]; then bash scripts/install-bench-deps.sh; fi
  cmake --preset release >/dev/null
  cmake --build --preset release
}

bench_results() {
  out=bench/results/$1-$(date +%Y%m%d-%H%M)
  mkdir -p "$out"
  { echo "machine: $(lscpu | sed -n 's/^Model name:\s*//p'), $(nproc) cores"; date -u; git rev-parse HEAD; } | tee "$out/machine.txt"
}
