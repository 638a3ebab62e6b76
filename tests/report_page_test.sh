#!/usr/bin/env bash
# The report's web page (web/build-report.mjs) in headless Chromium: a mesh voxfield wrote is shown
# by the page's viewer with exactly voxfield's triangle count, the screenshot shows it (pixels of
# the mesh's colours where the background would be), the markdown becomes HTML (a table, an
# image), and a missing model fails with its name and writes no page.
# Needs: VOXFIELD (the CLI), CHROMIUM, WEB (the repo's web/ with node_modules).
set -euo pipefail
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "report_page_test: $*" >&2; exit 1; }

"$VOXFIELD" generate spheres --size 48 --seed 3 -o "$work/world.vox" >/dev/null
"$VOXFIELD" mesh "$work/world.vox" -o "$work/spheres.glb" --stats "$work/stats.json" >/dev/null
triangles=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["triangles"])' "$work/stats.json")
cat > "$work/report.md" <<'MD'
# a test report

| a | b |
|---|---|
| 1 | 2 |

## Section

![picture](picture.png)
MD

# A missing model: exit 1 naming it, no page written.
if node "$WEB/build-report.mjs" "$work" absent.glb 2> "$work/err.txt"; then fail "a missing model was accepted"; fi
grep -q "absent.glb" "$work/err.txt" || fail "the error does not name the model: $(cat "$work/err.txt")"
[ ! -e "$work/report.html" ] || fail "a failed run wrote report.html"

node "$WEB/build-report.mjs" "$work" spheres.glb > /dev/null
chrome() {
  timeout 120 "$CHROMIUM" --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
    --window-size=800,600 --virtual-time-budget=15000 "$@" 2>/dev/null
}
chrome --dump-dom "file://$work/viewer.html" > "$work/dom.html"
grep -q 'data-state="ready"' "$work/dom.html" || fail "the viewer did not load the model: $(grep -o 'voxfield viewer[^<]*' "$work/dom.html" || true)"
shown=$(grep -o 'data-triangles="[0-9]*"' "$work/dom.html" | grep -o '[0-9]*')
[ "$shown" = "$triangles" ] || fail "the viewer shows $shown triangles, voxfield wrote $triangles"
chrome --dump-dom "file://$work/report.html" > "$work/report-dom.html"
grep -q '<table>' "$work/report-dom.html" || fail "the report's table was not rendered"
grep -q '<img src="picture.png"' "$work/report-dom.html" || fail "the report's image was not rendered"
grep -q 'data-state="ready"' "$work/report-dom.html" || fail "the report's viewer did not load"

chrome --screenshot="$work/shot.png" "file://$work/viewer.html" > /dev/null
/usr/bin/python3 - "$work/shot.png" <<'PY'
import sys
from PIL import Image
im = Image.open(sys.argv[1]).convert("RGB")
w, h = im.size
background = (0x1c, 0x1e, 0x24)
centre = [im.getpixel((x, y)) for x in range(w // 4, 3 * w // 4, 4) for y in range(h // 4, 3 * h // 4, 4)]
lit = [p for p in centre if max(abs(a - b) for a, b in zip(p, background)) > 24]
share = len(lit) / len(centre)
if share < 0.15:
    sys.exit(f"report_page_test: only {share:.0%} of the screenshot's centre shows the mesh")
print(f"report_page_test: the mesh covers {share:.0%} of the screenshot's centre")
PY
echo "report_page_test: ok ($triangles triangles shown)"
