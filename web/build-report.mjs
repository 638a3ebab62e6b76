// The showcase's report as a web page: OUT/report.md rendered to OUT/report.html (marked), with
// the terrain's .glb orbitable in the page (viewer.js, bundled by esbuild into one classic script,
// and each model as a script of base64), plus OUT/viewer.html, the viewer alone. Everything the
// pages need is written beside them: they open from disk with nothing fetched.
//
// usage: node web/build-report.mjs OUT [MODEL.glb ...]   (default model: terrain-field.glb)
// Exit status 1 with a message naming the file when an input is missing or unreadable. Every file
// is written under a temporary name first and the temporaries are renamed only once all are
// written, report.html last; a failed run removes its temporaries and leaves the pages as they
// were.
import { readFileSync, writeFileSync, renameSync, rmSync } from 'node:fs';
import { join, dirname, basename } from 'node:path';
import { fileURLToPath } from 'node:url';
import { build } from 'esbuild';
import { marked } from 'marked';

const here = dirname(fileURLToPath(import.meta.url));
const [out, ...requested] = process.argv.slice(2);
if (!out) {
  console.error('usage: node web/build-report.mjs OUT [MODEL.glb ...]');
  process.exit(2);
}
const models = requested.length ? requested : ['terrain-field.glb'];

function read(path) {
  try {
    return readFileSync(path);
  } catch (e) {
    console.error(`build-report: cannot read ${path}: ${e.code === 'ENOENT' ? 'no such file' : e.message}`);
    process.exit(1);
  }
}

const pending = [];  // [temporary, final], in the order they are renamed
function stage(path, text) {
  const temporary = `${path}.tmp-${process.pid}`;
  pending.push([temporary, path]);
  writeFileSync(temporary, text);
}
function commit() {
  for (const [temporary, path] of pending) renameSync(temporary, path);
}
function discard() {
  for (const [temporary] of pending) rmSync(temporary, { force: true });
}

const escapeHtml = (s) => s.replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);

const markdown = read(join(out, 'report.md')).toString('utf8');
const glbs = models.map((name) => {
  const bytes = read(join(out, name));
  if (bytes.length < 12 || bytes.toString('latin1', 0, 4) !== 'glTF') {
    console.error(`build-report: ${join(out, name)} is not a glTF binary (no "glTF" magic)`);
    process.exit(1);
  }
  return { name, bytes };
});

const bundle = await build({
  entryPoints: [join(here, 'viewer.js')],
  bundle: true,
  format: 'iife',
  minify: true,
  write: false,
  logLevel: 'silent',
  absWorkingDir: here,
});

const style = `
  body { font: 15px/1.5 system-ui, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
         color: #1d1f24; }
  img { max-width: 100%; }
  table { border-collapse: collapse; margin: 1em 0; font-size: 13px; }
  th, td { border: 1px solid #c8ccd4; padding: 3px 7px; vertical-align: top; }
  th { background: #eef0f4; }
  code { background: #f1f2f5; padding: 0 3px; border-radius: 3px; }
  .voxfield-viewer { width: 100%; height: 560px; background: #1c1e24; color: #eee; }
  .voxfield-viewer[data-standalone] { height: 100vh; }
`;
const modelScripts = glbs.map(({ name }) => `<script src="${escapeHtml(name)}.js"></script>`).join('\n');
const viewers = glbs
  .map(({ name }) => `<div class="voxfield-viewer" data-model="${escapeHtml(name)}"></div>\n<p><code>${escapeHtml(name)}</code>: drag to orbit, wheel to zoom, right-drag to pan.</p>`)
  .join('\n');

// The body: the report, with the 3-D view inserted before its first second-level heading.
let body = marked.parse(markdown);
const firstSection = body.indexOf('<h2');
const view = `<h2>The edited terrain in 3-D</h2>\n${viewers}\n`;
body = firstSection < 0 ? body + view : body.slice(0, firstSection) + view + body.slice(firstSection);

const page = (title, content, standalone) => `<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>${escapeHtml(title)}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>${style}${standalone ? ' body { max-width: none; margin: 0; padding: 0; }' : ''}</style>
</head><body>
${content}
${modelScripts}
<script src="viewer.js"></script>
</body></html>
`;

try {
  for (const { name, bytes } of glbs)
    stage(join(out, `${name}.js`),
      `window.voxfieldModels = window.voxfieldModels || {};\nwindow.voxfieldModels[${JSON.stringify(name)}] = "${bytes.toString('base64')}";\n`);
  stage(join(out, 'viewer.js'), bundle.outputFiles[0].text);
  stage(join(out, 'viewer.html'),
    page(`voxfield — ${glbs[0].name}`, `<div class="voxfield-viewer" data-standalone data-model="${escapeHtml(glbs[0].name)}"></div>`, true));
  stage(join(out, 'report.html'), page('voxfield showcase', body, false));
} catch (e) {
  discard();
  console.error(`build-report: cannot write into ${out}: ${e.message}`);
  process.exit(1);
}
commit();
console.log(`build-report: ${join(out, 'report.html')} and ${join(out, 'viewer.html')} (${glbs.map((g) => g.name).join(', ')})`);
