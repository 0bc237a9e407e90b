#!/usr/bin/env node
// The station's live page in a real browser (issue 29): runs `piezobench qualify --ui 127.0.0.1:0
// --paced` on the virtual bench with no answers file and no terminal (its operator steps must be
// answered in the page), opens the page in headless Chromium (Debian's, driven by npm's
// puppeteer-core: tests/js/browser.js) and checks, as an operator would see it:
//   - the page loads with no console error, no uncaught exception, no request leaving the station;
//   - every phase is seen running and then finished, in order;
//   - the live signals and the FRF update while the phases run (screen samples arrive at 10-20 Hz,
//     the FRF's average count grows);
//   - each operator prompt appears as buttons; clicking "confirm" with the mouse resumes the run;
//   - the typed capacitances are asked in the page: a bad value (-1 uF) is refused with the
//     terminal's words (qualify's own refusal on stdin, run alongside) and good ones are taken
//     and end up in the verdict table;
//   - a sample reaches the page less than 200 ms after it was measured (the sample's measurement
//     time, server clock, against its arrival, both on the server's clock);
//   - the final verdict table equals the terminal's (qualify's stdout) and the database's (db show
//     --json), measurement by measurement;
//   - the database tab lists the unit and its certificate link answers;
//   - hostile requests while the phases run (oversized, unknown and escaping paths, foreign Host and
//     Origin, an answer without the operator token, 1,000 concurrent connections) are refused
//     cleanly and the qualification goes on;
//   - Ctrl-C with the page's stream open ends qualify within 1 s.
// Screenshots: OUT/typed.png (a typed value refused), OUT/live.png (during the FRF phase),
// OUT/final.png, OUT/database.png.
//
//   node station_page_check.js PIEZOBENCH BENCH.toml STATION.toml OUT_DIR
'use strict';
const { spawn, execFileSync } = require('node:child_process');
const fs = require('node:fs');
const path = require('node:path');
const { launchChromium, watchPage } = require('../js/browser.js');

const WIDTH = 1280, HEIGHT = 1100;
const TIMEOUT_MS = Number(process.env.PIEZOBENCH_PAGE_TIMEOUT_MS || 100000);
const LATENCY_LIMIT_MS = 200;
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
// A latency in the summary: none when no sample arrived (the failures then say why).
const ms = (x) => (typeof x === 'number' ? x.toFixed(0) : 'none');
const t0 = Date.now();
// What happened when: printed as it happens with PIEZOBENCH_PAGE_CHECK_VERBOSE, and with the failures.
const traced = [];
const trace = (what) => {
  const line = `${Date.now() - t0} ms: ${what}`;
  traced.push(line);
  if (process.env.PIEZOBENCH_PAGE_CHECK_VERBOSE) console.error(line);
};

// qualify's table on stdout: "      NAME   VALUE UNIT [MIN, MAX] VERDICT" under "  PHASE  try N ...".
function terminalTable(text) {
  const rows = [];
  let phase = null;
  for (const line of text.split('\n')) {
    let m = line.match(/^  (\S+)\s+try \d+ (\S+)/);
    if (m) { phase = m[1]; continue; }
    m = line.match(/^      (\S+)\s+(\S+) (\S*)\s+\[([^\]]*)\] (pass|marginal|fail)$/);
    if (m && phase) rows.push({ phase, name: m[1], value: m[2] === 'none' ? null : Number(m[2]), verdict: m[5] });
  }
  return rows;
}

function compareTables(what, expected, found, relative, failures) {
  if (expected.length !== found.length) {
    failures.push(`${what}: ${expected.length} measurements, the page shows ${found.length}`);
    return;
  }
  for (let i = 0; i < expected.length; ++i) {
    const e = expected[i], f = found[i];
    const same = e.phase === f.phase && e.name === f.name && e.verdict === f.verdict &&
      ((e.value === null && f.value === null) || Math.abs(e.value - f.value) <= relative * Math.abs(e.value));
    if (!same) failures.push(`${what}: row ${i} is ${JSON.stringify(e)}, the page shows ${JSON.stringify(f)}`);
  }
}

