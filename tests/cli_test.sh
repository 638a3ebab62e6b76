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

# info streams a scene graph of 2^17 instances: its peak memory stays near convert's (the probe
# found it holding every instance's JSON, 35 times convert's memory at 2^20 instances).
check "info streams its instances" 0 /usr/bin/python3 "$(dirname "$0")/info_streams_test.py" "$V" "$tmp/swarm"
sed 's/^/  /' "$tmp/out"; rm -rf "$tmp/swarm"

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


# Distance fields against SciPy's exact transforms (an independent implementation).
if $PY -c "import scipy.ndimage" 2>/dev/null; then
  check "world for fields" 0 $PY -c "
import numpy as np
rng = np.random.default_rng(11)
a = (rng.random((37, 23, 29)) < 0.03).astype(np.uint8) * 7
a[5:12, 3:9, 20:27] = 3
np.save('$tmp/w.npy', a)"
  for m in manhattan chebyshev euclidean; do
    check "field $m" 0 "$V" field "$tmp/w.npy" -o "$tmp/f_$m.npy" --metric $m --stats "$tmp/s_$m.json" --sites "$tmp/n_$m.npy"
  done
  check "field signed euclidean" 0 "$V" field "$tmp/w.npy" -o "$tmp/f_signed.npy" --metric euclidean --signed
  check "field clamped u8" 0 "$V" field "$tmp/w.npy" -o "$tmp/f_u8.npy" --metric euclidean --storage u8 --max-distance 5
  check "field anisotropic" 0 "$V" field "$tmp/w.npy" -o "$tmp/f_aniso.npy" --metric euclidean --spacing 0.5,1,2.5
  check "field jfa-seed stats" 0 "$V" field "$tmp/w.npy" -o "$tmp/f_seed.npy" --algorithm jfa-seed --stats "$tmp/s_seed.json" --packed "$tmp/packed.npy"
  check "scipy agrees" 0 $PY -c "
import json, numpy as np
from scipy import ndimage as nd
a = np.load('$tmp/w.npy'); air = a == 0; solid = ~air
edt = nd.distance_transform_edt(air)
ref = {'euclidean': edt, 'manhattan': nd.distance_transform_cdt(air, metric='taxicab'),
       'chebyshev': nd.distance_transform_cdt(air, metric='chessboard')}
for m, r in ref.items():
    f = np.load('$tmp/f_%s.npy' % m)
    assert f.dtype == np.float32 and f.shape == a.shape, (m, f.dtype, f.shape)
    assert np.allclose(f, r, rtol=0, atol=1e-5), (m, np.abs(f - r).max())
    # nearest sites: the reported site is solid and exactly as far as the distance says
    n = np.load('$tmp/n_%s.npy' % m).astype(int)
    assert n.shape == a.shape + (3,)
    idx = np.indices(a.shape).transpose(1, 2, 3, 0) + n
    assert (a[idx[..., 0], idx[..., 1], idx[..., 2]] != 0).all(), m
    o = np.abs(n)
    d = {'euclidean': np.sqrt((o ** 2).sum(-1)), 'manhattan': o.sum(-1), 'chebyshev': o.max(-1)}[m]
    assert np.allclose(d, r, atol=1e-5), m
    s = json.load(open('$tmp/s_%s.json' % m))
    assert s['metric'] == m and s['algorithm'] == 'exact' and s['dims'] == [37, 23, 29] and s['ms'] > 0, s
signed = np.where(solid, -nd.distance_transform_edt(solid), edt)
assert np.allclose(np.load('$tmp/f_signed.npy'), signed, atol=1e-5)
u8 = np.load('$tmp/f_u8.npy'); assert u8.dtype == np.uint8
assert (u8 == np.floor(np.minimum(edt, 5) * 4 + 1e-9).astype(np.uint8)).all()
aniso = nd.distance_transform_edt(air, sampling=(0.5, 1, 2.5))
assert np.allclose(np.load('$tmp/f_aniso.npy'), aniso, rtol=1e-6, atol=1e-5)
seed = json.load(open('$tmp/s_seed.json'))
assert seed['algorithm'] == 'jfa-seed' and seed['error']['max_under'] == 0 and 'percent_unsafe' in seed['error'], seed
assert (np.load('$tmp/f_seed.npy') >= ref['manhattan'] - 1e-6).all()
p = np.load('$tmp/packed.npy'); assert p.dtype == np.uint32
assert ((p >> 8) & 255 == np.minimum(np.load('$tmp/f_seed.npy'), 255).astype(np.uint32)).all()
"
  check "compare" 0 "$V" compare "$tmp/w.npy" --metric chebyshev --json "$tmp/cmp.json"
  expect_grep "compare table" "$tmp/out" "jfa+2"
  check "compare json" 0 $PY -c "
import json; j = json.load(open('$tmp/cmp.json'))
names = [r['algorithm'] for r in j['algorithms']]
assert names == ['exact','brute','brute-chunked','fim','jfa-seed','jfa','jfa+1','jfa+2','hybrid','lod'], names
assert j['algorithms'][0]['error']['wrong_voxels'] == 0 and j['algorithms'][1]['error']['wrong_voxels'] == 0"
else
  echo "note: SciPy not installed; skipped the SciPy cross-checks"
fi
# Scripted edits: the world replayed in NumPy, the field checked against SciPy.
if $PY -c "import scipy.ndimage" 2>/dev/null; then
  check "edit world" 0 $PY -c "
import numpy as np
a = np.zeros((40, 30, 20), np.uint8); a[20:30, 5:25, 0:8] = 2; np.save('$tmp/e.npy', a)"
  cat > "$tmp/edits.jsonl" <<'JSONL'
{"op":"place","shape":"sphere","center":[10,10,10],"radius":4,"material":3}
{"op":"carve","shape":"box","min":[22,8,2],"max":[27,12,7]}

{"op":"paint","shape":"sphere","center":[25,15,4],"radius":6,"material":9}
{"op":"place","shape":"box","min":[35,25,15],"max":[45,35,25],"material":4}
{"op":"place","shape":"capsule","a":[2,2,18],"b":[12,20,18],"radius":1.5,"material":5}
JSONL
  check "edit" 0 "$V" edit "$tmp/e.npy" -e "$tmp/edits.jsonl" -o "$tmp/e_field.npy" --metric euclidean \
      --max-distance 6 --save-world "$tmp/e_world.npy" --stats "$tmp/e_stats.json"
  check "edits replayed" 0 $PY -c "
