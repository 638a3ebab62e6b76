# voxfield-mpi command-line tests: what cli_test.sh and cli_frames_test.sh share (sourced):
# the arguments, mpirun with a deadline, a working directory with small worlds, and the checks.
# Usage (of the scripts that source it): SCRIPT VOXFIELD VOXFIELD_MPI MPIEXEC
# shellcheck shell=bash
set -euo pipefail
VF=$1 VFM=$2 MPIEXEC_BIN=$3
# Every mpirun gets a deadline: a job that hangs (a rank waiting forever on one that failed) fails
# this test within minutes and names the command, instead of holding CI until its own limit.
MPI_RUN_SECONDS=${MPI_RUN_SECONDS:-240}
# Under the sanitizers (the asan-ubsan test preset sets VOXFIELD_MPI_RANK_SAMPLE=1) each loop over
# rank counts runs only its largest: the most slab borders, middle ranks with a neighbour on each
# side. Every check still runs under ASan + UBSan but for a few inputs and formats that a loop
# also skips there (each says which), and the optimised build runs every count and input. An
# mpirun of instrumented ranks costs about 2.5 s, and the whole matrix had put CI over its budget.
rank_counts() {  # rank_counts N... (ascending): the counts to run
  if [ "${VOXFIELD_MPI_RANK_SAMPLE:-0}" = 1 ]; then echo "${!#}"; else echo "$@"; fi
}
exec 3>&2  # the test's own stderr, for messages from runs whose stderr is redirected
MPIEXEC() {
  local code=0 start=$SECONDS
  timeout -k 10 "$MPI_RUN_SECONDS" "$MPIEXEC_BIN" "$@" || code=$?
  if [ $((SECONDS - start)) -ge "$MPI_RUN_SECONDS" ]; then
    echo "FAIL: hung for ${MPI_RUN_SECONDS} s: mpirun $*" >&3
    exit 1
  fi
  return "$code"
}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# One machine: shared memory between the ranks, and a failed job ended at once (most runs here
# are refusals; the killed jobs below keep the default grace); tests/CMakeLists.txt says what that
# saves.
export OMPI_MCA_pml=${OMPI_MCA_pml:-ob1} OMPI_MCA_btl=${OMPI_MCA_btl:-self,vader}
export OMPI_MCA_odls_base_sigkill_timeout=${OMPI_MCA_odls_base_sigkill_timeout:-0}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
/usr/bin/python3 - <<'PY'
import numpy as np
rng = np.random.default_rng(3)
a = (rng.random((37, 29, 53)) < 0.01).astype(np.uint8) * rng.integers(1, 5, (37, 29, 53)).astype(np.uint8)
np.save("f.npy", np.asfortranarray(a))
np.save("c.npy", a)
np.save("big_endian.npy", a.astype(">i4"))
np.save("fraction.npy", np.where(a > 0, 0.5, 0.0).astype(np.float32))
PY
fail=0
same() {  # same REF OUT WHAT
  if ! cmp -s "$1" "$2"; then echo "FAIL: $3: $2 differs from voxfield's $1"; fail=1; fi
}

# Bad input: one message (from rank 0), exit 1 (2 for usage), nothing written.
expect_failure() {  # expect_failure CODE PATTERN ARGS...
  local code=$1 pattern=$2
  shift 2
  rm -f bad.npy bad.vfw bad.ply bad.vdb bad.txt
  set +e
  MPIEXEC -np "${EXPECT_RANKS:-2}" "$VFM" "$@" >out.txt 2>err.txt
  local got=$?
  set -e
  if [ "$got" -ne "$code" ]; then echo "FAIL: $* exited $got, expected $code"; cat err.txt; fail=1; fi
  if ! grep -q -- "$pattern" err.txt; then echo "FAIL: $*: no '$pattern' in:"; cat err.txt; fail=1; fi
  if [ "$(grep -c -- "$pattern" err.txt)" -gt 1 ]; then
    echo "FAIL: $*: said more than once:"; cat err.txt; fail=1
  fi
  if [ -e bad.npy ] || [ -e bad.vfw ] || [ -e bad.ply ] || [ -e bad.vdb ] || [ -e bad.txt ]; then echo "FAIL: $* wrote an output"; fail=1; fi
  if ls -a | grep -q vftmp; then echo "FAIL: $* left a temporary"; fail=1; fi
}
# The shared corpus lies beside the repository (README).
vox=$(dirname "$0")/../../../shared/data/vox/dotvox_axes.vox