// Hostile requests while the station runs, over raw sockets: each must get a clean refusal (the
// status given) and the station must go on. Returns the failures.
function rawRequest(port, text, timeoutMs = 5000) {
  const net = require('node:net');
  return new Promise((resolve) => {
    let data = '';
    const socket = net.connect(port, '127.0.0.1', () => socket.write(text));
    socket.setTimeout(timeoutMs, () => socket.destroy());
    socket.on('data', (d) => { data += d.toString('latin1'); });
    socket.on('error', () => {});
    socket.on('close', () => resolve(Number((data.match(/^HTTP\/1\.1 (\d{3})/) || [])[1] || 0)));
  });
}

async function hostileBurst(port) {
  const get = (target, extra = '') => `GET ${target} HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nConnection: close\r\n${extra}\r\n`;
  const cases = [
    ['oversized headers', get('/', 'X-Pad: ' + 'a'.repeat(20000) + '\r\n'), 431],
    ['oversized body', `POST /api/answer HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nContent-Length: 99999999\r\n\r\n`, 413],
    ['unknown path', get('/etc/passwd'), 404],
    ['dot-dot', get('/../../etc/passwd'), 400],
    ['encoded dot-dot', get('/%2e%2e/%2e%2e/etc/passwd'), 400],
    ['foreign Host', `GET / HTTP/1.1\r\nHost: evil.example\r\nConnection: close\r\n\r\n`, 421],
    ['foreign Origin', get('/api/state', 'Origin: http://evil.example\r\n'), 403],
    ['answer without the operator token', `POST /api/answer HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nContent-Length: 25\r\nConnection: close\r\n\r\n{"id":1,"answer":"abort"}`, 403],
  ];
  const failures = [];
  for (const [what, text, expected] of cases) {
    const status = await rawRequest(port, text);
    if (status !== expected) failures.push(`hostile request (${what}): HTTP ${status}, expected ${expected}`);
  }
  // 1,000 concurrent connections: each one served (200) or refused (503), none left hanging.
  const statuses = await Promise.all(Array.from({ length: 1000 }, () => rawRequest(port, get('/api/state'), 10000)));
  const served = statuses.filter((x) => x === 200).length, busy = statuses.filter((x) => x === 503).length;
  if (served + busy !== 1000 || served < 1) failures.push(`1,000 concurrent connections: ${served} served, ${busy} refused 503, ${1000 - served - busy} other`);
  return { failures, served, busy };
}

// Takes `count` of the station's event streams with raw sockets (each answered 200 and kept open);
// resolves to a function that closes them.
async function holdStreams(port, count) {
  const net = require('node:net');
  const sockets = await Promise.all(Array.from({ length: count }, () => new Promise((resolve) => {
    const socket = net.connect(port, '127.0.0.1', () => socket.write(`GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\n\r\n`));
    let head = '';
    socket.on('data', (d) => { if (head.length < 64) { head += d.toString('latin1'); if (/^HTTP\/1\.1 \d{3}/.test(head)) resolve(socket); } });
    socket.on('error', () => resolve(socket));
    socket.setTimeout(5000, () => resolve(socket));
  })));
  return () => { for (const socket of sockets) socket.destroy(); };
}

// Types the capacitances in the page's fields as an operator would: first a bad sensor value
// (-1 uF), which the station must refuse with the terminal's words (the prompt staying open), then
// 5.2 and 10.1 uF. Returns { refusal, accepted }.
async function typeValues(page, mouseClick, shotPath) {
  const fill = async (name, text) => {
    await page.click(`#prompt-fields input[name="${name}"]`, { clickCount: 3 });
    await page.keyboard.press('Backspace');
    await page.type(`#prompt-fields input[name="${name}"]`, text);
  };
  await fill('sensor_uF', '-1');
  await fill('actuator_uF', '10.1');
  await mouseClick('#prompt-buttons button[data-answer="confirm"]');
  let refusal = '';
  for (let i = 0; i < 50 && !refusal; ++i) {
    await sleep(100);
    refusal = await page.evaluate("document.getElementById('prompt').hidden ? 'closed' : document.getElementById('prompt-error').textContent");
  }
  refusal = refusal.replace(/^Not answered: /, '');
  // The refusal in the page: the top of the page down to the prompt's box.
  const bottom = await page.evaluate("Math.ceil(document.getElementById('prompt').getBoundingClientRect().bottom) + 12");
  await page.screenshot({ path: shotPath, clip: { x: 0, y: 0, width: WIDTH, height: Math.min(bottom, HEIGHT) } });
  await fill('sensor_uF', '5.2');
  await mouseClick('#prompt-buttons button[data-answer="confirm"]');
  let accepted = false;
  for (let i = 0; i < 50 && !accepted; ++i) {
    await sleep(100);
    accepted = await page.evaluate("document.getElementById('prompt').hidden || document.getElementById('prompt').dataset.id !== String((window.pbLive.state.prompt || {}).id)");
  }
  return { refusal, accepted };
}

