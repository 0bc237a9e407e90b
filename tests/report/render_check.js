#!/usr/bin/env node
// Opens a report.html in headless Chromium (Debian's /usr/bin/chromium) and checks that it works
// as a person would see it: every figure drawn as a Plotly SVG with all its traces, no console
// error, no uncaught exception, no dialog (a sign of injected script), no request leaving the file
// (the report must work offline). Saves a full-page screenshot and checks the PNG: its size is the
// page's, and it is not blank.
//
//   node render_check.js REPORT.html SCREENSHOT.png
//
// Environment: PIEZOBENCH_CHROMIUM overrides /usr/bin/chromium. Exit code 0 when every check
// passes, 1 otherwise (each failure printed). Chromium is driven by npm's puppeteer-core
// (tests/js/browser.js).
'use strict';
const fs = require('node:fs');
const path = require('node:path');
const zlib = require('node:zlib');

const WIDTH = 1280;
const HEIGHT = 900;
const TIMEOUT_MS = Number(process.env.PIEZOBENCH_RENDER_TIMEOUT_MS || 90000);

function usage() {
  console.error('usage: node render_check.js REPORT.html SCREENSHOT.png [--figures LIST.md]');
  process.exit(2);
}

// ---- checks on the embedded document, before any browser ----------------------------------------
function embeddedDocument(html) {
  const m = html.match(/<script type="application\/json" id="pb-data">([\s\S]*?)<\/script>/);
  if (!m) throw new Error('no <script id="pb-data"> in the report');
  return JSON.parse(m[1]);
}

// Figure ids a list promises (docs/report.md: table rows "| 2.5a | `frf-de` | ...").
function promisedFigures(markdown) {
  const ids = [];
  for (const line of markdown.split('\n')) {
    const m = line.match(/^\|\s*[0-9]+\.[0-9]+[a-z]?\s*\|\s*`([a-z0-9-]+)`/);
    if (m) ids.push(m[1]);
  }
  return ids;
}

function nearestIndex(xs, x) {
  let best = -1;
  for (let i = 0; i < xs.length; ++i) {
    if (xs[i] === null) continue;
    if (best < 0 || Math.abs(Math.log(xs[i] / x)) < Math.abs(Math.log(xs[best] / x))) best = i;
  }
  return best;
}

// In every figure with a magnitude panel first and a "Phase" panel, each group's model (dashed)
// and measurement (solid): wherever their magnitudes agree within 25 %, their phases must be within
// 180 degrees (the same branch). Model phases are drawn continuous; in `model-vs` the 2-DoF model's
// zero is minimum phase while the measured one is not, so past the anti-resonance the two are one
// turn apart by design: there a difference within 180 degrees of 360 passes too. Returns the
// failures.
function phaseBranchFailures(data) {
  const failures = [];
  let compared = 0;
  for (const fig of data.figures) {
    if (fig.x_category || fig.panels.length < 2) continue;
    const phasePanel = fig.panels.find((p) => /^Phase/.test(p.y_label));
    if (!phasePanel) continue;
    const magPanel = fig.panels[0];
    const groups = new Set(phasePanel.traces.filter((t) => t.group !== undefined).map((t) => t.group));
    for (const g of groups) {
      const pick = (panel, dash) => panel.traces.find((t) => t.group === g && Boolean(t.dash) === dash);
      const [mMag, dMag, mPh, dPh] = [pick(magPanel, false), pick(magPanel, true), pick(phasePanel, false), pick(phasePanel, true)];
      if (!mMag || !dMag || !mPh || !dPh) continue;
      let worst = 0, worstX = 0;
      for (let i = 0; i < dPh.x.length; ++i) {
        const x = dPh.x[i], y = dPh.y[i];
        if (x === null || y === null || !(x > 0)) continue;
        const a = nearestIndex(dMag.x, x), b = nearestIndex(mMag.x, x), c = nearestIndex(mPh.x, x);
        if (a < 0 || b < 0 || c < 0 || dMag.y[a] === null || mMag.y[b] === null || mPh.y[c] === null) continue;
        if (Math.abs(Math.log(dMag.y[a] / mMag.y[b])) > Math.log(1.25)) continue;
        ++compared;
        let d = Math.abs(y - mPh.y[c]);
        if (fig.id === 'model-vs') d = Math.min(d, Math.abs(d - 360));
        if (d > worst) { worst = d; worstX = x; }
      }
      if (worst > 180) failures.push(`figure ${fig.id}: ${g}: model and measured phase ${worst.toFixed(0)} deg apart at ${worstX.toPrecision(4)} where their magnitudes agree`);
    }
  }
  return { failures, compared };
}

