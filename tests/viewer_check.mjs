// Opens a page written by pic::view_html in headless Chromium and checks that it works
// offline: a canvas appears, the model is drawn in the middle, no console errors, no
// network requests. Used by viewer_test.cpp.
//
// usage: node viewer_check.mjs PAGE.html SCREENSHOT.png
// env:   PIC_NODE_MODULES_DIR  directory holding node_modules/playwright-core (default: here)
//        PIC_CHROMIUM          browser executable (default: /usr/bin/chromium)
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const [page_path, shot_path] = process.argv.slice(2);
if (!page_path || !shot_path) {
  console.error('usage: node viewer_check.mjs PAGE.html SCREENSHOT.png');
  process.exit(2);
}
const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(process.env.PIC_NODE_MODULES_DIR || here, 'resolve-from-here.js'));
const { chromium } = require('playwright-core');

const browser = await chromium.launch({
  executablePath: process.env.PIC_CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
         '--disable-component-update', '--disable-sync', '--no-first-run',
         // WebGL without a GPU: Chromium's software renderer, which it no longer picks alone.
         '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  timeout: 60000,
});
const problems = [];
try {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  page.on('console', (m) => { if (m.type() === 'error') problems.push('console error: ' + m.text()); });
  page.on('pageerror', (e) => problems.push('page error: ' + e.message));
  page.on('request', (r) => {
    if (!/^(file|data|blob):/.test(r.url())) problems.push('network request: ' + r.url());
  });
  await page.goto(pathToFileURL(path.resolve(page_path)).href);
  await page.waitForSelector('canvas', { timeout: 30000 });
  await page.waitForFunction(() => window.picViewerReady === true, null, { timeout: 30000 });
  for (const box of await page.$$('#ui input[type=checkbox]:not([disabled])')) await box.check();
  const png = await page.screenshot({ path: shot_path });

  // Decode the screenshot in the page itself (no PNG decoder needed here) and count the
  // pixels of the middle third that differ from the background.
  const middle = await page.evaluate(async (b64) => {
    const img = new Image();
    img.src = 'data:image/png;base64,' + b64;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const w = Math.floor(img.width / 3), h = Math.floor(img.height / 3);
    const d = g.getImageData(w, h, w, h).data;
    let foreground = 0;
    for (let i = 0; i < d.length; i += 4)
      if (Math.abs(d[i] - 250) + Math.abs(d[i + 1] - 250) + Math.abs(d[i + 2] - 252) > 30) foreground++;
    return { foreground, total: w * h };
  }, png.toString('base64'));
  const checked = await page.$$eval('#ui input:checked', (l) => l.length);
  const stats = await page.textContent('#stats');
  console.log(JSON.stringify({ middle, checked, stats_chars: stats.length }));
  if (middle.foreground < 0.3 * middle.total) problems.push('the middle of the page is mostly background');
  if (checked < 1) problems.push('no toggle could be checked');
} catch (e) {
  problems.push(String(e));
} finally {
  await browser.close();
}
for (const p of problems) console.error(p);
process.exit(problems.length ? 1 : 0);