import json, numpy as np
from scipy import ndimage as nd
a = np.load('$tmp/e.npy')
x, y, z = np.indices(a.shape)
a[(x - 10) ** 2 + (y - 10) ** 2 + (z - 10) ** 2 <= 16] = 3
a[22:28, 8:13, 2:8] = 0
m = ((x - 25) ** 2 + (y - 15) ** 2 + (z - 4) ** 2 <= 36) & (a != 0); a[m] = 9
a[35:, 25:, 15:] = 4
p = np.stack([x, y, z], -1).astype(float); A = np.array([2, 2, 18.]); B = np.array([12, 20, 18.])
t = np.clip(((p - A) @ (B - A)) / ((B - A) @ (B - A)), 0, 1)
a[((p - A - t[..., None] * (B - A)) ** 2).sum(-1) <= 2.25] = 5
w = np.load('$tmp/e_world.npy')
assert (w == a).all(), np.argwhere(w != a)[:5]
f = np.load('$tmp/e_field.npy')
assert np.allclose(f, np.minimum(nd.distance_transform_edt(a == 0), 6), atol=1e-5)
s = json.load(open('$tmp/e_stats.json'))
assert s['edits'] == 5 and len(s['edit_ms']) == 5 and len(s['voxels_recomputed']) == 5 and s['p99_ms'] >= s['p50_ms'], s
r = s['voxels_recomputed']
assert r[2] == 0, r  # the paint changes materials only: distances cannot move, nothing is recomputed
assert all(v > 0 for i, v in enumerate(r) if i != 2), r
"
  printf '%s\n' '{"op":"place","shape":"sphere","center":[1,1,1],"radius":2}' '{"op":"place","shape":"blob"}' > "$tmp/bad.jsonl"
  check "edit: malformed line" 1 "$V" edit "$tmp/e.npy" -e "$tmp/bad.jsonl" -o "$tmp/bad_field.npy"
  expect_grep "edit: line number" "$tmp/err" "line 2"
  [ ! -e "$tmp/bad_field.npy" ] && passes=$((passes+1)) || { echo "FAIL: edit wrote output despite a bad line"; fails=$((fails+1)); }
fi
check "edit --help" 0 "$V" edit --help

# The durable world format through the CLI.
check "convert to vfw" 0 "$V" convert "$C/ephtracy_monu10.vox" "$tmp/m.vfw"
check "info vfw" 0 "$V" info "$tmp/m.vfw"
expect_grep "vfw solid count" "$tmp/out" "solid voxels:  150764"
check "convert vfw to vox" 0 "$V" convert "$tmp/m.vfw" "$tmp/m2.vox"
check "info vfw round trip" 0 "$V" info "$tmp/m2.vox"
expect_grep "vfw round trip count" "$tmp/out" "solid voxels:  150764"
head -c 3000 "$tmp/m.vfw" > "$tmp/cut.vfw"
check "truncated vfw" 1 "$V" info "$tmp/cut.vfw"
expect_grep "truncated vfw message" "$tmp/err" "cut.vfw"

# The dissertation's edit stream, verified against full rebuilds after every edit.
check "bench edits --verify" 0 "$V" bench edits --world 48 --chunk 16 --edits 40 --metric manhattan --max-distance 6 \
    --verify --csv "$tmp/edits.csv" --json "$tmp/edits.json"
expect_grep "bench edits verify line" "$tmp/out" "verify: 0 of 40"
[ "$(wc -l < "$tmp/edits.csv")" -eq 41 ] && passes=$((passes+1)) || { echo "FAIL: bench edits CSV rows"; fails=$((fails+1)); }
check "bench edits json" 0 $PY -c "
import json; j = json.load(open('$tmp/edits.json'))
assert j['edits'] == 40 and j['verify_mismatches'] == 0 and j['latency_ms']['p99'] >= j['latency_ms']['median'] > 0, j"

check "field: lod without focus" 2 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/x.npy" --algorithm lod
check "field: unknown metric" 2 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/x.npy" --metric taxicab
check "field: spacing with manhattan" 1 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/x.npy" --spacing 1,2,3
check "field: bad input" 1 "$V" field "$C/dotvox_not_a.vox" -o "$tmp/x.npy"
[ ! -e "$tmp/x.npy" ] && passes=$((passes+1)) || { echo "FAIL: output written despite errors"; fails=$((fails+1)); }
for cmd in field compare; do check "$cmd --help" 0 "$V" "$cmd" --help; done

# Rendering: a PNG of the asked size (decoded with Python's zlib), the stats file, clear refusals.
check "render top" 0 "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/knight.png" --camera top --width 120 --height 90 \
    --stats "$tmp/render.json"
check "render png decodes" 0 $PY -c "
import json, struct, zlib
d = open('$tmp/knight.png', 'rb').read()
assert d[:8] == b'\x89PNG\r\n\x1a\n'
w, h, depth, colour = struct.unpack('>IIBB', d[16:26])
assert (w, h, depth, colour) == (120, 90, 8, 2), (w, h, depth, colour)
pos, idat = 8, b''
while pos < len(d):
    n = struct.unpack('>I', d[pos:pos + 4])[0]
    if d[pos + 4:pos + 8] == b'IDAT': idat += d[pos + 8:pos + 8 + n]
    pos += 12 + n
assert len(zlib.decompress(idat)) == h * (1 + 3 * w)
j = json.load(open('$tmp/render.json'))
assert j['width'] == 120 and j['height'] == 90 and j['ms'] > 0 and j['primary']['rays'] == 120 * 90, j"
for view in distance error chunks; do
  check "render $view view" 0 "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/knight-$view.png" --width 64 --height 48 --view $view
done
check "render: bad camera" 2 "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/bad.png" --camera "eye=1,2:target=0,0,0"
expect_grep "render bad camera message" "$tmp/err" "three numbers"
check "render: bad view" 2 "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/bad.png" --view xray
check "render: missing input" 1 "$V" render "$tmp/nothing.vox" -o "$tmp/bad.png"
[ ! -e "$tmp/bad.png" ] && passes=$((passes+1)) || { echo "FAIL: render wrote despite errors"; fails=$((fails+1)); }