// The terminal's refusal of the same bad value: qualify with the same station, its prompts
// answered on stdin (y to the first step, -1 for the sensor's capacitance); the message it exits with.
function terminalRefusal(binary, bench, station, out) {
  const { spawnSync } = require('node:child_process');
  const r = spawnSync(binary, ['qualify', '--bench', bench, '--station', station, '--serial', 'TERM-0001', '--db', path.join(out, 'terminal.db'),
    '--data', path.join(out, 'terminal-data')], { input: 'y\n-1\n', encoding: 'utf8', timeout: 60000 });
  return ((r.stderr || '').match(/error: (operator: [^\n]*sensor_uF[^\n]*)/) || ['', `no refusal (exit ${r.status}): ${(r.stderr || '').slice(-300)}`])[1];
}

async function main() {
  const [binary, bench, station, outArg] = process.argv.slice(2);
  if (!outArg) { console.error('usage: node station_page_check.js PIEZOBENCH BENCH.toml STATION.toml OUT_DIR'); process.exit(2); }
  const out = path.resolve(outArg);
  fs.rmSync(out, { recursive: true, force: true });
  fs.mkdirSync(out, { recursive: true });
  const failures = [];
  const db = path.join(out, 'station.db');
  const serial = 'WEB-0001';

  // The station, its stdin closed: only the page can answer.
  const qualify = spawn(binary, ['qualify', '--bench', bench, '--station', station, '--serial', serial, '--batch', 'W1', '--db', db,
    '--data', path.join(out, 'data'), '--paced', '--ui', '127.0.0.1:0', '--ui-linger', '60'], { stdio: ['ignore', 'pipe', 'pipe'] });
  let stdout = '', stderr = '';
  qualify.stdout.on('data', (d) => { stdout += d; });
  qualify.stderr.on('data', (d) => { stderr += d; });
  const qualifyExit = new Promise((resolve) => qualify.on('exit', (code, signal) => resolve({ code, signal, at: Date.now() })));
  let url = null;
  for (let i = 0; i < 100 && !url; ++i) {
    const m = stderr.match(/station page: (http:\/\/127\.0\.0\.1:\d+\/)#token=([0-9a-f]+)/);
    if (m) url = { base: m[1], token: m[2] };
    else await sleep(50);
  }
  if (!url) throw new Error('qualify printed no page address:\n' + stderr);
  trace('qualify serving ' + url.base);

  let chromium = null;
  const timer = setTimeout(() => {
    console.error(`station_page_check: timed out after ${TIMEOUT_MS / 1000} s\n${stderr.slice(-3000)}`);
    const proc = chromium && chromium.browser.process();
    if (proc) proc.kill('SIGKILL');
    qualify.kill('SIGKILL');
    process.exit(1);
  }, TIMEOUT_MS);

  let summary = '';
  try {
    chromium = await launchChromium(WIDTH, HEIGHT);
    const page = await chromium.browser.newPage();
    const consoleErrors = [];
    watchPage(page, consoleErrors, (u) => u.startsWith(url.base) || /^(data|blob|about):/.test(u), 'request outside the station: ');
    const evaluate = (expression) => page.evaluate(expression);
    const screenshot = (file) => page.screenshot({ path: path.join(out, file) });
    // A click with the mouse at the element's centre (scrolled into view); false when it is absent.
    const mouseClick = async (selector) => {
      const element = await page.$(selector);
      if (!element) return false;
      await element.click();
      return true;
    };

    // Every stream the station serves taken (max_streams, 16): the page's stream is refused (503) and
    // the browser closes it for good; the page must ask again by itself once one is free.
    const port = Number(url.base.match(/:(\d+)\//)[1]);
    const releaseStreams = await holdStreams(port, 16);
    await page.goto(url.base + '#token=' + url.token, { waitUntil: 'load' });
    let refusedOnce = false;
    for (let i = 0; i < 100 && !refusedOnce; ++i) { await sleep(50); refusedOnce = await evaluate('!!window.pbLive && window.pbLive.reconnects > 0'); }
    releaseStreams();
    if (!refusedOnce) failures.push('with every stream taken, the page saw no refusal of its own (pbLive.reconnects = 0)');
    let reconnectedMs = null;
    const released = Date.now();
    for (let i = 0; i < 100 && reconnectedMs === null; ++i) {
      if (await evaluate("document.getElementById('pb-status').dataset.state === 'connected'")) reconnectedMs = Date.now() - released;
      else await sleep(100);
    }
    if (reconnectedMs === null) failures.push('the page did not connect within 10 s of a stream becoming free');
    trace(`stream refused, then connected ${reconnectedMs} ms after the streams were freed`);
    let loaded = false;
    for (let i = 0; i < 100 && !loaded; ++i) {
      loaded = await evaluate("document.readyState === 'complete' && !!window.pbLive");
      if (!loaded) await sleep(50);
    }
    if (!loaded) throw new Error('the page did not load within 5 s');
    trace('loaded');
    // Follow the qualification: answer each prompt with the mouse, watch the live data.
    let hostile = null, typed = null;
    const answered = [];
    const samplesAt = [];
    const frfAverages = new Set();
    let liveShot = false, complete = false;
    const deadline = Date.now() + 60000;
    while (Date.now() < deadline) {
      const s = await evaluate(`(() => { const l = window.pbLive || {}; const st = l.state || {};
        const box = document.getElementById('prompt');
        return { state: document.getElementById('pb-status').dataset.state, status: st.status, prompt: st.prompt ? st.prompt.id : null,
          stream: l.source ? l.source.readyState : null, reconnects: l.reconnects,
          fields: st.prompt && st.prompt.fields ? st.prompt.fields.length : 0,
          shown: box && !box.hidden ? box.dataset.id : null, samples: l.samplesReceived || 0, frf: l.frf ? l.frf.averages : null,
          frfPhase: l.frf ? l.frf.phase : null, drawn: document.querySelectorAll('#plot-signals .scatterlayer .trace').length }; })()`);
      samplesAt.push({ t: Date.now(), n: s.samples });
      if (samplesAt.length % 50 === 1) {
        trace(`page: ${s.state}, run ${s.status}, prompt ${s.prompt} (shown ${s.shown}), stream readyState ${s.stream} after ${s.reconnects} refusals, ${s.samples} samples`);
      }
      if (s.frf !== null) frfAverages.add(s.frf);
      if (s.shown && s.prompt !== null && String(s.prompt) === s.shown && !answered.includes(s.prompt)) {
        if (hostile) await hostile;  // the page's own requests must not meet the burst's 503s
        await sleep(300);  // an operator reads it
        if (s.fields > 0) {
          typed = await typeValues(page, mouseClick, path.join(out, 'typed.png'));
          if (typed.accepted) answered.push(s.prompt);
        } else if (await mouseClick('#prompt-buttons button[data-answer="confirm"]')) answered.push(s.prompt);
        trace('answered prompt ' + s.prompt);
        if (answered.length === 1) hostile = hostileBurst(port);  // while the phases run
      }
      if (!liveShot && s.frf !== null && s.frf >= 3 && s.drawn > 0) {
        await screenshot('live.png');
        liveShot = true;
      }
      if (s.status === 'complete' || s.status === 'aborted' || s.status === 'failed') { complete = s.status === 'complete'; break; }
      await sleep(100);
    }
    trace('qualification over');
    if (!complete) failures.push('the qualification did not complete within 60 s: ' + stderr.slice(-1500));
    if (answered.length !== 3) failures.push(`${answered.length} prompts answered in the page, the station asks 3`);
    // The typed capacitances: a bad value refused with the terminal's words, then taken.
    const refusal = terminalRefusal(binary, bench, station, out);
    if (!typed) failures.push('no prompt asked for typed values');
    else {
      if (!typed.refusal || refusal !== typed.refusal) failures.push(`typed -1 uF: the page says "${typed.refusal}", the terminal "${refusal}"`);
      if (!typed.accepted) failures.push('the typed values 5.2 and 10.1 uF were not taken');
    }
    const hostileResult = hostile ? await hostile : { failures: ['the hostile requests did not run'], served: 0, busy: 0 };
    failures.push(...hostileResult.failures);
    await sleep(400);  // the last state and samples

    const live = await evaluate(`(() => { const l = window.pbLive; const lat = l.latencies.slice().sort((a, b) => a - b);
      const q = (p) => lat.length ? lat[Math.min(lat.length - 1, Math.floor(p * lat.length))] : null;
      const seen = {}; for (const [k, v] of Object.entries(l.phasesSeen)) seen[k] = Array.from(v);
      return { latencies: lat.length, p50: q(0.5), p99: q(0.99), max: lat.length ? lat[lat.length - 1] : null, seen, samples: l.samplesReceived,
        messages: l.messages, phases: l.state.phases.map((p) => ({ name: p.name, state: p.state, record_s: p.record_s, started_ms: p.started_ms, finished_ms: p.finished_ms })),
        table: Array.from(document.querySelectorAll('#verdicts tbody tr[data-name]')).map((r) => ({ phase: r.dataset.phase, name: r.dataset.name,
          value: r.dataset.value === '' ? null : Number(r.dataset.value), verdict: r.dataset.verdict })),
        certificate: !!document.getElementById('certificate-link'), verdict: (document.getElementById('unit-verdict') || {}).textContent }; })()`);
    // Phases advance: each one started after the one before it and finished; those that take time
    // (a record on the paced bench) were seen running. An instrument phase (flatness, capacitance)
    // lasts milliseconds: the page's mailbox may skip its running state, by design.
    let previousStart = 0;
    for (const p of live.phases) {
      const seen = live.seen[p.name] || [];
      if (p.record_s > 1 && !seen.includes('running') && !seen.includes('retried')) failures.push(`phase ${p.name} was never seen running (${seen.join(', ')})`);
      if (!['passed', 'marginal', 'failed'].includes(p.state)) failures.push(`phase ${p.name} ends ${p.state}`);
      if (!(p.started_ms >= previousStart && p.finished_ms >= p.started_ms)) failures.push(`phase ${p.name} did not start after the one before it`);
      previousStart = p.started_ms;
    }
    const seenRunning = live.phases.filter((p) => (live.seen[p.name] || []).includes('running')).length;
    // The signals: screen samples arrived during the paced phases, at a screen rate (10-20 per second of signal).
    const growth = samplesAt.filter((x, i) => i > 0 && x.n > samplesAt[i - 1].n).length;
    if (live.samples < 50 || growth < 10) failures.push(`live signals: ${live.samples} screen samples in ${growth} updates`);
    if (frfAverages.size < 3) failures.push(`FRF built up over ${frfAverages.size} average counts (${Array.from(frfAverages).join(', ')})`);
    // p99 within the limit; the worst sample may meet a pause of the shared machine, within 2.5 x.
    if (live.latencies < 50 || !(live.p99 < LATENCY_LIMIT_MS) || !(live.max < 2.5 * LATENCY_LIMIT_MS)) {
      failures.push(`latency: ${live.latencies} samples, p50 ${live.p50} ms, p99 ${live.p99} ms, max ${live.max} ms (limit ${LATENCY_LIMIT_MS} ms)`);
    }
    if (!live.certificate) failures.push('no certificate link after the qualification');
    await page.setViewport({ width: WIDTH, height: 1700, deviceScaleFactor: 1 });
    await sleep(300);
    await screenshot('final.png');

    // The verdict table: the terminal's and the database's.
    const terminal = terminalTable(stdout);
    compareTables('terminal', terminal, live.table, 1e-4, failures);
    const shown = JSON.parse(execFileSync(binary, ['db', 'show', serial, '--json', '--db', db], { encoding: 'utf8' }));
    const database = [];
    for (const t of shown.phase_tries) for (const m of t.measurements) database.push({ phase: t.phase, name: m.name, value: m.value, verdict: m.verdict });
    compareTables('database', database, live.table, 0, failures);

    // The database tab.
    await mouseClick('#tab-db');
    let dbState = null;
    for (let i = 0; i < 50 && dbState !== 'loaded'; ++i) { await sleep(100); dbState = await evaluate("document.getElementById('pb-status').dataset.database || ''"); }
    const dbView = await evaluate(`({ rows: Array.from(document.querySelectorAll('#quals tbody tr')).map((r) => r.dataset.serial),
      charts: document.querySelectorAll('#charts .plot .main-svg').length })`);
    if (!dbView.rows.includes(serial)) failures.push(`the database tab lists ${JSON.stringify(dbView.rows)}, not ${serial}`);
    if (dbView.charts < 1) failures.push('the database tab draws no control chart');
    await mouseClick(`#quals tbody tr[data-serial="${serial}"] button`);
    await sleep(400);
    await screenshot('database.png');
    const cert = await evaluate(`fetch('/api/certificate/${serial}', {headers: {Authorization: 'Bearer ${url.token}'}}).then(async (r) => [r.status, (await r.text()).length])`);
    if (cert[0] !== 200 || cert[1] < 1000) failures.push(`certificate: HTTP ${cert[0]}, ${cert[1]} bytes`);
    // The refused value's answer is a 422 by design: Chromium logs it as a failed load, once.
    const refused = consoleErrors.findIndex((e) => /status of 422/.test(e) && /\/api\/answer/.test(e));
    if (refused >= 0) consoleErrors.splice(refused, 1);
    // So is the stream's 503 while every stream was taken (Chromium words it as a failed load or an aborted EventSource).
    for (let i = consoleErrors.length - 1; i >= 0; --i) if (/503/.test(consoleErrors[i]) && /api\/events|EventSource/.test(consoleErrors[i])) consoleErrors.splice(i, 1);
    failures.push(...consoleErrors);

    // Ctrl-C with the page's event stream open: qualify ends within 1 s.
    await mouseClick('#tab-live');
    const streams = await evaluate('window.pbLive.source.readyState');
    const before = Date.now();
    qualify.kill('SIGINT');
    const end = await Promise.race([qualifyExit, sleep(5000).then(() => null)]);
    const shutdownMs = end ? end.at - before : null;
    if (streams !== 1) failures.push(`the page's event stream is not open before Ctrl-C (readyState ${streams})`);
    if (!end) failures.push('qualify did not end within 5 s of Ctrl-C');
    else if (shutdownMs >= 1000) failures.push(`qualify ended ${shutdownMs} ms after Ctrl-C (limit 1000 ms)`);
    else if (end.code !== 0) failures.push(`qualify exited with ${end.code} (${end.signal})`);
    summary = `station_page_check: ${live.phases.length} phases finished in order (${seenRunning} seen running), ${answered.length} prompts answered in the page, ` +
      `${live.samples} screen samples in ${live.messages} messages, FRF averages ${Array.from(frfAverages).sort((a, b) => a - b).join(',')}; ` +
      `latency sample -> page p50 ${ms(live.p50)} ms, p99 ${ms(live.p99)} ms, max ${ms(live.max)} ms over ${live.latencies} samples; ` +
      `verdict table (${live.table.length} measurements, unit ${live.verdict}) equal to the terminal's and the database's; ` +
      `hostile requests refused cleanly while it ran (1,000 concurrent: ${hostileResult.served} served, ${hostileResult.busy} refused 503); ` +
      `a refused stream asked again (connected ${reconnectedMs} ms after a stream was free); no console error; Ctrl-C with a stream open: exit in ${shutdownMs} ms; screenshots in ${out}`;
  } finally {
    clearTimeout(timer);
    if (chromium) await chromium.close();
    qualify.kill('SIGKILL');
  }
  if (failures.length > 0) {
    console.error('station_page_check: FAILED\n  ' + failures.join('\n  ') + '\n--- trace:\n' + traced.join('\n') +
      '\n--- qualify stderr (end):\n' + stderr.slice(-2000));
    process.exit(1);
  }
  console.log(summary);
}

main().then(() => process.exit(0)).catch((e) => {
  console.error('station_page_check: ' + e.stack + '\n--- trace:\n' + traced.join('\n'));
  process.exit(1);
});
