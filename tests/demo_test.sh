#!/usr/bin/env bash
# voxfield-demo end to end, under Xvfb: benchmark mode for 30 frames on the Vulkan ray marcher
# (lavapipe in CI) with the validation layer, on the CPU renderer, and with no Vulkan driver at
# all (CPU frames presented through OpenGL); then clicks and a key sent with xdotool. Each run must exit 0, write
# a CSV with one row per frame, print no validation message, and leave a screenshot showing sky
# and world. DEMO and FRAME_CHECK are set by CTest.
set -u
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

run() {  # name, demo arguments...
  local name=$1
  shift
  local status=0 t0=$SECONDS
  env ${RUN_ENV:-} xvfb-run -a -s "-screen 0 1024x768x24" "$DEMO" --benchmark --frames 30 --width 480 --height 270 --world 64 \
      --csv "$out/$name.csv" --screenshot "$out/$name.png" "$@" >"$out/$name.out" 2>"$out/$name.err" || status=$?
  if [ "$status" -ne 0 ]; then
    fail "$name: exit status $status: $(tail -5 "$out/$name.err")"
    return
  fi
  grep -q "validation:" "$out/$name.err" && fail "$name: validation messages: $(grep -m3 validation: "$out/$name.err")"
  [ "$(head -1 "$out/$name.csv")" = "frame,frame_ms,update_ms,render_ms,edits,gpu_submits,gpu_dispatches,gpu_bytes_up,gpu_bytes_down,mesh_ms,triangles,bytes_up" ] ||
    fail "$name: CSV header"
  local rows
  rows=$(tail -n +2 "$out/$name.csv" | wc -l)
  [ "$rows" -eq 30 ] || fail "$name: $rows CSV rows, expected 30"
  # The benchmark's edits keep coming: the last row counts at least one.
  awk -F, 'END { exit !($5 >= 1) }' "$out/$name.csv" || fail "$name: no edits were made"
  "$FRAME_CHECK" "$out/$name.png" || fail "$name: the screenshot is not a frame of sky and world"
  echo "ok: $name, $((SECONDS - t0)) s ($(tail -1 "$out/$name.err"))"
}

run vulkan --backend vulkan --validation
grep -q "Vulkan ray marcher" "$out/vulkan.err" || fail "vulkan: the demo did not say it draws with the Vulkan ray marcher"
# Every frame dispatches the ray marcher; frames copy at most what edits changed (the first frame
# copies the scene); nothing is ever read back.
awk -F, 'NR > 1 && ($7 < 1 || $9 != 0 || $6 > 1) { bad = 1 } END { exit bad }' "$out/vulkan.csv" ||
  fail "vulkan: a frame without a dispatch, with more than one submit of voxfield's, or with a read-back"
awk -F, 'NR == 2 { first = $8 } NR > 2 && $8 > max { max = $8 } END { exit !(max < first) }' "$out/vulkan.csv" ||
  fail "vulkan: a later frame copied as much as the whole scene"
# The fields computed and kept on the device (gpu::DeviceRenderScene): every frame still dispatches
# the ray marcher, and what comes back is at most the packed chunks' summaries (8 bytes each; the
# 64 x 64 x 32 world has 32 chunks of 16), never a field or a frame.
run vulkan-fields --backend vulkan --fields device --validation
grep -q "its fields computed there" "$out/vulkan-fields.err" ||
  fail "vulkan-fields: the demo did not say its fields are computed on the device"
awk -F, 'NR > 1 && ($7 < 1 || $9 > 32 * 8) { bad = 1 } END { exit bad }' "$out/vulkan-fields.csv" ||
  fail "vulkan-fields: a frame without a dispatch, or reading back more than the chunks' summaries"
run cpu --backend cpu
grep -q "CPU renderer" "$out/cpu.err" || fail "cpu: the demo did not say it draws with the CPU renderer"
# No Vulkan driver at all: the CPU renderer's frames, presented through OpenGL.
RUN_ENV="VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json" run opengl --backend vulkan
grep -q "shown through OpenGL" "$out/opengl.err" || fail "opengl: the demo did not say it fell back to OpenGL"