# The Vulkan backend (lavapipe in CI): the same file as the CPU, byte for byte. Mesa's drivers leak
# at exit, unattributably (the loader unloads them first): no leak detection for these commands.
GPU="env ASAN_OPTIONS=detect_leaks=0"
if $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/probe.npy" --backend vulkan 2>&1 | grep -q "built without the Vulkan"; then
  echo "skipping the Vulkan checks: this voxfield was built without the backend"
else
  check "field --backend vulkan" 0 $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/kg.npy" --backend vulkan \
      --metric euclidean --signed --max-distance 12 --storage u8 --stats "$tmp/kg.json"
  check "field --backend cpu" 0 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/kc.npy" --backend cpu \
      --metric euclidean --signed --max-distance 12 --storage u8
  cmp -s "$tmp/kg.npy" "$tmp/kc.npy" && passes=$((passes+1)) || { echo "FAIL: vulkan and cpu fields differ"; fails=$((fails+1)); }
  check "field gpu stats" 0 $PY -c "
import json; j = json.load(open('$tmp/kg.json'))
assert j['backend'] == 'vulkan' and j['gpu']['submits'] == 1 and j['gpu']['fence_waits'] == 1, j"
  check "field: jfa+1 on the gpu" 0 $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/jg.npy" --backend vulkan \
      --algorithm jfa+1 --metric chebyshev --storage u8
  check "field: jfa+1 on the cpu" 0 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/jc.npy" --algorithm jfa+1 \
      --metric chebyshev --storage u8
  cmp -s "$tmp/jg.npy" "$tmp/jc.npy" && passes=$((passes+1)) || { echo "FAIL: gpu and cpu jfa+1 differ"; fails=$((fails+1)); }
  check "field: nearest sites on the gpu" 0 $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/sg.npy" --backend vulkan \
      --metric euclidean --signed --max-distance 12 --storage u16 --sites "$tmp/sgs.npy"
  check "field: nearest sites on the cpu" 0 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/sc.npy" \
      --metric euclidean --signed --max-distance 12 --storage u16 --sites "$tmp/scs.npy"
  cmp -s "$tmp/sg.npy" "$tmp/sc.npy" && cmp -s "$tmp/sgs.npy" "$tmp/scs.npy" && passes=$((passes+1)) ||
    { echo "FAIL: gpu and cpu nearest sites differ"; fails=$((fails+1)); }
  check "field: hybrid on the gpu" 0 $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/hg.npy" --backend vulkan \
      --algorithm hybrid --metric manhattan --storage u16
  check "field: hybrid on the cpu" 0 "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/hc.npy" --algorithm hybrid \
      --metric manhattan --storage u16
  cmp -s "$tmp/hg.npy" "$tmp/hc.npy" && passes=$((passes+1)) || { echo "FAIL: gpu and cpu hybrid differ"; fails=$((fails+1)); }
  check "field: brute-chunked on the gpu" 1 $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/x.npy" --backend vulkan \
      --algorithm brute-chunked
  expect_grep "brute-chunked on the gpu message" "$tmp/err" "not on the Vulkan backend"
  check "field --backend auto" 0 $GPU "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/ka.npy" --backend auto
  # No Vulkan driver at all: a clear message, and the CPU does the work.
  check "vulkan without a device" 0 env VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json $GPU \
      "$V" field "$C/ephtracy_chr_knight.vox" -o "$tmp/kn.npy" --backend vulkan --metric euclidean --signed \
      --max-distance 12 --storage u8
  expect_grep "vulkan without a device message" "$tmp/err" "using the cpu backend"
  cmp -s "$tmp/kn.npy" "$tmp/kc.npy" && passes=$((passes+1)) || { echo "FAIL: cpu fallback field differs"; fails=$((fails+1)); }
  # Edits kept on the GPU: verified against full rebuilds after every edit, at most one submit each.
  check "bench edits --backend vulkan --verify" 0 $GPU "$V" bench edits --world 40 --chunk 8 --edits 30 --metric euclidean \
      --signed --max-distance 5 --storage u8 --verify --backend vulkan --json "$tmp/gedits.json"
  check "render --backend vulkan" 0 $GPU "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/kgpu.png" --width 96 --height 64 \
      --backend vulkan --fields host --stats "$tmp/rgpu.json"
  check "render gpu stats" 0 $PY -c "
import json; j = json.load(open('$tmp/rgpu.json'))
assert j['backend'] == 'vulkan' and j['gpu']['submits'] == 1 and j['width'] == 96, j"
  # Fields computed on the device and drawn there: the same picture as fields from the host; only
  # 8 bytes per chunk come back (its summary), and nothing of the fields.
  check "render --fields device" 0 $GPU "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/kdev.png" --width 96 \
      --height 64 --backend vulkan --fields device --stats "$tmp/rdev.json"
  cmp -s "$tmp/kgpu.png" "$tmp/kdev.png" && passes=$((passes+1)) || { echo "FAIL: device fields draw another picture"; fails=$((fails+1)); }
  check "render device fields stats" 0 $PY -c "
import json; j = json.load(open('$tmp/rdev.json')); d = j['device_fields']
assert j['fields'] == 'device' and d['bytes_down'] == 8 * d['chunks_packed'] > 0 and d['submits'] == 4, j
g = j['gpu']; assert g['submits'] == d['submits'] + 1 and g['bytes_downloaded'] == d['bytes_down'] + 96 * 64 * 4, j"
  check "render --fields device on the cpu" 1 "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/x.png" --fields device
  expect_grep "device fields without a device message" "$tmp/err" "needs a Vulkan device"
  check "render: error view on the gpu" 0 $GPU "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/rerr.png" --backend vulkan \
      --view error --algorithm jfa-seed --width 96 --height 64
  check "render: a cut outside the box on the gpu" 1 $GPU "$V" render "$C/ephtracy_chr_knight.vox" -o "$tmp/x.png" \
      --backend vulkan --view distance --slice 100000
  expect_grep "cut outside the box message" "$tmp/err" "lies outside the box"
  check "gpu edits json" 0 $PY -c "
