// Draws the figures of piezobench's report.html with plotly.js (inlined before this script).
// The figures come from the JSON element #pb-data (see html_report.hpp for the layout).
// When every plot is drawn, #pb-status gets data-state="rendered" and data-count=N; any error
// (a script error, a failed plot) sets data-state="error" and is shown on the page. The headless
// test (tests/report/render_check.js) waits for that state.
(function () {
  'use strict';
  const status = document.getElementById('pb-status');
  const problems = [];

  function report(message) {
    problems.push(String(message));
    status.dataset.state = 'error';
    status.textContent = 'The report could not draw every plot:\n' + problems.join('\n');
  }
  window.addEventListener('error', function (e) { report(e.message || 'script error'); });
  window.addEventListener('unhandledrejection', function (e) {
    report((e.reason && e.reason.message) || String(e.reason));
  });

  // Plotly reads a small HTML subset, $..$ (LaTeX) and %{..} (hover templates) in its text; the
  // document's strings are plain text, so those characters are entity-encoded (Plotly decodes
  // entities when it draws).
  function text(s) {
    return String(s).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;')
      .replace(/\$/g, '&#36;').replace(/%/g, '&#37;');
  }

  // One colour per unit (group), the same in every figure.
  const palette = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2',
    '#7f7f7f', '#bcbd22', '#17becf', '#393b79', '#ad494a', '#637939', '#7b4173'];
  const colours = new Map();
  function colour(key) {
    if (!colours.has(key)) colours.set(key, palette[colours.size % palette.length]);
    return colours.get(key);
  }

  function axisName(prefix, i) { return i === 0 ? prefix : prefix + (i + 1); }

  function build(fig) {
    const n = fig.panels.length;
    const panelPx = n === 1 ? 380 : 220;
    const gapPx = 26;
    const total = n * panelPx + (n - 1) * gapPx;
    const margin = { l: 80, r: 20, t: 34, b: 56 };
    const layout = {
      height: total + margin.t + margin.b,
      margin: margin,
      hovermode: 'closest',
      hoverlabel: { namelength: -1 },
      barmode: 'group',
      legend: { groupclick: 'togglegroup', tracegroupgap: 2 },
      font: { family: 'system-ui, "DejaVu Sans", sans-serif', size: 12 },
      xaxis: {
        title: { text: text(fig.x_label) },
        type: fig.x_category ? 'category' : (fig.x_log ? 'log' : 'linear'),
        anchor: axisName('y', n - 1),
        automargin: true,
        showline: true, mirror: true, linecolor: '#9aa3b2', gridcolor: '#e6e9ef',
        exponentformat: 'power',
      },
    };
    const traces = [];
    const shown = new Set();
    fig.panels.forEach(function (panel, i) {
      const top = 1 - i * (panelPx + gapPx) / total;
      layout[axisName('yaxis', i)] = {
        domain: [Math.max(0, top - panelPx / total), Math.min(1, top)],
        title: { text: text(panel.y_label) },
        type: panel.y_log ? 'log' : 'linear',
        anchor: 'x',
        automargin: true,
        showline: true, mirror: true, linecolor: '#9aa3b2', gridcolor: '#e6e9ef',
        exponentformat: 'power',
      };
      panel.traces.forEach(function (t, j) {
        const key = t.group !== undefined ? 'group:' + t.group : 'trace:' + fig.id + ':' + i + ':' + j;
        const c = colour(t.group !== undefined ? t.group : t.name);
        const band = t.mode === 'band';
        const trace = {
          name: text(t.group !== undefined ? t.group : t.name),
          legendgroup: key,
          showlegend: !band && !shown.has(key),
          x: t.x, y: t.y,
          xaxis: 'x', yaxis: axisName('y', i),
          hovertemplate: text(t.name) + '<br>' + (t.text ? '%{text}<br>' : '') + '%{x}, %{y}<extra></extra>',
        };
        if (t.text) trace.text = t.text.map(function (s) { return s === null ? '' : text(s); });
        if (!band) shown.add(key);
        if (band) {
          // A 95 % band: the polygon lower edge then upper edge reversed, filled, under the curve.
          trace.type = 'scatter';
          trace.mode = 'lines';
          trace.x = t.x.concat(t.x.slice().reverse());
          trace.y = t.y.concat(t.y_upper.slice().reverse());
          trace.fill = 'toself';
          trace.fillcolor = c;
          trace.opacity = 0.18;
          trace.line = { color: c, width: 0 };
          trace.hoverinfo = 'skip';
        } else if (t.mode === 'bars') {
          trace.type = 'bar';
          trace.marker = { color: c };
          trace.opacity = t.dash ? 0.55 : 1;
        } else {
          trace.type = 'scatter';
          trace.mode = t.mode;
          trace.line = { color: c, width: 1.6, dash: t.dash ? 'dash' : 'solid' };
          trace.marker = { color: c, size: 6, symbol: t.dash ? 'circle-open' : 'circle' };
          trace.connectgaps = false;
        }
        traces.push(trace);
      });
    });
    return { traces: traces, layout: layout };
  }

  const config = {
    responsive: true,
    displaylogo: false,
    modeBarButtonsToRemove: ['select2d', 'lasso2d'],
  };

  async function drawAll() {
    const data = JSON.parse(document.getElementById('pb-data').textContent);
    if (typeof Plotly === 'undefined') throw new Error('the plotting library is missing');
    let drawn = 0;
    for (const fig of data.figures) {
      const div = document.getElementById('fig-' + fig.id);
      try {
        const f = build(fig);
        config.toImageButtonOptions = { format: 'svg', filename: fig.id };
        await Plotly.newPlot(div, f.traces, f.layout, config);
        drawn += 1;
      } catch (e) {
        div.textContent = 'This plot could not be drawn: ' + e.message;
        report('figure ' + fig.id + ': ' + e.message);
      }
    }
    status.dataset.count = String(drawn);
    if (problems.length === 0) {
      status.dataset.state = 'rendered';
      status.textContent = drawn + ' interactive plots drawn.';
    }
    return data.figures;
  }

  // Printing: plots get the width of an A4 page, and back after.
  function plots() { return Array.from(document.querySelectorAll('div.pb-plot.js-plotly-plot')); }
  window.addEventListener('beforeprint', function () {
    plots().forEach(function (gd) { Plotly.relayout(gd, { width: 700 }); });
  });
  window.addEventListener('afterprint', function () {
    plots().forEach(function (gd) { Plotly.relayout(gd, { width: null }); });
  });

  drawAll().catch(function (e) { report(e.message); });
})();
