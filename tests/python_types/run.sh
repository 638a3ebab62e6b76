#!/usr/bin/env bash
# The package's type stubs (python/voxfield/*.pyi, PEP 561) against the built module: mypy's
# stubtest checks that every name and signature in the stubs exists at run time and the reverse;
# mypy --strict checks a typed use of the package against the stubs, which is then run.
# Usage: run.sh BUILD_PYTHON_DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
export PYTHONPATH=$1 MYPYPATH=$1
cd "$(mktemp -d)"
/usr/bin/python3 -m mypy.stubtest voxfield --allowlist "$here/stubtest_allowlist.txt"
/usr/bin/python3 -m mypy --strict --no-incremental --cache-dir=/dev/null "$here/typed_use.py"
/usr/bin/python3 "$here/typed_use.py"