import json; j = json.load(open('$tmp/gedits.json'))
assert j['backend'] == 'vulkan' and j['verify_mismatches'] == 0, j"
  # CSG models on Vulkan: each variant's own kernel, and the interpreter, give one picture.
  GEAR="$(dirname "$0")/../examples/csg/gear.sdf"
  check "csg render --backend vulkan" 0 $GPU "$V" csg "$GEAR" render -o "$tmp/gear-gpu.png" --width 64 --height 48 \
      --depth 4 --backend vulkan --evaluators compiled --stats "$tmp/gear-gpu.json"
  check "csg render: the interpreter on vulkan" 0 $GPU "$V" csg "$GEAR" render -o "$tmp/gear-int.png" --width 64 \
      --height 48 --depth 4 --backend vulkan --evaluators interpreter
  cmp -s "$tmp/gear-gpu.png" "$tmp/gear-int.png" && passes=$((passes+1)) || { echo "FAIL: compiled and interpreted CSG frames differ"; fails=$((fails+1)); }
  check "csg render gpu stats" 0 $PY -c "
import json; j = json.load(open('$tmp/gear-gpu.json'))
g = j['gpu']
assert j['backend'] == 'vulkan' and g['variants_compiled'] == j['variants'] and g['interpreted_dispatches'] == 0, j
assert g['compiled_dispatches'] > 0 and g['rounds'] > 0, j
assert all(j[k] is None for k in ('hits', 'evaluations', 'instructions', 'cells_entered')), j"
  check "csg render: a bad evaluator name" 2 $GPU "$V" csg "$GEAR" render -o "$tmp/x.png" --backend vulkan --evaluators fast
  expect_grep "bad evaluator named" "$tmp/err" "fast not in"
  [ ! -e "$tmp/x.png" ] && passes=$((passes+1)) || { echo "FAIL: csg render wrote a picture after refusing"; fails=$((fails+1)); }
  # Vector fields on Vulkan: frames decayed and blended, every output format, byte for byte the CPU's.
  cat > "$tmp/agents.json" <<'JSON'
{"frames": [{"sources": [{"position": [1, 2, 3], "previous": [0, 1, 2], "radius": 2.5},
                         {"position": [4, 4, 4], "radius": 0.2}]},
            {"sources": [{"position": [2, 3, 3], "previous": [1, 2, 3], "radius": 2.5}]},
            {"sources": []}]}
JSON
  for alg in splat jfa+2; do
    for ext in npy fga vf; do
      check "vectors $alg .$ext on vulkan" 0 $GPU "$V" vectors "$tmp/agents.json" -o "$tmp/vg.$ext" --resolution 24,20,16 \
          --algorithm $alg --storage rgba16f --backend vulkan --stats "$tmp/vg.json"
      check "vectors $alg .$ext on the cpu" 0 "$V" vectors "$tmp/agents.json" -o "$tmp/vc.$ext" --resolution 24,20,16 \
          --algorithm $alg --storage rgba16f
      cmp -s "$tmp/vg.$ext" "$tmp/vc.$ext" && passes=$((passes+1)) || { echo "FAIL: vulkan and cpu vectors ($alg, .$ext) differ"; fails=$((fails+1)); }
    done
  done
  check "vectors gpu stats" 0 $PY -c "
import json; j = json.load(open('$tmp/vg.json'))
g = j['gpu']
assert j['backend'] == 'vulkan' and j['frames'] == 3 and j['flood_passes'] > 0, j
assert set(j['gpu_passes_ms']) == {'seed', 'flood', 'step'}, j
assert g['bytes_downloaded'] >= 24 * 20 * 16 * 8 and g['submits'] >= 4, j"
  check "bench vectors --backend vulkan" 0 $GPU "$V" bench vectors --test quarter-resolution --steps 3 --backend vulkan \
      --csv "$tmp/bv.csv" --plot "$tmp/bv.svg"
  check "bench vectors plot" 0 $PY -c "
import xml.dom.minidom as m; d = m.parse('$tmp/bv.svg')
bars = [r for r in d.getElementsByTagName('rect') if r.getElementsByTagName('title')]
assert len(bars) == 4, len(bars)  # splat and jfa at 64x64x64 and 64x16x64
assert 'vulkan' in d.getElementsByTagName('text')[0].firstChild.data"
  check "bench vectors --plot .png" 0 "$V" bench vectors --test decay --steps 2 --plot "$tmp/bv.png"
  check "bench vectors png plot" 0 $PY -c "
import struct, zlib
b = open('$tmp/bv.png', 'rb').read()
assert b[:8] == bytes([137, 80, 78, 71, 13, 10, 26, 10]), 'a PNG signature'
w, h = struct.unpack('>II', b[16:24])
assert w > 300 and h > 300, (w, h)"
  check "bench vectors: a plot that is neither" 2 "$V" bench vectors --test decay --steps 1 --plot "$tmp/bv.gif"
  expect_grep "plot extension named" "$tmp/err" ".svg or .png"
  [ ! -e "$tmp/bv.gif" ] && passes=$((passes+1)) || { echo "FAIL: bench vectors wrote after refusing"; fails=$((fails+1)); }
  check "bench vectors gpu csv" 0 $PY -c "
import csv; rows = list(csv.DictReader(open('$tmp/bv.csv')))
assert len(rows) == 4 and all(r['backend'] == 'vulkan' and float(r['submits_per_step']) == 1 for r in rows), rows
assert {r['nx'] + 'x' + r['ny'] for r in rows} == {'64x64', '64x16'}, rows"
  check "vectors picture on vulkan" 0 $GPU "$V" vectors "$tmp/agents.json" -o "$tmp/vg.png" --width 64 --height 48 --backend vulkan
  check "vectors: --backend for a world" 2 $GPU "$V" vectors "$C/ephtracy_chr_knight.vox" -o "$tmp/x.npy" --backend vulkan
  expect_grep "vectors world backend message" "$tmp/err" "--backend is for sources"
  [ ! -e "$tmp/x.npy" ] && passes=$((passes+1)) || { echo "FAIL: vectors wrote after refusing"; fails=$((fails+1)); }
  # Marching cubes on the GPU (HistoPyramid): the CPU's mesh — the same vertices and triangles,
  # the same topology — in one computing submit and one read-back.
  $PY -c "