# The vectors mode: the paper's agents, their field stepped once a frame (benchmark mode: one
# fixed step per frame) and drawn with the reactive sheet — on the Vulkan passes (the frame's step
# and picture recorded into the frame) under validation, on the CPU, and through OpenGL. The field
# is the same bit for bit on both backends, so the pictures right of the panel agree within the
# visualiser's float tolerance; they show the green sheet and the coloured field.
vector_frames=${VECTOR_FRAMES:-10}  # fewer under a sanitizer (tests/CMakeLists.txt)
# The vectors and terrain modes through OpenGL (no Vulkan device) step and mesh on the CPU exactly
# as their cpu runs do; only the picture's way to the screen differs, which the plain opengl run
# above already takes. Under a sanitizer (OPENGL_MODES=0, tests/CMakeLists.txt) they are left to
# the optimised build: 43 s of the sanitizer stage's CPU time.
opengl_modes=${OPENGL_MODES:-1}
vrun() {  # name, demo arguments...
  local name=$1
  shift
  local status=0 t0=$SECONDS
  env ${RUN_ENV:-} xvfb-run -a -s "-screen 0 1024x768x24" "$DEMO" --mode vectors --benchmark --frames "$vector_frames" --width 640 \
      --height 360 --csv "$out/$name.csv" --screenshot "$out/$name.png" "$@" >"$out/$name.out" 2>"$out/$name.err" || status=$?
  if [ "$status" -ne 0 ]; then
    fail "$name: exit status $status: $(tail -5 "$out/$name.err")"
    return
  fi
  grep -q "validation:" "$out/$name.err" && fail "$name: validation messages: $(grep -m3 validation: "$out/$name.err")"
  awk -F, -v n="$vector_frames" 'END { exit !(NR == n + 1 && $5 == n) }' "$out/$name.csv" ||
    fail "$name: expected $vector_frames frames of one step each"
  echo "ok: $name, $((SECONDS - t0)) s ($(grep -m1 "vectors mode" "$out/$name.err"))"
}
vrun vectors-vulkan --backend vulkan --validation
grep -q "stepped and drawn on the Vulkan device" "$out/vectors-vulkan.err" || fail "vectors-vulkan: not on the device"
# Every frame of the Vulkan path: voxfield's step and picture go in the frame (no submit of its own).
awk -F, 'NR > 1 && ($6 != 0 || $7 < 2) { bad = 1 } END { exit bad }' "$out/vectors-vulkan.csv" ||
  fail "vectors-vulkan: a frame with a submission of voxfield's own, or without its step and picture"
vrun vectors-cpu --backend cpu
[ "$opengl_modes" = 1 ] &&
  RUN_ENV="VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json" vrun vectors-opengl --backend vulkan
/usr/bin/python3 - "$out" "$opengl_modes" <<'PY' || fail "vectors: the pictures differ or lack the sheet and the field"
import sys
from PIL import Image
out = sys.argv[1]
others = ("vulkan", "opengl") if sys.argv[2] == "1" else ("vulkan",)
shots = {n: Image.open(f"{out}/vectors-{n}.png").convert("RGB") for n in ("cpu",) + others}
w, h = shots["cpu"].size
box = (370, 0, w, h)  # right of the panel
px = {n: list(s.crop(box).getdata()) for n, s in shots.items()}
def near(p, q, tolerance=2):
    return max(abs(a - b) for a, b in zip(p, q)) <= tolerance
for n in others:
    # The backends step the same field bit for bit but march and shade in their own floats, so
    # colours agree within 2 — except where a hard edge (the sheet's silhouette, the box's) passes
    # within rounding of a pixel's ray: one backend's ray grazes the sheet, the other's misses it,
    # and the pixel takes the colour of its neighbour across the edge (seen: one pixel of 97 200 in
    # a 6-frame run, sheet green against background). Such a pixel must show a colour the CPU's
    # picture has beside it; anything else is a real divergence.
    img, ref = shots[n].load(), shots["cpu"].load()
    off = [(x, y) for x in range(box[0], w) for y in range(h) if not near(img[x, y], ref[x, y])]
    stray = [(x, y) for x, y in off
             if not any(near(img[x, y], ref[u, v]) for u in range(max(x - 1, box[0]), min(x + 2, w))
                        for v in range(max(y - 1, 0), min(y + 2, h)))]
    total = len(px["cpu"])
    print(f"vectors {n} vs cpu: {total - len(off)} of {total} pixels within 2; "
          f"{len(off)} more than 2 off, {len(stray)} of them without that colour beside them")
    assert len(off) <= 0.001 * total and not stray, (n, len(off), stray[:5])
def is_green(p):
    return p[1] > p[0] + 30 and p[1] > p[2] + 30
background = max(set(px["cpu"]), key=px["cpu"].count)
green = sum(map(is_green, px["cpu"]))
coloured = sum(sum(p) > sum(background) + 60 and not is_green(p) for p in px["cpu"])
print(f"vectors: {green} sheet pixels, {coloured} field pixels")
assert green > 2000 and coloured > 300
PY

