#!/usr/bin/env node
// The live signals of a hardware bench while its record runs (issue 29): `piezobench bench serve`
// (the virtual bench behind the UDP I/O protocol, on loopback) and `qualify --ui` against it over
// UDP; this script reads the page's event stream (/api/events, what the page reads) and checks:
//   - the record's screen samples arrive while the record is being measured, not when it ends:
//     most of them reach the stream before the record's last sample was measured;
//   - a sample reaches the stream less than 200 ms after it was measured (the median; p99 printed;
//     the sample's measurement time and its arrival, both on this machine's clock);
//   - the record's whole length is shown once (about 20 screen samples per second of record,
//     no second copy when the record is handed over at its end);
//   - qualify completes and exits 0.
//
//   node station_udp_live_check.js PIEZOBENCH OUT_DIR
'use strict';
const { spawn } = require('node:child_process');
const fs = require('node:fs');
const http = require('node:http');
const path = require('node:path');

const RECORD_S = 5.0;
// 2 kHz: the loop over UDP is a round trip per cycle; a lower rate keeps the test's own load (two
// processes exchanging datagrams) small on a 2-core CI machine. The page's path is the same.
const RATE_HZ = 2000;
const LATENCY_LIMIT_MS = 200;
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

async function waitFor(get, what, ms) {
  for (let waited = 0; waited < ms; waited += 50) {
    const v = get();
    if (v) return v;
    await sleep(50);
  }
  throw new Error('no ' + what + ' within ' + ms + ' ms');
}