// ---- PNG decoding (8-bit RGB/RGBA, not interlaced: what Chromium writes) -------------------------
function decodePng(buffer) {
  const signature = Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
  if (buffer.length < 8 || !buffer.subarray(0, 8).equals(signature)) throw new Error('not a PNG file');
  let offset = 8;
  let width = 0, height = 0, depth = 0, colourType = 0, interlace = 0;
  const idat = [];
  while (offset + 8 <= buffer.length) {
    const length = buffer.readUInt32BE(offset);
    const type = buffer.toString('latin1', offset + 4, offset + 8);
    const data = buffer.subarray(offset + 8, offset + 8 + length);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      depth = data[8];
      colourType = data[9];
      interlace = data[12];
    } else if (type === 'IDAT') {
      idat.push(data);
    } else if (type === 'IEND') {
      break;
    }
    offset += 12 + length;
  }
  const channels = { 2: 3, 6: 4 }[colourType];
  if (depth !== 8 || channels === undefined || interlace !== 0) {
    throw new Error(`unsupported PNG layout (depth ${depth}, colour type ${colourType}, interlace ${interlace})`);
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  if (raw.length !== height * (stride + 1)) throw new Error('PNG data has the wrong length');
  const pixels = Buffer.alloc(height * stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    const out = pixels.subarray(y * stride, (y + 1) * stride);
    const prev = y > 0 ? pixels.subarray((y - 1) * stride, y * stride) : Buffer.alloc(stride);
    for (let i = 0; i < stride; ++i) {
      const a = i >= channels ? out[i - channels] : 0;
      const b = prev[i];
      const c = i >= channels ? prev[i - channels] : 0;
      let v = line[i];
      if (filter === 1) v += a;
      else if (filter === 2) v += b;
      else if (filter === 3) v += (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        v += pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
      } else if (filter !== 0) throw new Error(`bad PNG filter ${filter}`);
      out[i] = v & 0xff;
    }
  }
  return { width, height, channels, pixels };
}

// Fraction of pixels that are not (near) white, and the number of distinct colours (capped).
function inkStatistics(png) {
  let ink = 0;
  const colours = new Set();
  const n = png.width * png.height;
  for (let k = 0; k < n; ++k) {
    const i = k * png.channels;
    const r = png.pixels[i], g = png.pixels[i + 1], b = png.pixels[i + 2];
    if (r < 235 || g < 235 || b < 235) ++ink;
    if (colours.size < 5000) colours.add((r << 16) | (g << 8) | b);
  }
  return { inkFraction: ink / n, colours: colours.size };
}

const { launchChromium, watchPage } = require('../js/browser.js');

const t0 = Date.now();
function trace(what) { if (process.env.PIEZOBENCH_RENDER_CHECK_VERBOSE) console.error(`${Date.now() - t0} ms: ${what}`); }
function sleep(ms) { return new Promise((resolve) => setTimeout(resolve, ms)); }