# The terrain mode: smooth terrain shaped by seeded brushes (one every 20 ms of wall time, at most
# four a frame, added and carved in turn) — on the Vulkan device (under validation in the optimised build) the thesis's
# pipeline (the field resident, each frame's edits uploading their samples, classify, HistoPyramid
# and an indirect draw); with the CPU renderer and through OpenGL each edit re-meshes its chunks
# for the CPU rasteriser. The CSV's terrain columns count the mesh and the bytes the edits upload
# (or would); the screenshot shows the grass right of the panel, and the brushes' rock, sand and
# snow on it.
trun() {  # name, demo arguments...
  local name=$1
  shift
  local status=0 t0=$SECONDS
  env ${RUN_ENV:-} xvfb-run -a -s "-screen 0 1024x768x24" "$DEMO" --mode terrain --benchmark --frames 40 --interval-ms 20 \
      --width 640 --height 360 --csv "$out/$name.csv" --screenshot "$out/$name.png" "$@" >"$out/$name.out" 2>"$out/$name.err" || status=$?
  if [ "$status" -ne 0 ]; then
    fail "$name: exit status $status: $(tail -5 "$out/$name.err")"
    return
  fi
  grep -q "validation:" "$out/$name.err" && fail "$name: validation messages: $(grep -m3 validation: "$out/$name.err")"
  grep -q "terrain mode" "$out/$name.err" || fail "$name: the demo did not say it is in the terrain mode"
  # 40 frames; at least 5 edits by the end; every row has a mesh; the last edit re-meshed and
  # would upload some chunks, but far less than the whole field (128 x 128 x 64 i8 samples).
  awk -F, 'NR > 1 && $11 < 1000 { bad = 1 } END { exit bad || !(NR == 41 && $5 >= 5 && $10 > 0 && $12 > 0 && $12 < 1048576 / 4) }' "$out/$name.csv" ||
    fail "$name: the terrain columns are wrong: $(tail -1 "$out/$name.csv")"
  /usr/bin/python3 - "$out/$name.png" <<'PY' || fail "$name: the screenshot does not show the edited terrain"
import sys
from PIL import Image
im = Image.open(sys.argv[1]).convert("RGB")
w, h = im.size
px = list(im.crop((370, 0, w, h)).getdata())  # right of the panel
grass = sum(p[1] > p[0] + 15 and p[1] > p[2] + 15 for p in px)
brushed = sum(abs(p[0] - p[1]) < 40 and p[0] > 60 and not (p[1] > p[0] + 15) for p in px)  # rock, sand, snow
print(f"terrain: {grass} grass pixels, {brushed} brushed")
# The edits come on wall time, so a slow build (ASan) makes several times more of them and they
# cover much of the grass: the check is that the terrain fills the view and shows both.
assert grass + brushed > 0.15 * len(px) and grass > 0.02 * len(px) and brushed > 100
PY
  echo "ok: $name, $((SECONDS - t0)) s ($(tail -1 "$out/$name.csv" | cut -d, -f5,10-12))"
}
# Under a sanitizer the validation layer's own work, on ASan's allocator, took 91-115 s of this run's
# 15 s (tests/CMakeLists.txt passes TERRAIN_VALIDATION= there); the optimised build's run of this
# script keeps it, with synchronisation validation.
trun terrain-vulkan --backend vulkan ${TERRAIN_VALIDATION---validation}
grep -q "HistoPyramid and an indirect draw on the Vulkan device" "$out/terrain-vulkan.err" ||
  fail "terrain-vulkan: the GPU did not draw the terrain: $(grep -m1 'terrain mode' "$out/terrain-vulkan.err")"
trun terrain-cpu --backend cpu
[ "$opengl_modes" = 1 ] &&
  RUN_ENV="VK_ICD_FILENAMES=/nonexistent.json VK_DRIVER_FILES=/nonexistent.json" trun terrain-opengl --backend vulkan

