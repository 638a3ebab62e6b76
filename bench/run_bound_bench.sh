#!/usr/bin/env bash
# The memory-traffic bound beside the exact Manhattan transform (issue 20 asks where a missed
# target's bound is): this machine's bandwidth by voxfield-bench-stream (read, write, copy and
# in-place read-modify-write over 1 GiB arrays, 1 and 2 threads), then the transform on the 256³
# scenes in u8 and f32 storage, 1 and 2 threads, in the same sitting. The harness runs with glibc's
# transparent huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1, what docs/limits.md tells an
# application to set), so each run's fresh output costs what it costs the CLI (jemalloc, huge
# pages), not 4 KiB first-touch faults. Results go to bench/results/bound-DATE/.
# Usage: bash bench/run_bound_bench.sh [RUNS]   (default 7)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-7}
source bench/common.sh
bench_prepare
bin=build/release/bin
bench_results bound >/dev/null
cat "$out/machine.txt"
"$bin/voxfield-bench-stream" 1024 "$runs" | tee "$out/stream.md"
for storage in u8 f32; do
  GLIBC_TUNABLES=glibc.malloc.hugetlb=1 "$bin/voxfield-bench-field" --scenes spheres,terrain --sizes 256 \
    --metrics manhattan --threads 1,2 --storage "$storage" --runs "$runs" --json "$out/records.jsonl" |
    tee "$out/manhattan-$storage.txt"
done
echo "results in $out"