async function main() {
  const [reportArg, screenshotArg, ...rest] = process.argv.slice(2);
  if (!reportArg || !screenshotArg) usage();
  let figuresList = null;
  if (rest.length > 0) {
    if (rest[0] !== '--figures' || rest.length !== 2) usage();
    figuresList = rest[1];
  }
  const report = path.resolve(reportArg);
  const screenshot = path.resolve(screenshotArg);
  const failures = [];
  if (!fs.existsSync(report)) throw new Error(`no report at ${report}`);
  fs.rmSync(screenshot, { force: true });
  const embedded = embeddedDocument(fs.readFileSync(report, 'utf8'));
  const phase = phaseBranchFailures(embedded);
  failures.push(...phase.failures);
  let promised = [];
  if (figuresList) {
    promised = promisedFigures(fs.readFileSync(figuresList, 'utf8'));
    if (promised.length === 0) failures.push(`${figuresList} lists no figure ("| 2.5a | \`id\` | ..." rows)`);
    const ids = new Set(embedded.figures.map((f) => f.id));
    for (const id of promised) if (!ids.has(id)) failures.push(`figure ${id}, listed in ${figuresList}, is not in the report`);
  }

  let chromium = null;
  const timer = setTimeout(() => {
    console.error(`render_check: timed out after ${TIMEOUT_MS / 1000} s`);
    const proc = chromium && chromium.browser.process();
    if (proc) proc.kill('SIGKILL');
    process.exit(1);
  }, TIMEOUT_MS);

  try {
    chromium = await launchChromium(WIDTH, HEIGHT);
    trace('chromium started');
    const page = await chromium.browser.newPage();
    const consoleErrors = [];
    watchPage(page, consoleErrors, (url) => /^(file|data|blob|about):/.test(url), 'network request (not offline): ');
    const viewport = (height) => page.setViewport({ width: WIDTH, height, deviceScaleFactor: 1 });

    trace('page ready');
    const started = Date.now();
    await page.goto('file://' + report, { waitUntil: 'domcontentloaded', timeout: TIMEOUT_MS - 5000 });
    const evaluate = (expression) => page.evaluate(expression);
    let state = 'pending';
    while (Date.now() - started < TIMEOUT_MS - 5000) {
      state = await evaluate("(document.getElementById('pb-status') || {dataset: {}}).dataset.state || 'loading'");
      if (state === 'rendered' || state === 'error') break;
      await sleep(100);
    }
    const renderMs = Date.now() - started;
    trace('rendered');
    if (state !== 'rendered') {
      const text = await evaluate("(document.getElementById('pb-status') || {}).textContent || ''");
      failures.push(`report state is "${state}", not "rendered": ${text}`);
    }

    // Every figure of the embedded document has its div, an SVG drawn by Plotly and every trace.
    const check = await evaluate(`(() => {
      const data = JSON.parse(document.getElementById('pb-data').textContent);
      const plotDivs = document.querySelectorAll('div.pb-plot');
      const figures = data.figures.map((fig) => {
        const div = document.getElementById('fig-' + fig.id);
        const expectedTraces = fig.panels.reduce((n, p) => n + p.traces.length, 0);
        return {
          id: fig.id,
          hasDiv: div !== null,
          svg: div ? div.querySelectorAll('svg.main-svg').length : 0,
          drawnTraces: div ? div.querySelectorAll('.cartesianlayer g.trace').length : 0,
          expectedTraces,
          legendEntries: div ? div.querySelectorAll('g.legend g.traces').length : 0,
          height: div ? div.getBoundingClientRect().height : 0,
        };
      });
      return {
        declared: Number(document.getElementById('pb-status').dataset.figures),
        plotDivs: plotDivs.length,
        withSvg: Array.from(plotDivs).filter((d) => d.querySelector('svg.main-svg')).length,
        figures,
        injected: typeof window.__pbInjected !== 'undefined',
        title: document.title,
        pageHeight: Math.ceil(document.documentElement.scrollHeight),
      };
    })()`);
    if (check.plotDivs !== check.figures.length || check.declared !== check.figures.length) {
      failures.push(`${check.plotDivs} plot divs and ${check.declared} declared figures for ${check.figures.length} figures in the data`);
    }
    if (check.withSvg !== check.figures.length) {
      failures.push(`${check.withSvg} of ${check.figures.length} plot divs hold a drawn plot`);
    }
    for (const f of check.figures) {
      if (!f.hasDiv) failures.push(`figure ${f.id}: no div#fig-${f.id}`);
      else if (f.svg === 0) failures.push(`figure ${f.id}: not drawn (no SVG)`);
      else if (f.drawnTraces !== f.expectedTraces) {
        failures.push(`figure ${f.id}: ${f.drawnTraces} traces drawn, ${f.expectedTraces} in the document`);
      }
      if (f.hasDiv && f.height < 100) failures.push(`figure ${f.id}: only ${f.height} px high`);
    }
    if (check.injected) failures.push('a script from the document ran (window.__pbInjected is set)');

    trace('checked');
    // Full-page screenshot at the page's size.
    const height = Math.min(check.pageHeight, 16000);
    await viewport(height);
    await sleep(200);
    await page.screenshot({ path: screenshot, captureBeyondViewport: true, clip: { x: 0, y: 0, width: WIDTH, height, scale: 1 } });
    trace('screenshot');
    // One screenshot per section too (SCREENSHOT-<id>.png), to look at each part at full size.
    const sections = await evaluate(`Array.from(document.querySelectorAll('main > section')).map((s) => {
      const r = s.getBoundingClientRect();
      return { id: s.id, top: r.top + window.scrollY, height: r.height };
    })`);
    const stem = screenshot.replace(/\.png$/, '');
    for (const sec of sections) {
      await viewport(Math.ceil(Math.min(sec.height, 8000)));
      await evaluate(`window.scrollTo(0, ${Math.floor(sec.top)})`);
      await sleep(150);
      await page.screenshot({ path: `${stem}-${sec.id}.png` });
    }
    await viewport(height);
    await evaluate('window.scrollTo(0, 0)');
    await sleep(150);
    trace('section screenshots');

    // Interaction with a real mouse, on the first figure with several panels and a group:
    // hovering a point shows its label; clicking the group's legend entry hides the group's
    // traces in every panel, clicking again shows them.
    const target = state !== 'rendered' ? undefined : await evaluate(`(() => {
      const data = JSON.parse(document.getElementById('pb-data').textContent);
      const fig = data.figures.find((f) => f.panels.length > 1 && f.panels[0].traces.some((t) => t.group));
      if (!fig) return null;
      const gd = document.getElementById('fig-' + fig.id);
      const t = gd.data.findIndex((tr) => tr.legendgroup && tr.legendgroup.startsWith('group:'));
      const trace = gd.data[t];
      const xa = gd._fullLayout.xaxis, ya = gd._fullLayout[trace.yaxis.replace('y', 'yaxis')];
      const k = Math.floor(trace.x.length / 3);
      const box = gd.getBoundingClientRect();
      const legend = Array.from(gd.querySelectorAll('g.legend g.traces'))
        .find((g) => g.textContent === trace.name).querySelector('rect.legendtoggle').getBoundingClientRect();
      // Traces of the same panel with a point within 4 px of the target: any of them may own the label.
      const px = (tr, i) => [xa.l2p(xa.d2l(tr.x[i])), ya.l2p(ya.d2l(tr.y[i]))];
      const [tx, ty] = px(trace, k);
      const near = gd.data.filter((tr) => tr.yaxis === trace.yaxis && tr.x.some((x, i) => {
        if (x === null || tr.y[i] === null) return false;
        const [x2, y2] = px(tr, i);
        return Math.hypot(x2 - tx, y2 - ty) <= 4;
      })).map((tr) => tr.hovertemplate.split('<br>')[0]);
      return {
        near,
        id: fig.id, group: trace.legendgroup, name: fig.panels[0].traces.find((x) => x.group).name,
        members: gd.data.filter((tr) => tr.legendgroup === trace.legendgroup).length,
        panels: new Set(gd.data.filter((tr) => tr.legendgroup === trace.legendgroup).map((tr) => tr.yaxis)).size,
        point: { x: box.left + xa._offset + xa.l2p(xa.d2l(trace.x[k])), y: box.top + ya._offset + ya.l2p(ya.d2l(trace.y[k])) },
        legend: { x: legend.left + legend.width / 2, y: legend.top + legend.height / 2 },
      };
    })()`);
    if (target === undefined) {
      // Not drawn: already a failure.
    } else if (target === null) {
      failures.push('no figure with several panels and grouped traces to check the interaction on');
    } else {
      await page.mouse.move(target.point.x, target.point.y);
      await sleep(300);
      const hover = await evaluate(`Array.from(document.querySelectorAll('#fig-${target.id} .hoverlayer .hovertext')).map((h) => h.textContent).join(' | ')`);
      if (!hover.includes(target.name) && !target.near.some((n) => n && hover.includes(n))) {
        failures.push(`hover on ${target.id}: label "${hover}" names neither "${target.name}" nor a trace drawn at that point`);
      }
      await page.mouse.move(2, 2);
      const hidden = (state) => `document.getElementById('fig-${target.id}')._fullData
        .filter((tr) => tr.legendgroup === ${JSON.stringify(target.group)}).map((tr) => tr.visible === ${state})`;
      for (const [round, state] of [[1, "'legendonly'"], [2, 'true']]) {
        await page.mouse.click(target.legend.x, target.legend.y);
        let flags = [];
        for (let i = 0; i < 30; ++i) {  // Plotly waits for a possible double click first
          await sleep(100);
          flags = await evaluate(hidden(state));
          if (flags.length > 0 && flags.every(Boolean)) break;
        }
        if (flags.length !== target.members || !flags.every(Boolean)) {
          failures.push(`legend click ${round} on ${target.id}: ${flags.filter(Boolean).length} of ${target.members} ` +
            `traces of ${target.group} have visible=${state}`);
        }
      }
      if (target.panels < 2) failures.push(`figure ${target.id}: group ${target.group} spans ${target.panels} panel`);
    }
    trace('interaction');
    failures.push(...consoleErrors);

    // The PNG as written: the expected size, and ink spread over it (not a blank page).
    const png = decodePng(fs.readFileSync(screenshot));
    if (png.width !== WIDTH || png.height !== height) {
      failures.push(`screenshot is ${png.width} x ${png.height} px, expected ${WIDTH} x ${height}`);
    }
    const ink = inkStatistics(png);
    if (ink.inkFraction < 0.02 || ink.colours < 50) {
      failures.push(`screenshot looks blank: ${(100 * ink.inkFraction).toFixed(2)} % ink, ${ink.colours} colours`);
    }

    trace('png');
    if (failures.length === 0) {
      const traces = check.figures.reduce((n, f) => n + f.drawnTraces, 0);
      console.log(`render_check: ${check.figures.length} of ${check.figures.length} figures drawn (${traces} traces) ` +
        `in ${renderMs} ms, no console error; hover label and legend toggle of ${target.group.slice(6)} across ` +
        `${target.panels} panels of ${target.id} work; screenshot ${png.width} x ${png.height} px, ` +
        `${(100 * ink.inkFraction).toFixed(1)} % ink, ${ink.colours}${ink.colours >= 5000 ? '+' : ''} colours: ${screenshot}; ` +
        `model and measured phase on one branch at ${phase.compared} points` +
        (figuresList ? `; the ${promised.length} figures of ${path.basename(figuresList)} present` : ''));
    }
  } finally {
    clearTimeout(timer);
    if (chromium) await chromium.close();
    trace('chromium closed');
  }
  if (failures.length > 0) {
    console.error('render_check: FAILED\n  ' + failures.join('\n  '));
    process.exit(1);
  }
}

main().then(() => process.exit(0)).catch((e) => {
  console.error('render_check: ' + e.message);
  process.exit(1);
});