import numpy as np
x, y, z = np.meshgrid(*(np.arange(n, dtype=np.float32) for n in (30, 26, 22)), indexing='ij')
np.save('$tmp/sphere.npy', np.sqrt((x - 14.6) ** 2 + (y - 12.2) ** 2 + (z - 10.9) ** 2) - 8.3)"
  check "mesh --backend vulkan" 0 $GPU "$V" mesh "$tmp/sphere.npy" -o "$tmp/sg.ply" --backend vulkan --stats "$tmp/sg.json"
  check "mesh --backend cpu" 0 "$V" mesh "$tmp/sphere.npy" -o "$tmp/sc.ply" --stats "$tmp/sc.json"
  check "mesh: gpu and cpu meshes agree" 0 $PY -c "
import json; g, c = json.load(open('$tmp/sg.json')), json.load(open('$tmp/sc.json'))
assert g['backend'] == 'vulkan' and c['backend'] == 'cpu', (g['backend'], c['backend'])
for k in ('vertices', 'triangles', 'watertight', 'euler_characteristic', 'boundary_edges'):
    assert g[k] == c[k], (k, g[k], c[k])
assert abs(g['volume_units3'] - c['volume_units3']) < 1e-6 * c['volume_units3'], (g['volume_units3'], c['volume_units3'])
assert g['gpu']['submits'] == 2 and g['gpu']['dispatches'] == g['gpu']['pyramid_levels'] + 2, g['gpu']"
  check "mesh: --backend vulkan with surface nets" 2 $GPU "$V" mesh "$tmp/sphere.npy" -o "$tmp/sn.ply" --backend vulkan --algorithm sn
  expect_grep "mesh backend message" "$tmp/err" "marching cubes only"
  [ ! -e "$tmp/sn.ply" ] && passes=$((passes+1)) || { echo "FAIL: mesh wrote after refusing"; fails=$((fails+1)); }
fi


# Issue 14: a failed command writes no output, the same mistake gets the same answer.
K="$C/ephtracy_chr_knight.vox"
mkdir -p "$tmp/aon"; cd "$tmp/aon"
printf '{"op":"place","shape":"sphere","center":[4,4,4],"radius":2,"material":3}\n' > edits.jsonl
check "edit: bad --save-world type writes nothing" 1 "$V" edit "$K" -e edits.jsonl -o f.npy --save-world w.txt
[ ! -e f.npy ] && passes=$((passes+1)) || { echo "FAIL: f.npy written by a failed edit"; fails=$((fails+1)); }
check "edit: --stats into a missing directory writes nothing" 1 "$V" edit "$K" -e edits.jsonl -o f.npy --stats nodir/s.json
expect_grep "missing directory named" "$tmp/err" "nodir"
[ ! -e f.npy ] && passes=$((passes+1)) || { echo "FAIL: f.npy written before --stats failed"; fails=$((fails+1)); }
check "field: --sites with an algorithm without sites writes nothing" 1 "$V" field "$K" -o o.npy --algorithm brute-chunked --sites s.npy
expect_grep "sites refusal" "$tmp/err" "does not track nearest sites"
[ ! -e o.npy ] && [ ! -e s.npy ] && passes=$((passes+1)) || { echo "FAIL: field wrote output before refusing --sites"; fails=$((fails+1)); }
check "edit: a directory as the script" 1 "$V" edit "$K" -e "$tmp/aon" -o f.npy
expect_grep "directory script refused" "$tmp/err" "not a regular file"
printf '{"op":"place","shape":"sphere","center":[4,4,4],"radius":2}\n{"op":"paint","shape":"sphere","center":[1,1,1],"radius":1,"material":1.5}\n' > bad.jsonl
check "edit: fractional material" 1 "$V" edit "$K" -e bad.jsonl -o f.npy
expect_grep "edit error names the line" "$tmp/err" "bad.jsonl: at byte 60: line 2: "
check "convert to .npy" 0 "$V" convert "$K" w.npy
cp w.npy w0.npy
check "field refuses to overwrite its input" 1 "$V" field w.npy -o w.npy
expect_grep "input overwrite refused" "$tmp/err" "also an input"
cmp -s w.npy w0.npy && passes=$((passes+1)) || { echo "FAIL: field damaged its input"; fails=$((fails+1)); }
check "convert onto itself is safe" 0 "$V" convert w.npy w.npy
cmp -s w.npy w0.npy && passes=$((passes+1)) || { echo "FAIL: convert onto itself changed the file"; fails=$((fails+1)); }
ln -s w.npy link.npy
check "convert writes through a symlink" 0 "$V" convert "$C/ephtracy_chr_cat.vox" link.npy
[ -L link.npy ] && passes=$((passes+1)) || { echo "FAIL: the symlink was replaced"; fails=$((fails+1)); }
check "convert cat" 0 "$V" convert "$C/ephtracy_chr_cat.vox" cat.npy
cmp -s w.npy cat.npy && passes=$((passes+1)) || { echo "FAIL: the symlink's target was not written"; fails=$((fails+1)); }
printf '{"op":"place","shape":"stamp","file":"cat.npy","offset":[0,0,0]}\n' > stamp.jsonl
check "edit refuses to overwrite a stamp it reads" 1 "$V" edit "$K" -e stamp.jsonl -o cat.npy
expect_grep "stamp overwrite refused" "$tmp/err" "also an input"
cmp -s w.npy cat.npy && passes=$((passes+1)) || { echo "FAIL: the stamp was overwritten"; fails=$((fails+1)); }
check "stats to stdout" 0 "$V" field "$K" -o o2.npy --stats -
expect_grep "stats on stdout" "$tmp/out" '"algorithm": "exact"'
mkfifo fifo.vox
check "a FIFO as input does not block" 1 timeout 10 "$V" info fifo.vox
expect_grep "fifo refused" "$tmp/err" "not a regular file"
check "--memory-limit refuses with the file named" 1 "$V" --memory-limit 1M info "$C/ephtracy_monu3.vox"
expect_grep "memory refusal names the file" "$tmp/err" "ephtracy_monu3.vox"
expect_grep "memory refusal names the limit" "$tmp/err" "limit of 1.0 MiB"
check "bad --memory-limit is a usage error" 2 "$V" --memory-limit 12Q info "$K"
check "render --chunk 7 is a usage error" 2 "$V" render "$K" -o x.png --chunk 7
check "field --chunk 7 is a usage error" 2 "$V" field "$K" -o x.npy --chunk 7
check "render --fog nan is a usage error" 2 "$V" render "$K" -o x.png --fog nan
check "render --metric bad is a usage error" 2 "$V" render "$K" -o x.png --metric taxicab
check "bench --interval-ms nan is a usage error" 2 "$V" bench edits --interval-ms nan
check "--threads 0 says what is allowed" 2 "$V" field "$K" -o x.npy --threads 0
expect_grep "threads range" "$tmp/err" "1 to 1024"
check "unknown command named" 2 "$V" frobnicate
expect_grep "unknown command message" "$tmp/err" 'unknown command "frobnicate"'
for cmd in info convert; do check "$cmd --help mentions .vfw" 0 "$V" "$cmd" --help; expect_grep "$cmd help vfw" "$tmp/out" ".vfw"; done
check "edit --help mentions .vfw" 0 "$V" edit --help
expect_grep "save-world help vfw" "$tmp/out" "save-world.*vfw"
ls -a | grep -q vftmp && { echo "FAIL: temporaries left behind"; fails=$((fails+1)); } || passes=$((passes+1))
cd - >/dev/null

