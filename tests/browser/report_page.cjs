// Opens an rtcost report in headless Chromium (driven by playwright-core) and checks it as a
// reader would see it: no console error, no uncaught exception, no request leaving the file,
// every plot rendered as SVG with marks, every image decoded, one table row per hierarchy.
// Takes a full-page screenshot. Usage: node report_page.cjs REPORT.html SCREENSHOT.png CHROMIUM
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const { chromium } = require(path.join(__dirname, '../../third_party/js/node_modules/playwright-core'));

async function main() {
  const [html, shot, executable] = process.argv.slice(2);
  const url = 'file://' + path.resolve(html);
  const problems = [];
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'rtcost-chromium-'));
  const started = Date.now();
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: executable,
    headless: true,
    viewport: { width: 1300, height: 900 },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
           '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  try {
    const page = await context.newPage();
    page.on('console', (m) => { if (m.type() === 'error') problems.push('console error: ' + m.text()); });
    page.on('pageerror', (e) => problems.push('uncaught: ' + e.message));
    // Self-contained: the page itself is the only thing it may load.
    await page.route('**/*', (route) => {
      if (route.request().url() === url) return route.continue();
      problems.push('request: ' + route.request().url());
      return route.abort();
    });
    await page.goto(url);
    // The page's script marks the body when every plot is done (or one failed).
    await page.waitForFunction(() => document.body.dataset.plots !== undefined, null, { timeout: 60000 })
      .catch(() => problems.push('the plots never finished (60 s)'));
    const state = await page.evaluate(() => {
      const plots = [...document.querySelectorAll('div.plot')].map((d) => {
        const svg = d.querySelector('svg');
        const box = svg ? svg.getBoundingClientRect() : { width: 0, height: 0 };
        return { id: d.id, width: box.width, height: box.height,
                 marks: svg ? svg.querySelectorAll('g.role-mark > path, g.role-mark > text, g.role-mark > line').length : 0 };
      });
      const images = [...document.querySelectorAll('img')].map((i) => ({ alt: i.alt, ok: i.complete && i.naturalWidth > 0 }));
      return { plots, images, status: document.body.dataset.plots || 'not finished',
               rows: document.querySelectorAll('#eval tbody tr').length,
               hierarchies: JSON.parse(document.getElementById('rtcost-plots').textContent)['plot-speed'].data.values.length };
    });
    if (state.status !== 'done') problems.push('plots: ' + state.status);
    if (state.plots.length < 4) problems.push('expected at least 4 plots, found ' + state.plots.length);
    for (const p of state.plots)
      if (!(p.marks > 0 && p.width > 50 && p.height > 50))
        problems.push(`plot ${p.id}: ${p.marks} marks in ${p.width}x${p.height} px`);
    if (state.images.length < 2) problems.push('expected the render and heat maps, found ' + state.images.length + ' images');
    for (const i of state.images) if (!i.ok) problems.push('image not decoded: ' + i.alt);
    if (state.rows !== state.hierarchies || state.rows === 0)
      problems.push(`table has ${state.rows} rows for ${state.hierarchies} hierarchies`);
    await page.screenshot({ path: shot, fullPage: true });
    const summary = state.plots.map((p) => `${p.id} ${p.marks} marks`).join(', ');
    console.log(`report_page: ${state.plots.length} plots (${summary}), ${state.images.length} images, ` +
                `${state.rows} rows; screenshot ${shot}; ${((Date.now() - started) / 1000).toFixed(1)} s in Chromium`);
  } finally {
    await context.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
  if (problems.length) {
    for (const p of problems) console.error('report_page: FAIL: ' + p);
    process.exit(1);
  }
}

main().catch((e) => { console.error('report_page: FAIL: ' + (e.stack || e)); process.exit(1); });
