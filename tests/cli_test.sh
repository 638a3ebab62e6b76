#!/usr/bin/env bash
# End-to-end checks of the voxfield CLI: exit codes, error messages, and file round trips checked
# against NumPy when it is available. Called by CTest with VOXFIELD and VOX_CORPUS set.
set -u
fails=0; passes=0
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

check() {  # check NAME EXPECTED_CODE CMD...
  local name=$1 want=$2; shift 2
  "$@" >"$tmp/out" 2>"$tmp/err"; local got=$?
  if [ "$got" -ne "$want" ]; then
    echo "FAIL $name: exit $got, expected $want"; sed 's/^/  | /' "$tmp/err" | head -5; fails=$((fails+1))
  else passes=$((passes+1)); fi
}
expect_grep() {  # expect_grep NAME FILE PATTERN
  if grep -q -- "$3" "$2"; then passes=$((passes+1)); else echo "FAIL $1: '$3' not in output"; sed 's/^/  | /' "$2" | head -5; fails=$((fails+1)); fi
}

V=$VOXFIELD; C=$VOX_CORPUS
check "no command is a usage error" 2 "$V"
check "unknown command" 2 "$V" frobnicate
check "unknown option" 2 "$V" info --bogus "$C/ephtracy_menger.vox"
check "missing argument" 2 "$V" info
for cmd in info convert generate showcase; do check "$cmd --help" 0 "$V" "$cmd" --help; done
check "--help" 0 "$V" --help

check "missing file" 1 "$V" info "$tmp/nope.vox"
expect_grep "missing file message" "$tmp/err" "nope.vox"
check "bad magic" 1 "$V" info "$C/dotvox_not_a.vox"
expect_grep "bad magic message names the file" "$tmp/err" "dotvox_not_a.vox"
expect_grep "bad magic message names the offset" "$tmp/err" "at byte 0"
check "slab6 file" 1 "$V" info "$C/vengi_slab6_vox_test.vox"
check "unknown extension" 1 "$V" info "$C/README.md"

check "info menger" 0 "$V" info "$C/ephtracy_menger.vox"
expect_grep "menger solid count" "$tmp/out" "solid voxels:  160000"
check "info menger json" 0 "$V" info --json "$C/ephtracy_menger.vox"
expect_grep "menger json count" "$tmp/out" '"solid_voxels": 160000'

# Every corpus file: info works (exit 0) unless it is one of the two non-MagicaVoxel files.
for f in "$C"/*.vox; do
  case $(basename "$f") in dotvox_not_a.vox|vengi_slab6_vox_test.vox) want=1;; *) want=0;; esac
  check "info $(basename "$f")" $want "$V" info --json "$f"
done

# convert .vox -> .npy -> .vox keeps every voxel.
check "convert vox to npy" 0 "$V" convert "$C/ephtracy_chr_knight.vox" "$tmp/knight.npy"
check "convert npy to vox" 0 "$V" convert "$tmp/knight.npy" "$tmp/knight.vox"
check "info round trip" 0 "$V" info "$tmp/knight.vox"
expect_grep "round trip count" "$tmp/out" "solid voxels:  398"
check "convert to unknown type" 1 "$V" convert "$C/ephtracy_chr_knight.vox" "$tmp/knight.txt"
check "convert into missing directory" 1 "$V" convert "$C/ephtracy_chr_knight.vox" "$tmp/no/dir/k.npy"

# NumPy as the oracle: the .npy we write is a[x, y, z] with the model's SIZE as shape.
PY=/usr/bin/python3
if $PY -c "import numpy" 2>/dev/null; then
  check "convert menger" 0 "$V" convert "$C/ephtracy_menger.vox" "$tmp/menger.npy"
  check "numpy reads menger" 0 $PY -c "
import numpy as np
a = np.load('$tmp/menger.npy')
assert a.shape == (81, 81, 81), a.shape
assert (a != 0).sum() == 160000
assert a[40, 40, :].sum() == 0  # the central tunnel
"
  # NumPy-written arrays in both orders come back identical through voxfield.
  check "numpy writes" 0 $PY -c "
import numpy as np
rng = np.random.default_rng(5)
a = (rng.random((17, 9, 23)) < 0.3).astype(np.uint8) * rng.integers(1, 256, (17, 9, 23)).astype(np.uint8)
np.save('$tmp/c.npy', a); np.save('$tmp/f.npy', np.asfortranarray(a)); np.save('$tmp/b.npy', a != 0)
"
  check "convert C order" 0 "$V" convert "$tmp/c.npy" "$tmp/c_out.npy"
  check "convert F order" 0 "$V" convert "$tmp/f.npy" "$tmp/f.vox"
  check "convert F back" 0 "$V" convert "$tmp/f.vox" "$tmp/f_out.npy"
  check "convert bool" 0 "$V" convert "$tmp/b.npy" "$tmp/b_out.npy"
  check "numpy compares" 0 $PY -c "
import numpy as np
a = np.load('$tmp/c.npy')
for name in ['c_out', 'f_out']:
    b = np.load('$tmp/' + name + '.npy')
    # the .vox trip trims to the content's bounding box; compare on it
    nz = np.argwhere(a != 0); lo = nz.min(0); hi = nz.max(0) + 1
    if b.shape != a.shape: a2 = a[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
    else: a2 = a
    assert b.shape == a2.shape, (name, b.shape, a2.shape)
    assert (a2 == b).all(), name
assert (np.load('$tmp/b_out.npy') == (a != 0)).all()
"
else
  echo "note: NumPy not installed; skipped the NumPy cross-checks"
fi

check "generate" 0 "$V" generate terrain --size 40,30,20 -o "$tmp/t.npy"
check "numpy reads generated" 0 $PY -c "
import numpy as np; a = np.load('$tmp/t.npy'); assert a.shape == (40, 30, 20) and 0.3 < (a != 0).mean() < 0.7"

echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