# Meshes in: a cube as OBJ (quads) — its field is the box's, its voxels the cube's; mistakes are
# refused with the file and the byte, and write nothing.
printf 'v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 1 5 8 4\nf 2 3 7 6\n' >"$tmp/cube.obj"
check "mesh field needs --voxel-size" 2 "$V" field "$tmp/cube.obj" -o "$tmp/m.npy"
expect_grep "mesh field names the missing option" "$tmp/err" "cube.obj: a mesh needs --voxel-size"
check "mesh field" 0 "$V" field "$tmp/cube.obj" -o "$tmp/m.npy" --voxel-size 0.5 --stats "$tmp/m.json"
check "mesh field values" 0 /usr/bin/python3 -c "
import json, numpy as np
a, s = np.load('$tmp/m.npy'), json.load(open('$tmp/m.json'))
first = np.array(s['first_sample'])
idx = np.indices(a.shape).reshape(3, -1).T
p = first + 0.5 * idx
d = np.maximum(-p, p - 2)  # outside distance per axis of the box [0, 2]^3
want = np.where((d > 0).any(1), np.linalg.norm(np.maximum(d, 0), axis=1), d.max(1))
assert a.dtype == np.float32 and a.shape == (8, 8, 8), (a.dtype, a.shape)
assert np.abs(a.reshape(-1) - want).max() < 1e-6, np.abs(a.reshape(-1) - want).max()"
check "mesh voxelised" 0 "$V" convert "$tmp/cube.obj" "$tmp/cube.npy" --voxel-size 0.5
expect_grep "an .npy drops the frame, said" "$tmp/err" "cube.npy keeps no frame"
check "mesh voxels" 0 /usr/bin/python3 -c "
import numpy as np; a = np.load('$tmp/cube.npy'); assert a.shape == (4, 4, 4) and (a == 1).all(), a"
# A voxelised mesh keeps the mesh's units as its frame: meshed again (the voxels' faces), it lands
# on the cube [0, 2]^3.
check "mesh voxelised to .vfw" 0 "$V" convert "$tmp/cube.obj" "$tmp/cube.vfw" --voxel-size 0.5
check "info shows the frame" 0 "$V" info "$tmp/cube.vfw"
expect_grep "info frame" "$tmp/out" "frame:         origin (0, 0, 0), voxel size (0.5, 0.5, 0.5)"
check "framed world meshed" 0 "$V" mesh "$tmp/cube.vfw" -o "$tmp/cube-again.obj"
check "framed mesh in the cube's units" 0 /usr/bin/python3 -c "
import numpy as np
v = np.array([[float(t) for t in l.split()[1:4]] for l in open('$tmp/cube-again.obj') if l.startswith('v ')])
assert np.abs(v.min(0)).max() < 1e-6 and np.abs(v.max(0) - 2).max() < 1e-6, (v.min(0), v.max(0))"
# A frame given to a world: a scan's anisotropic voxels and where it lies. Its level set in world
# units is measured in those voxels (by default for a .vdb, said on stderr; refused when another
# --spacing or metric is asked for); OpenVDB's transform then puts voxel (i, j, k)'s centre at
# origin + ((i, j, k) + 1/2) * size.
check "frame given" 0 "$V" convert "$tmp/cube.npy" "$tmp/scan.vfw" --voxel-size 0.5,0.5,2 --origin 10,0,-5
check "info of the given frame" 0 "$V" info "$tmp/scan.vfw" --json
expect_grep "given voxel size" "$tmp/out" '"voxel_size_world": \['
check "a frame cannot go to .npy" 2 "$V" convert "$tmp/cube.npy" "$tmp/x.npy" --voxel-size 2
expect_grep "frame to .npy refused" "$tmp/err" "cannot keep"
[ ! -e "$tmp/x.npy" ] && passes=$((passes+1)) || { echo "FAIL: a refused frame wrote its output"; fails=$((fails+1)); }
check "two voxel sizes refused" 2 "$V" convert "$tmp/cube.npy" "$tmp/x.vfw" --voxel-size 1,2
check "a non-finite origin refused" 2 "$V" convert "$tmp/cube.npy" "$tmp/x.vfw" --origin 0,nan,0
check "a zero rotation axis refused" 2 "$V" convert "$tmp/cube.npy" "$tmp/x.vfw" --rotate 30,0,0,0
[ ! -e "$tmp/x.vfw" ] && passes=$((passes+1)) || { echo "FAIL: a refused frame wrote its output"; fails=$((fails+1)); }
# Turned 90 degrees about z: the voxel x axis runs along world y, so OpenVDB puts index (1, 0, 0)
# one voxel edge up y from index (0, 0, 0).
# (pyopenvdb cannot open the world's Int32 grid: its level set's Float grid carries the frame.)
check "a rotated frame" 0 "$V" convert "$tmp/cube.npy" "$tmp/turned.vfw" --voxel-size 2 --rotate 90,0,0,1
check "its level set" 0 "$V" field "$tmp/turned.vfw" --signed --max-distance 3 -o "$tmp/turned.vdb"
check "its transform, by OpenVDB" 0 /usr/bin/python3 -c "
import numpy as np, pyopenvdb as vdb
g = vdb.read('$tmp/turned.vdb', 'distance')
d = np.array(g.transform.indexToWorld((1, 0, 0))) - np.array(g.transform.indexToWorld((0, 0, 0)))
assert np.allclose(d, (0, 2, 0)), d
assert np.allclose(g.transform.indexToWorld((0, 0, 0)), (-1, 1, 1)), g.transform.indexToWorld((0, 0, 0))"
check "an anisotropic level set in voxels refused" 1 "$V" field "$tmp/scan.vfw" --metric euclidean --signed --max-distance 3 --spacing 1,1,1 -o "$tmp/scan.vdb"
expect_grep "spacing named" "$tmp/err" "spacing"
expect_grep "the refusal names the output (given before the field is computed)" "$tmp/err" "scan.vdb: vdb: the field was measured"
check "an anisotropic Manhattan level set refused" 1 "$V" field "$tmp/scan.vfw" --metric manhattan --signed --max-distance 3 -o "$tmp/scan.vdb"
expect_grep "metric named" "$tmp/err" "Manhattan"
check "a clamp within half a voxel refused" 1 "$V" field "$tmp/scan.vfw" --metric euclidean --signed --max-distance 0.2 -o "$tmp/scan.vdb"
expect_grep "the clamp's refusal names the output" "$tmp/err" "scan.vdb: vdb: a clamp of 0.2"
[ ! -e "$tmp/scan.vdb" ] && passes=$((passes+1)) || { echo "FAIL: a refused level set wrote its output"; fails=$((fails+1)); }
check "a level set in world units" 0 "$V" field "$tmp/scan.vfw" --metric euclidean --signed --max-distance 3 -o "$tmp/scan.vdb"
expect_grep "measured in the voxel size, said" "$tmp/err" "measuring in the world's voxel size 0.5 x 0.5 x 2"
check "its transform, by OpenVDB" 0 /usr/bin/python3 -c "
import numpy as np, pyopenvdb as vdb
g = vdb.read('$tmp/scan.vdb', 'distance')
assert np.allclose(g.transform.voxelSize(), (0.5, 0.5, 2)), g.transform.voxelSize()
for ijk in [(0, 0, 0), (3, 1, 2), (-2, 5, 1)]:
    want = np.array([10, 0, -5]) + (np.array(ijk) + 0.5) * (0.5, 0.5, 2)
    assert np.allclose(g.transform.indexToWorld(ijk), want), (ijk, g.transform.indexToWorld(ijk))