# Interactive: real input events through the window system (xdotool). A left click places and a
# right click carves at the ray hit, each a separate edit; F12 saves a screenshot; Ctrl+Q quits
# (within 30 s, well before the runs' cap of 3000 frames).
if command -v xdotool >/dev/null; then
  # The clicks pick in the world itself: with the host's scene (cpu), and with the fields kept on
  # the device only (no host scene).
  interactive() {  # interactive NAME ARGS...
    local name=$1; shift
    mkdir -p "$out/$name"
    local status=0 t0=$SECONDS
    (cd "$out/$name" && DEMO="$DEMO" DEMO_ARGS="$*" xvfb-run -a -s "-screen 0 1024x768x24" bash -c '
      # shellcheck disable=SC2086
      "$DEMO" --world 64 --width 640 --height 360 $DEMO_ARGS --frames 3000 --csv i.csv 2>i.err &
      pid=$!
      win=$(timeout 60 xdotool search --sync --name voxfield-demo | head -1)
      sleep 1
      xdotool mousemove --window "$win" 480 220 click 1   # right of the panel, on the terrain
      sleep 0.5
      xdotool mousemove --window "$win" 480 220 click 3
      sleep 0.3
      xdotool key --window "$win" F12
      sleep 0.3
      xdotool key --window "$win" ctrl+q
      # Ctrl+Q must end the run within 30 s (running out the frame cap would take minutes under ASan).
      for _ in $(seq 60); do kill -0 $pid 2>/dev/null || break; sleep 0.5; done
      if kill -0 $pid 2>/dev/null; then kill $pid; wait $pid; exit 97; fi
      wait $pid') || status=$?
    if [ "$status" -eq 97 ]; then
      fail "$name: Ctrl+Q did not quit within 30 s"
    elif [ "$status" -ne 0 ]; then
      fail "$name: exit status $status: $(tail -3 "$out/$name/i.err" 2>/dev/null)"
    else
      awk -F, 'END { exit !($5 >= 2) }' "$out/$name/i.csv" || fail "$name: the clicks did not edit (edits: $(tail -1 "$out/$name/i.csv"))"
      "$FRAME_CHECK" "$out/$name/voxfield-demo-1.png" || fail "$name: no F12 screenshot of the world"
      echo "ok: $name, $((SECONDS - t0)) s (clicks placed and carved; F12 saved a screenshot)"
    fi
  }
  interactive interactive --backend cpu
  interactive interactive-device-fields --backend vulkan --fields device
  grep -q "its fields computed there" "$out/interactive-device-fields/i.err" ||
    fail "interactive-device-fields: the fields did not go to the device: $(head -3 "$out/interactive-device-fields/i.err")"
  # The terrain mode under the mouse: a left click adds a sphere where the cursor's ray meets the
  # surface, a right click carves one.
  mkdir -p "$out/terrain-interactive"
  status=0 t0=$SECONDS
  (cd "$out/terrain-interactive" && DEMO="$DEMO" xvfb-run -a -s "-screen 0 1024x768x24" bash -c '
    "$DEMO" --mode terrain --width 640 --height 360 --backend cpu --frames 3000 --csv i.csv 2>i.err &
    pid=$!
    win=$(timeout 60 xdotool search --sync --name voxfield-demo | head -1)
    sleep 1
    xdotool mousemove --window "$win" 500 250 click 1
    sleep 0.5
    xdotool mousemove --window "$win" 520 200 click 3
    sleep 0.5
    xdotool key --window "$win" ctrl+q
    # Ctrl+Q must end the run within 30 s (running out the frame cap would take minutes under ASan).
    for _ in $(seq 60); do kill -0 $pid 2>/dev/null || break; sleep 0.5; done
    if kill -0 $pid 2>/dev/null; then kill $pid; wait $pid; exit 97; fi
    wait $pid') || status=$?
  if [ "$status" -eq 97 ]; then
    fail "terrain-interactive: Ctrl+Q did not quit within 30 s"
  elif [ "$status" -ne 0 ]; then
    fail "terrain-interactive: exit status $status: $(tail -3 "$out/terrain-interactive/i.err" 2>/dev/null)"
  else
    awk -F, 'END { exit !($5 >= 2 && $11 > 0) }' "$out/terrain-interactive/i.csv" ||
      fail "terrain-interactive: the clicks did not edit the terrain ($(tail -1 "$out/terrain-interactive/i.csv"))"
    echo "ok: terrain-interactive, $((SECONDS - t0)) s (a click added, a click carved)"
  fi
else
  fail "xdotool is missing (scripts/install-deps.sh installs it)"
fi

# Bad arguments are refused with a message, not a crash.
if "$DEMO" --world 3 >/dev/null 2>"$out/bad.err"; then fail "--world 3 was accepted"; fi
if xvfb-run -a "$DEMO" --load /nonexistent.vox --benchmark --frames 1 >/dev/null 2>"$out/missing.err"; then
  fail "a missing --load file was accepted"
fi
grep -q "nonexistent.vox" "$out/missing.err" || fail "the missing file is not named: $(cat "$out/missing.err")"

[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "voxfield-demo: all checks passed"