async function main() {
  const [binary, outArg] = process.argv.slice(2);
  if (!outArg) { console.error('usage: node station_udp_live_check.js PIEZOBENCH OUT_DIR'); process.exit(2); }
  const out = path.resolve(outArg);
  fs.rmSync(out, { recursive: true, force: true });
  fs.mkdirSync(out, { recursive: true });
  const children = [];
  const logs = { target: '', qualify: '' };
  const timer = setTimeout(() => {
    console.error(`station_udp_live_check: timed out after 90 s\n--- bench serve:\n${logs.target.slice(-1500)}\n--- qualify:\n${logs.qualify.slice(-3000)}`);
    for (const c of children) c.kill('SIGKILL');
    process.exit(1);
  }, 90000);
  try {
    // The target.
    const target = spawn(binary, ['bench', 'serve', '--udp', '127.0.0.1:0', '--rate', String(RATE_HZ), '--idle-timeout', '60'], { stdio: ['ignore', 'pipe', 'pipe'] });
    children.push(target);
    let targetOut = '';
    target.stdout.on('data', (d) => { targetOut += d; logs.target += d; });
    target.stderr.on('data', (d) => { logs.target += d; });
    const address = await waitFor(() => (targetOut.match(/127\.0\.0\.1:\d+/) || [])[0], 'address from bench serve', 10000);
    const bench = path.join(out, 'bench-udp.toml'), station = path.join(out, 'station.toml');
    fs.writeFileSync(bench, `[bench]\nname = "udp loopback"\nbackend = "udp"\nsample_rate_Hz = ${RATE_HZ}\n[udp]\naddress = "${address}"\ntimeout_s = 0.2\n` +
      '[amplifier]\ngain_V_per_V = 20\n[limits]\nva_min_V = -20\nva_max_V = 150\nslew_rate_V_per_s = 1e5\nwatchdog_s = 5.0\n');
    fs.writeFileSync(station, `name = "udp live"\n[[phases]]\nname = "frf"\nexperiment = "frf-noise"\nduration_s = ${RECORD_S}\n` +
      '[[phases.measurements]]\nname = "resonance_Hz"\n');
    // The operator's answers: a try that fails its checks (a loaded host can make the loop miss
    // replies: stale inputs) continues, instead of waiting for an answer nobody gives.
    const answers = path.join(out, 'answers.toml');
    fs.writeFileSync(answers, 'operator = "test"\n[phases.frf]\non_check_fail = ["continue"]\n');

    // The station, its page on a free port. It serves the page 1 s after the qualification: with
    // --ui-linger 0 it exits at once and, on a loaded host, the stream can close before the phase's
    // final state reaches it (finishedAt.frf never set: 4 failures in 10 runs beside 3 busy
    // processes at nice 10, as CI's background builds are; 0 in 10 with 1 s).
    const qualify = spawn(binary, ['qualify', '--bench', bench, '--station', station, '--serial', 'UDP-1', '--db', path.join(out, 'st.db'),
      '--data', path.join(out, 'data'), '--answers', answers, '--ui', '127.0.0.1:0', '--ui-linger', '1'], { stdio: ['ignore', 'pipe', 'pipe'] });
    children.push(qualify);
    let stderr = '';
    qualify.stderr.on('data', (d) => { stderr += d; logs.qualify += d; });
    qualify.stdout.on('data', () => {});
    const exited = new Promise((resolve) => qualify.on('exit', (code) => resolve(code)));
    const base = await waitFor(() => (stderr.match(/station page: (http:\/\/127\.0\.0\.1:\d+\/)/) || [])[1], 'page address from qualify', 20000);

    // The page's event stream.
    const samples = [];  // { at, arrived, phase, t }
    const finishedAt = {};
    let buffered = '';
    const request = http.get(base + 'api/events', (res) => {
      res.setEncoding('utf8');
      res.on('data', (chunk) => {
        const arrived = Date.now();
        buffered += chunk;
        let end;
        while ((end = buffered.indexOf('\n\n')) >= 0) {
          const event = buffered.slice(0, end);
          buffered = buffered.slice(end + 2);
          for (const line of event.split('\n')) {
            if (!line.startsWith('data:')) continue;
            const m = JSON.parse(line.slice(5));
            for (const s of m.samples || []) samples.push({ at: s.at, arrived, phase: s.phase, t: s.t });
            for (const p of (m.state && m.state.phases) || []) {
              if (['passed', 'marginal', 'failed'].includes(p.state) && !(p.name in finishedAt)) finishedAt[p.name] = arrived;
            }
          }
        }
      });
      res.on('error', () => {});
    });
    request.on('error', () => {});
    const code = await exited;
    request.destroy();
    target.kill('SIGKILL');

    const failures = [];
    if (code !== 0) failures.push(`qualify exited with ${code}: ${stderr.slice(-1500)}`);
    const record = samples.filter((s) => s.phase === 'frf');
    if (record.length === 0) throw new Error('no screen sample of the record reached the stream:\n' + stderr.slice(-1500));
    const lastMeasured = Math.max(...record.map((s) => s.at)) + 50;  // the last block's end
    const early = record.filter((s) => s.arrived < lastMeasured).length;
    const span = (Math.max(...record.map((s) => s.t)) - Math.min(...record.map((s) => s.t)));
    const latencies = record.map((s) => s.arrived - s.at).sort((a, b) => a - b);
    const q = (p) => latencies[Math.min(latencies.length - 1, Math.floor(p * latencies.length))];
    if (early < 0.5 * record.length) failures.push(`only ${early} of ${record.length} screen samples arrived before the record's last sample was measured`);
    // The latency check (p99 < 200 ms) is the browser test's; here the typical sample must
    // be within it (the median: a single scheduling stall of a loaded 2-core host must not fail
    // the check of item 2, samples during the record), its p99 printed.
    if (!(q(0.5) < LATENCY_LIMIT_MS)) failures.push(`latency p50 ${q(0.5).toFixed(0)} ms (limit ${LATENCY_LIMIT_MS} ms)`);
    // 20 screen samples per second of record, shown once (the record is ~RECORD_S long plus ramps).
    const expected = 20 * span;
    if (record.length > expected + 25 || record.length < 20 * RECORD_S - 5) failures.push(`${record.length} screen samples for ${span.toFixed(2)} s of record`);
    if (!(finishedAt.frf >= lastMeasured)) failures.push('the phase finished before its last sample was measured');
    if (failures.length > 0) {
      console.error('station_udp_live_check: FAILED\n  ' + failures.join('\n  '));
      process.exit(1);
    }
    console.log(`station_udp_live_check: qualify over UDP (bench serve on ${address}, ${RATE_HZ / 1000} kHz): ${record.length} screen samples over ` +
      `${span.toFixed(2)} s of record, ${early} of them on the stream before the record's last sample was measured; ` +
      `latency sample -> stream p50 ${q(0.5).toFixed(0)} ms, p99 ${q(0.99).toFixed(0)} ms, max ${latencies[latencies.length - 1].toFixed(0)} ms`);
  } finally {
    clearTimeout(timer);
    for (const c of children) c.kill('SIGKILL');
  }
}

main().then(() => process.exit(0)).catch((e) => {
  console.error('station_udp_live_check: ' + e.stack);
  process.exit(1);
});