assert abs(g.background - (3 - 0.25)) < 1e-6, g.background  # the clamp less half the smallest edge"
# A camera in the world's frame (--camera-frame world) draws the frame the same camera placed in
# voxels by hand draws: voxel v at (100, -50, 3) + v / 4, so voxel (70, -30, 45) is world
# (117.5, -57.5, 14.25) and (16, 16, 6) is (104, -46, 4.5).
check "a terrain for framed cameras" 0 "$V" generate terrain --size 32 -o "$tmp/t32.npy"
check "framed terrain" 0 "$V" convert "$tmp/t32.npy" "$tmp/t32.vfw" --voxel-size 0.25 --origin 100,-50,3
check "render, camera in voxels" 0 "$V" render "$tmp/t32.vfw" -o "$tmp/cam-vox.png" --width 96 --height 64 \
  --camera "eye=70,-30,45:target=16,16,6"
check "render, camera in the world" 0 "$V" render "$tmp/t32.vfw" -o "$tmp/cam-world.png" --width 96 --height 64 \
  --camera "eye=117.5,-57.5,14.25:target=104,-46,4.5" --camera-frame world
check "the same frame either way" 0 cmp "$tmp/cam-vox.png" "$tmp/cam-world.png"
# Voxels that are not cubes: the terrain as a scan of 0.25 x 0.25 x 1 voxels, drawn by a camera in
# its world, is the view of the same terrain built of 0.25-cubes, each voxel four high (flat
# light: ambient occlusion and shadows measure distances in voxels).
check "the terrain built of cubes" 0 /usr/bin/python3 -c "
import numpy as np
a = np.load('$tmp/t32.npy')
np.save('$tmp/t32x4.npy', np.repeat(a, 4, axis=2))
one = np.zeros_like(a)
one[0, 0, 0] = 1  # a world of one voxel: about the sky alone
np.save('$tmp/t32-one.npy', one)"
check "a scan's frame" 0 "$V" convert "$tmp/t32.npy" "$tmp/t32-scan.vfw" --voxel-size 0.25,0.25,1 --origin 100,-50,3
check "the cubes' frame" 0 "$V" convert "$tmp/t32x4.npy" "$tmp/t32-cubes.vfw" --voxel-size 0.25 --origin 100,-50,3
check "one voxel's frame" 0 "$V" convert "$tmp/t32-one.npy" "$tmp/t32-one.vfw" --voxel-size 0.25,0.25,1 --origin 100,-50,3
for cam in "eye=112,-54,22:target=104,-46,12" "eye=120,-60,25:target=104,-46,8:ortho=20"; do
  for w in scan cubes one; do
    check "render the $w, camera in the world" 0 "$V" render "$tmp/t32-$w.vfw" -o "$tmp/cam-$w.png" \
      --width 96 --height 64 --no-shadows --no-ao --camera "$cam" --camera-frame world
  done
  check "the scan's view is the world's ($cam)" 0 /usr/bin/python3 -c "
