// The station's page (docs/station.md, "The live page"): the live qualification from /api/events
// (Server-Sent Events), the operator's prompts as buttons (POST /api/answer), and the database
// (/api/qualifications, /api/units/SN, /api/charts, /api/certificate/SN). Everything it loads
// comes from the station itself; text from the server is always inserted as text, never as markup.
'use strict';
(() => {
  const WINDOW_S = 30;            // seconds of signals shown
  const LATENCY_KEEP = 2000;      // latencies kept for window.pbLive
  const RECONNECT_MS = 2000;      // a refused stream (503: the station is busy) is asked again after this
  const $ = (id) => document.getElementById(id);
  const status = $('pb-status');

  // The token: given once in the address's fragment (#token=...), kept for this tab only.
  const token = (() => {
    const m = location.hash.match(/token=([0-9a-f]{16,128})/);
    if (m) {
      sessionStorage.setItem('pbToken', m[1]);
      history.replaceState(null, '', location.pathname);
    }
    return sessionStorage.getItem('pbToken') || '';
  })();
  const withToken = (url) => (token ? url + (url.includes('?') ? '&' : '?') + 'token=' + token : url);
  async function api(path, options = {}) {
    const headers = Object.assign({}, options.headers || {});
    if (token) headers.Authorization = 'Bearer ' + token;
    const response = await fetch(path, Object.assign({}, options, { headers }));
    const text = await response.text();
    let body = null;
    try { body = JSON.parse(text); } catch (e) { body = text; }
    if (!response.ok) throw new Error((body && body.error) || response.statusText);
    return body;
  }

  function el(tag, attrs = {}, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) {
      if (k === 'class') e.className = v;
      else if (k.startsWith('data-')) e.setAttribute(k, v);
      else if (k === 'onclick') e.addEventListener('click', v);
      else e[k] = v;
    }
    for (const c of children) e.append(c instanceof Node ? c : document.createTextNode(c === null || c === undefined ? '' : String(c)));
    return e;
  }
  const fmtNumber = (x) => (x === null || x === undefined ? '' : Number(x).toPrecision(5).replace(/\.?0+(e|$)/, '$1'));
  const fmtDuration = (s) => {
    if (s === null || s === undefined || !isFinite(s)) return '';
    s = Math.max(0, Math.round(s));
    return Math.floor(s / 60) + ':' + String(s % 60).padStart(2, '0');
  };

  // ---- tabs --------------------------------------------------------------------------------------
  function showTab(name) {
    $('live').hidden = name !== 'live';
    $('db').hidden = name !== 'db';
    $('tab-live').classList.toggle('active', name === 'live');
    $('tab-db').classList.toggle('active', name === 'db');
    if (name === 'db') loadDatabase().catch(showDbError);
    window.dispatchEvent(new Event('resize'));
  }
  $('tab-live').addEventListener('click', () => showTab('live'));
  $('tab-db').addEventListener('click', () => showTab('db'));

  // ---- live state --------------------------------------------------------------------------------
  const live = {
    state: null, clockOffsetMs: 0, samples: [], frf: null, messages: 0, samplesReceived: 0,
    latencies: [], phasesSeen: {}, answered: [], reconnects: 0,
  };
  window.pbLive = live;  // for tests and the curious: counters, latencies (ms), the last state

  function phaseTimes(p, now) {
    let elapsed = null, remaining = null;
    if (p.started_ms > 0) elapsed = ((p.finished_ms > 0 ? p.finished_ms : now) - p.started_ms) / 1000;
    if (p.finished_ms > 0) remaining = 0;
    else if ((p.state === 'running' || p.state === 'retried') && p.record_s > 0) remaining = Math.max(0, p.record_s - elapsed);
    else if (p.state === 'waiting' && p.expected_s !== null) remaining = p.expected_s;
    return { elapsed, remaining };
  }

  function renderSummary() {
    const s = live.state;
    if (!s || !s.live) { $('summary').textContent = 'No qualification is running here: see the database.'; return; }
    const now = Date.now() + live.clockOffsetMs;
    const end = s.finished_ms > 0 ? s.finished_ms : now;
    let remaining = 0, known = true;
    for (const p of s.phases) {
      const t = phaseTimes(p, now);
      if (p.finished_ms > 0) continue;
      if (t.remaining === null) known = false; else remaining += t.remaining;
    }
    const parts = [`unit ${s.serial}`, s.batch ? `batch ${s.batch}` : '', `station "${s.station}"`, s.status,
      `elapsed ${fmtDuration((end - s.started_ms) / 1000)}`,
      s.finished_ms > 0 ? '' : `remaining ${known ? '' : '≥ '}${fmtDuration(remaining)}`];
    const summary = $('summary');
    summary.replaceChildren(parts.filter(Boolean).join(' · '));
    if (s.verdict) {
      summary.append(' · verdict ', el('span', { class: 'verdict-' + s.verdict, id: 'unit-verdict' }, s.verdict),
        s.deciding_phase ? ` (decided by ${s.deciding_phase}, ${s.deciding_measurement})` : '');
    }
    if (s.message) summary.append(el('div', { class: 'message' }, s.message));
  }

  function renderPhases() {
    const s = live.state;
    const now = Date.now() + live.clockOffsetMs;
    const rows = (s && s.phases ? s.phases : []).map((p) => {
      const t = phaseTimes(p, now);
      return el('tr', { 'data-phase': p.name, 'data-state': p.state },
        el('td', {}, p.name), el('td', {}, p.experiment), el('td', { class: 'state-' + p.state }, p.state),
        el('td', { class: 'num' }, p.tries || ''), el('td', { class: 'num' }, fmtDuration(t.elapsed)),
        el('td', { class: 'num' }, fmtDuration(t.remaining)));
    });
    $('phases').tBodies[0].replaceChildren(...rows);
  }

  function renderVerdicts() {
    const s = live.state;
    const rows = [];
    for (const p of (s && s.phases) || []) {
      if (!(p.finished_ms > 0)) continue;
      for (const m of p.measurements) {
        rows.push(el('tr', { 'data-phase': p.name, 'data-name': m.name, 'data-value': m.value === null ? '' : String(m.value), 'data-verdict': m.verdict },
          el('td', {}, p.name), el('td', {}, m.name), el('td', { class: 'num' }, m.value === null ? 'none' : fmtNumber(m.value)),
          el('td', {}, m.unit), el('td', { class: 'num' }, fmtNumber(m.min)), el('td', { class: 'num' }, fmtNumber(m.max)),
          el('td', { class: 'verdict-' + m.verdict }, m.verdict)));
      }
      if (p.reason) rows.push(el('tr', { class: 'reason' }, el('td', {}, p.name), el('td', { colSpan: 6, class: 'error' }, p.reason)));
    }
    $('verdicts').tBodies[0].replaceChildren(...rows);
    const cert = $('certificate');
    if (s && s.certificate) {
      cert.replaceChildren('Certificate: ', el('a', { href: withToken('/api/certificate/' + encodeURIComponent(s.serial)), target: '_blank', id: 'certificate-link' },
        `${s.serial} (HTML, printable)`));
    } else cert.replaceChildren();
  }

  function renderPrompt() {
    const s = live.state;
    const box = $('prompt');
    if (!s || !s.prompt) { box.hidden = true; box.dataset.id = ''; return; }
    if (box.dataset.id === String(s.prompt.id) && !box.hidden) return;
    box.dataset.id = String(s.prompt.id);
    $('prompt-text').textContent = 'Operator: ' + s.prompt.text;
    $('prompt-error').textContent = '';
    // Values to type (capacitance, a file name): a field each, checked here for its form and by the
    // station as the terminal checks it (its refusal shown below, the prompt staying open).
    const fields = (s.prompt.fields || []).map((f) => el('label', { class: 'field' }, f.question + ' ',
      el('input', Object.assign({ type: 'text', name: f.name, 'data-field': f.name, required: true, autocomplete: 'off' },
        f.name.endsWith('_uF') ? { inputMode: 'decimal', pattern: '[+\\-]?[0-9]*\\.?[0-9]+([eE][+\\-]?[0-9]+)?', title: 'a number, uF' } : {}))));
    const buttons = s.prompt.choices.map((c) => el('button', {
      type: 'button', 'data-answer': c, onclick: () => answer(s.prompt.id, c, fields.length > 0),
    }, c));
    $('prompt-fields').replaceChildren(...fields);
    $('prompt-buttons').replaceChildren(...buttons);
    box.hidden = false;
  }

  async function answer(id, choice, withValues) {
    const body = { id, answer: choice };
    if (withValues) {
      const inputs = Array.from(document.querySelectorAll('#prompt-fields input'));
      const bad = inputs.find((i) => !i.checkValidity());
      if (bad) { $('prompt-error').textContent = `Not answered: ${bad.title || 'required'} (${bad.name})`; return; }
      body.values = Object.fromEntries(inputs.map((i) => [i.name, i.value.trim()]));
    }
    try {
      await api('/api/answer', { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
      live.answered.push({ id, choice });
      // The station may already have opened the next prompt, its state arriving on the stream before
      // this answer's response: hide the box only while it still shows the prompt just answered.
      if ($('prompt').dataset.id === String(id)) $('prompt').hidden = true;
    } catch (e) {
      $('prompt-error').textContent = `Not answered: ${e.message}`;
    }
  }

  // ---- plots -------------------------------------------------------------------------------------
  const plotConfig = { displaylogo: false, responsive: true, modeBarButtonsToRemove: ['toImage'] };
  let redrawPending = false, signalsDirty = false, frfDirty = false;
  function scheduleRedraw() {
    if (redrawPending) return;
    redrawPending = true;
    requestAnimationFrame(() => {
      redrawPending = false;
      if (signalsDirty) drawSignals();
      if (frfDirty) drawFrf();
      signalsDirty = frfDirty = false;
    });
  }

  function band(xs, lo, hi, axis, colour, name) {
    return [
      { x: xs, y: hi, yaxis: axis, mode: 'lines', line: { width: 0 }, hoverinfo: 'skip', showlegend: false },
      { x: xs, y: lo, yaxis: axis, mode: 'lines', line: { width: 0 }, fill: 'tonexty', fillcolor: colour + '33', hoverinfo: 'skip', showlegend: false },
      { x: xs, y: null, yaxis: axis, mode: 'lines', line: { color: colour, width: 1.5 }, name },
    ];
  }

  function drawSignals() {
    const s = live.state;
    const t0 = s && s.started_ms ? s.started_ms : 0;
    const xs = live.samples.map((p) => (p.at - t0) / 1000);
    const pick = (key, i) => live.samples.map((p) => p[key][i]);
    const traces = [];
    const channels = [['va', 'y', '#1f77b4', 'Va [V]'], ['de', 'y2', '#2ca02c', 'd_e [µm]'], ['vs', 'y3', '#d62728', 'Vs [V]']];
    for (const [key, axis, colour, name] of channels) {
      const b = band(xs, pick(key, 0), pick(key, 1), axis, colour, name);
      b[2].y = pick(key, 2);
      traces.push(...b);
    }
    Plotly.react('plot-signals', traces, {
      margin: { l: 60, r: 10, t: 10, b: 40 }, showlegend: true, legend: { orientation: 'h', y: 1.04 },
      xaxis: { anchor: 'y3', title: { text: 'time into the qualification [s]' } },
      yaxis: { domain: [0.68, 1], title: { text: 'Va [V]' } },
      yaxis2: { domain: [0.34, 0.64], title: { text: 'd_e [µm]' } },
      yaxis3: { domain: [0, 0.30], title: { text: 'Vs [V]' } },
    }, plotConfig);
    const last = live.samples[live.samples.length - 1];
    $('signals-info').textContent = last ? `${last.phase} try ${last.try}, t = ${last.t.toFixed(1)} s` : '';
    // The hysteresis loop of the newest hysteresis phase's samples.
    const phases = (s && s.phases) || [];
    const hystPhase = [...live.samples].reverse().find((p) => (phases.find((q) => q.name === p.phase) || {}).experiment === 'hysteresis');
    if (hystPhase) {
      const pts = live.samples.filter((p) => p.phase === hystPhase.phase && p.try === hystPhase.try);
      Plotly.react('plot-hyst', [{ x: pts.map((p) => p.va[2]), y: pts.map((p) => p.de[2]), mode: 'lines+markers', marker: { size: 3 }, name: hystPhase.phase }], {
        margin: { l: 60, r: 10, t: 10, b: 40 }, xaxis: { title: { text: 'Va [V]' } }, yaxis: { title: { text: 'd_e [µm]' } },
      }, plotConfig);
      $('hyst-info').textContent = hystPhase.phase;
    }
  }

  function drawFrf() {
    const f = live.frf;
    if (!f || !f.f_Hz) { $('frf-info').textContent = f ? `${f.phase}: waiting for the first average` : ''; return; }
    Plotly.react('plot-frf', [
      { x: f.f_Hz, y: f.mag_um_per_V, name: '|d_e/u| [µm/V]', mode: 'lines', line: { color: '#1f77b4' } },
      { x: f.f_Hz, y: f.coherence, name: 'coherence', yaxis: 'y2', mode: 'lines', line: { color: '#ff7f0e' } },
    ], {
      margin: { l: 60, r: 10, t: 10, b: 40 }, legend: { orientation: 'h', y: 1.08 },
      xaxis: { type: 'log', anchor: 'y2', title: { text: 'frequency [Hz]' } },
      yaxis: { type: 'log', domain: [0.38, 1], title: { text: '|H| [µm/V]' } },
      yaxis2: { domain: [0, 0.3], range: [0, 1.05], title: { text: 'coh.' } },
    }, plotConfig);
    $('frf-info').textContent = `${f.phase}: ${f.averages} average${f.averages === 1 ? '' : 's'}`;
  }

  // ---- the event stream --------------------------------------------------------------------------
  function onMessage(event) {
    const received = Date.now();
    const m = JSON.parse(event.data);
    live.messages++;
    if (m.now_ms) live.clockOffsetMs = m.now_ms - received;
    if (m.state) {
      live.state = m.state;
      for (const p of m.state.phases || []) {
        (live.phasesSeen[p.name] = live.phasesSeen[p.name] || new Set()).add(p.state);
      }
      renderSummary(); renderPhases(); renderVerdicts(); renderPrompt();
      status.dataset.state = 'connected';
    }
    if (m.samples) {
      for (const p of m.samples) {
        // Latency of the block's first sample: measured (server clock) -> here (server clock).
        live.latencies.push(received + live.clockOffsetMs - p.at);
        if (live.latencies.length > LATENCY_KEEP) live.latencies.shift();
        live.samples.push(p);
      }
      live.samplesReceived += m.samples.length;
      const newest = live.samples[live.samples.length - 1].at;
      while (live.samples.length && live.samples[0].at < newest - WINDOW_S * 1000) live.samples.shift();
      signalsDirty = true;
    }
    if (m.frf) { live.frf = m.frf; frfDirty = true; }
    scheduleRedraw();
  }

  // A dropped stream is reconnected by the browser itself; a refused one (an answer other than 200:
  // a 503 while the station serves its maximum of connections or pages) closes it for good, so the
  // page asks again itself: it must never go silent while the station runs.
  function connect() {
    const source = new EventSource(withToken('/api/events'));
    source.onopen = () => { $('conn').textContent = 'live'; };
    source.onmessage = onMessage;
    source.onerror = () => {
      $('conn').textContent = 'reconnecting…';
      if (source.readyState === EventSource.CLOSED) {
        live.reconnects++;
        setTimeout(() => { if (live.source === source) connect(); }, RECONNECT_MS);
      }
    };
    live.source = source;
  }

  // ---- the database ------------------------------------------------------------------------------
  function showDbError(e) { $('unit-detail').replaceChildren(el('p', { class: 'error' }, 'Database: ' + e.message)); }

  async function loadDatabase() {
    const batch = $('batch').value;
    const all = await api('/api/qualifications');
    const batches = [...new Set(all.map((q) => q.batch).filter(Boolean))].sort();
    const select = $('batch');
    select.replaceChildren(el('option', { value: '' }, 'every batch'), ...batches.map((b) => el('option', { value: b }, b)));
    select.value = batches.includes(batch) ? batch : '';
    const rows = all.filter((q) => !select.value || q.batch === select.value).map((q) => el('tr', { 'data-serial': q.serial },
      el('td', { class: 'num' }, q.id),
      el('td', {}, el('button', { type: 'button', class: 'link', onclick: () => showUnit(q.serial).catch(showDbError) }, q.serial)),
      el('td', {}, q.batch), el('td', {}, q.status), el('td', { class: 'verdict-' + q.verdict }, q.verdict), el('td', {}, q.started),
      el('td', {}, q.deciding_phase ? `${q.deciding_phase}: ${q.deciding_measurement}` : ''),
      el('td', {}, q.status === 'complete' ? el('a', { href: withToken('/api/certificate/' + encodeURIComponent(q.serial)), target: '_blank' }, 'certificate') : '')));
    $('quals').tBodies[0].replaceChildren(...rows);
    await loadCharts(select.value);
    status.dataset.database = 'loaded';
  }

  async function showUnit(serial) {
    const q = await api('/api/units/' + encodeURIComponent(serial));
    const table = el('table', {}, el('thead', {}, el('tr', {}, ...['phase', 'try', 'status', 'measurement', 'value', 'unit', 'min', 'max', 'verdict'].map((h) => el('th', {}, h)))));
    const body = el('tbody');
    for (const t of q.phase_tries) {
      const ms = t.measurements.length ? t.measurements : [null];
      for (const m of ms) {
        body.append(el('tr', {}, el('td', {}, t.phase), el('td', { class: 'num' }, t.try), el('td', {}, t.status),
          el('td', {}, m ? m.name : t.reason), el('td', { class: 'num' }, m ? fmtNumber(m.value) : ''), el('td', {}, m ? m.unit : ''),
          el('td', { class: 'num' }, m ? fmtNumber(m.min) : ''), el('td', { class: 'num' }, m ? fmtNumber(m.max) : ''),
          el('td', { class: 'verdict-' + (m ? m.verdict : t.verdict) }, m ? m.verdict : t.verdict)));
      }
    }
    table.append(body);
    $('unit-detail').replaceChildren(el('h2', {}, `${q.serial}: qualification ${q.id}, ${q.status} ${q.verdict}`),
      el('p', {}, `station "${q.station}", operator "${q.operator}", ${q.started} .. ${q.finished}, ${q.software_version}`), table);
  }

  async function loadCharts(batch) {
    const charts = await api('/api/charts' + (batch ? '?batch=' + encodeURIComponent(batch) : ''));
    const box = $('charts');
    box.replaceChildren();
    for (const c of charts) {
      if (!c.points.length) continue;
      const div = el('div', { class: 'plot', id: 'chart-' + c.quantity });
      box.append(div);
      const xs = c.points.map((p) => p.serial);
      const line = (y, name, dash, colour) => ({ x: [xs[0], xs[xs.length - 1]], y: [y, y], mode: 'lines', name, line: { dash, color: colour, width: 1 } });
      const traces = [{ x: xs, y: c.points.map((p) => p.value), mode: 'markers', name: c.quantity,
        marker: { size: 8, color: c.points.map((p) => ({ pass: '#070', marginal: '#d80', fail: '#b00' })[p.verdict] || '#555') } },
      line(c.mean, 'mean', 'solid', '#333'), line(c.mean + 3 * c.sigma, 'mean ± 3σ', 'dot', '#777'), line(c.mean - 3 * c.sigma, 'mean − 3σ', 'dot', '#777')];
      if (c.min !== null) traces.push(line(c.min, 'spec min', 'dash', '#b00'));
      if (c.max !== null) traces.push(line(c.max, 'spec max', 'dash', '#b00'));
      Plotly.newPlot(div, traces, {
        title: { text: `${c.quantity} [${c.unit}]: ${c.marginal} marginal, ${c.failed} failed`, font: { size: 13 } },
        margin: { l: 55, r: 10, t: 35, b: 60 }, showlegend: false, xaxis: { type: 'category' },
      }, Object.assign({}, plotConfig, { displayModeBar: false }));
    }
  }
  $('batch').addEventListener('change', () => loadDatabase().catch(showDbError));
  $('refresh').addEventListener('click', () => loadDatabase().catch(showDbError));

  // ---- start -------------------------------------------------------------------------------------
  api('/api/state').then((s) => {
    live.state = s;
    renderSummary(); renderPhases(); renderVerdicts(); renderPrompt();
    if (s.live) connect();
    else { $('conn').textContent = 'database'; showTab('db'); }
    status.dataset.state = s.live ? 'connecting' : 'database';
  }).catch((e) => { $('summary').textContent = 'The station did not answer: ' + e.message; status.dataset.state = 'error'; });
  setInterval(() => { if (live.state && live.state.live) { renderSummary(); renderPhases(); } }, 500);
})();