import numpy as np
from PIL import Image
a, b, sky = (np.asarray(Image.open('$tmp/cam-' + w + '.png')) for w in ['scan', 'cubes', 'one'])
assert (b != sky).any(axis=2).mean() > 0.2, 'the terrain is not in view'
off = (a != b).any(axis=2).mean()
assert off <= 1 / 1000, off  # a pixel may flip where a ray grazes an edge"
done
printf 'v 0 0 0\nv 1 0 0\nf 1 2 3\n' >"$tmp/bad.obj"
check "bad mesh refused" 1 "$V" field "$tmp/bad.obj" -o "$tmp/bad.npy" --voxel-size 0.5
expect_grep "bad mesh names file and byte" "$tmp/err" "bad.obj: at byte 22: the face names vertex 3"
[ ! -e "$tmp/bad.npy" ] && passes=$((passes+1)) || { echo "FAIL: a refused mesh wrote its output"; fails=$((fails+1)); }
check "--voxel-size is for meshes" 2 "$V" convert "$tmp/cube.npy" "$tmp/again.npy" --voxel-size 1
check "a mesh field is Euclidean" 2 "$V" field "$tmp/cube.obj" -o "$tmp/m2.npy" --voxel-size 0.5 --metric manhattan

# A world's flow (vectors away from its solid voxels) as OpenVDB grids: the .npy's strengths, and
# its directions times them, read back by OpenVDB's own Python module.
check "vectors: a world's flow as .vdb" 0 "$V" vectors "$C/ephtracy_chr_knight.vox" -o "$tmp/flow.vdb" --reach 3
check "vectors: a world's flow as .npy" 0 "$V" vectors "$C/ephtracy_chr_knight.vox" -o "$tmp/flow.npy" --reach 3
check "vectors: the world's signed field as .vdb" 0 "$V" field "$C/ephtracy_chr_knight.vox" --signed --metric euclidean -o "$tmp/knight.vdb"
check "vectors: the flow's .vdb is its .npy, on the world's lattice" 0 $PY -c "
import numpy as np, pyopenvdb as vdb
t = np.load('$tmp/flow.npy'); g = {x.name: x for x in vdb.readAll('$tmp/flow.vdb')[0]}
first = tuple(int(c) for c in g['strength'].metadata['voxfield_first'])
s = np.zeros(t.shape[:3], np.float32); g['strength'].copyToArray(s, ijk=first)
v = np.zeros(t.shape[:3] + (3,), np.float32); g['vectors'].copyToArray(v, ijk=first)
assert (t[..., 3] > 0).sum() > 100 and np.array_equal(s, t[..., 3]), (t[..., 3] > 0).sum()
assert np.array_equal(v, t[..., :3] * t[..., 3:4])
# On the world's lattice: at every voxel of the field's domain the flow's strength is the reach's
# ramp of the level set's distance there (1 inside, 1 - d / 3 outside, d = level + 1/2), within
# rgba8's rounding; one voxel off, it is 2/3 off.
field = vdb.readAll('$tmp/knight.vdb')[0][0]
level = np.zeros(t.shape[:3], np.float32); field.copyToArray(level, ijk=first)
at = np.indices(t.shape[:3]).reshape(3, -1).T + np.array(first)
domain = ((at >= field.metadata['voxfield_domain_min']) & (at <= field.metadata['voxfield_domain_max'])).all(axis=1)
ramp = np.clip(1 - np.where(level > 0, level + 0.5, 0) / 3, 0, 1)
err = np.abs(s - ramp).reshape(-1)[domain]
assert domain.sum() > 1000 and err.max() <= 1 / 255, (domain.sum(), err.max())
for ijk in [first, (first[0] + 5, first[1] + 3, first[2] + 7)]:
    assert tuple(g['vectors'].transform.indexToWorld(ijk)) == tuple(field.transform.indexToWorld(ijk))"

# (An ASan build: GCC's links libasan dynamically, clang's links its runtime in; both name __asan_init.)
if grep -qa __asan_init "$V"; then
  # Under the sanitizers the showcase runs once, without a Vulkan driver: every CPU path it takes
  # is leak-checked. (With Vulkan it cannot be: Mesa's lavapipe makes a one-time allocation with its
  # first graphics pipeline, 112 bytes whatever the number of renderers, targets and pipelines made
  # and destroyed — measured — and the Vulkan loader unloads it before LeakSanitizer runs, so that
  # leak can neither be told from ours nor suppressed by name.) Its Vulkan paths run in the
  # optimised build's run of this script, and their own tests (voxfield_gpu_tests) under ASan and
  # UBSan; a second, Vulkan showcase here took 78 s of the sanitizer phase.
  check "showcase (small, no Vulkan driver, leak-checked)" 0 env VK_ICD_FILENAMES=/nonexistent.json \
    VK_DRIVER_FILES=/nonexistent.json "$V" showcase --size 48 --out "$tmp/showcase"
else
  check "showcase (small)" 0 "$V" showcase --size 48 --out "$tmp/showcase"
fi
expect_grep "showcase report" "$tmp/showcase/report.md" "jfa-seed"
expect_grep "showcase round trip" "$tmp/showcase/report.md" "identical"
expect_grep "showcase edits exact" "$tmp/showcase/report.md" "bit-identical to full rebuilds"
expect_grep "showcase meshes" "$tmp/showcase/report.md" "| marching cubes | [0-9]* | [0-9]* | [0-9]* | yes |"
expect_grep "showcase vector fields" "$tmp/showcase/report.md" "| splat | [0-9.]* | 0.000 | 0.00 | 0.0000 |"
expect_grep "showcase world flow exact under edits" "$tmp/showcase/report.md" "byte-identical\*\* to a rebuild"
expect_grep "showcase mesh voxelised back exactly" "$tmp/showcase/report.md" "solid voxels; 0 differ from the block's"
expect_grep "showcase world mesh kept through edits" "$tmp/showcase/report.md" "exactly the triangles of meshing the edited world from scratch"
for png in terrain-before terrain-after terrain-top-before terrain-top-after terrain-chunks terrain-distance error-jfa-seed vectors flow-before flow-after bunny bunny-slices terrain-mesh-edited; do
  [ -s "$tmp/showcase/$png.png" ] && grep -q "($png.png)" "$tmp/showcase/report.md" && passes=$((passes+1)) \
    || { echo "FAIL: showcase frame $png missing or not in the report"; fails=$((fails+1)); }
done

echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
