/* Component page: contract summary, bindings, parameters (editable where the contract allows,
 * with the value the RT half applied read back), start/stop/reset, live plots (server-sent
 * events, uPlot) and the RT half's wake-up latency histogram. */
'use strict';
(() => {
  const {app, el, get, post, fmtNs, fmtBytes, stateBadge, pageUrl, message} = Arflex;
  const name = new URLSearchParams(window.location.search).get('name');
  const status = el('div', {id: 'arflex-component-status'});

  async function chooser() {
    const data = await get('cell');
    const list = data.drcr ? (data.cell.instances || []) : [];
    app.replaceChildren(el('h2', {}, 'Components'), status,
      el('ul', {}, list.map(i => el('li', {}, el('a', {href: pageUrl('arflex-component', {name: i.name})}, i.name), ' ', stateBadge(i.state)))));
    if (!data.drcr) message(status, 'The DRCR is not running.', 'error');
  }

  const summary = el('div', {id: 'arflex-summary'});
  // Commands stay on the page even when the component left the cell (a stopped bundle).
  const cmd = (what) => el('button', {type: 'button', id: 'arflex-cmd-' + what, onclick: async () => {
    try { await post('command', {name, cmd: what}); message(status, what + ': done', 'ok'); load(); }
    catch (e) { message(status, what + ': ' + e.message, 'error'); }
  }}, what);
  const commands = el('p', {id: 'arflex-commands'}, 'Commands: ', cmd('start'), ' ', cmd('stop'), ' ', cmd('reset'));
  const params = el('div', {id: 'arflex-params'});
  const plots = el('div', {id: 'arflex-plots'});
  const histo = el('div', {id: 'arflex-histogram'});
  const portBox = el('div', {id: 'arflex-ports-live'});

  function kv(rows) {
    return el('table', {class: 'arflex-table'}, rows.map(([k, v]) => el('tr', {}, el('th', {}, k), el('td', {}, v))));
  }

  function renderSummary(d) {
    const c = d.contract || {};
    const i = d.instance || {};
    const ports = (c.ports || []).map(p => el('tr', {}, el('td', {}, p.direction), el('td', {}, p.name),
      el('td', {}, p.type + ' ' + p.typeVersion), el('td', {}, p.method), el('td', {}, p.binding || (p.direction === 'IN' ? 'any' : '')),
      el('td', {}, p.optional ? 'optional' : '')));
    // values the consumer refused on an input (damaged segment, invalid values) name their provider
    const bindings = (i.bindings || []).map(b => el('li', {}, b.provider + '.' + b.output + ' → ' + b.consumer + '.' + b.input,
      b.rejected ? el('span', {class: 'arflex-rejected', 'data-input': b.input}, ' (' + b.rejected + ' values refused)') : null));
    summary.replaceChildren(
      el('div', {}, 'State ', stateBadge(i.state), ' target ', i.targetState || '', ' ',
        i.failureReason ? el('span', {class: 'arflex-reason'}, '— ' + i.failureReason) : '',
        ''),
      el('h2', {}, 'Contract'),
      kv([['Name', c.name + ' ' + (c.version || '')], ['Description', c.description || ''],
        ['Task', (c.taskType || '') + (c.movesHardware ? ' (moves hardware)' : '')],
        ['Timing', 'period ' + fmtNs(c.periodNs) + ', deadline ' + fmtNs(c.deadlineNs) + ', wcet ' + fmtNs(c.wcetNs) + ', priority ' + c.priority],
        ['CPUs', (c.cpus || []).join(',') || 'any'], ['Memory', fmtBytes(c.memoryBytes)], ['Network', fmtBytes(c.networkBps) + '/s'],
        ['Criticality', String(c.criticality)],
        ['Fault policy', (c.restart || '') + ', ' + c.intensity + ' restarts in ' + c.windowMs + ' ms, backoff ' + c.backoffMs + ' ms, safe output ' + (c.safeOutput || '')],
        ['Update', c.updateUrl ? c.updateUrl + ' (sha256 ' + c.updateSha256 + ')' : 'none'],
        ['Source', c.source || ''], ['Bundle', String(c.bundleId)], ['PID / CPU', (i.pid || '-') + ' / ' + (i.cpu >= 0 ? i.cpu : '-')]]),
      el('h2', {}, 'Ports'),
      el('table', {class: 'arflex-table'}, el('tr', {}, ['Dir', 'Port', 'Type', 'Method', 'Binding', ''].map(h => el('th', {}, h))), ports),
      el('h2', {}, 'Bindings'), bindings.length ? el('ul', {}, bindings) : el('p', {}, 'None.'));
  }

  function renderParams(d) {
    const i = d.instance || {};
    const rows = (i.params || []).map(p => {
      const applied = el('span', {class: 'arflex-applied', id: 'arflex-applied-' + p.name}, p.value);
      const input = el('input', {type: 'text', id: 'arflex-param-' + p.name, value: p.value, size: 10, disabled: !p.mutable});
      const err = el('span', {class: 'arflex-field-error'});
      const apply = el('button', {type: 'button', id: 'arflex-apply-' + p.name, disabled: !p.mutable, onclick: async () => {
        err.textContent = ''; input.classList.remove('arflex-invalid');
        try {
          const r = await post('param', {name, param: p.name, value: input.value});
          applied.textContent = r.applied;
          message(status, p.name + ' applied by the RT half: ' + r.applied, 'ok');
        } catch (e) {
          err.textContent = e.message; input.classList.add('arflex-invalid');
        }
      }}, 'Apply');
      const range = (p.min !== null && p.min !== undefined ? p.min : '−∞') + ' … ' + (p.max !== null && p.max !== undefined ? p.max : '+∞');
      return el('tr', {}, el('td', {}, p.name), el('td', {}, p.type), el('td', {}, range), el('td', {}, p.unit || ''),
        el('td', {}, p.defaultValue), el('td', {}, applied), el('td', {}, p.mutable ? [input, ' ', apply, err] : 'fixed while Active'));
    });
    params.replaceChildren(el('h2', {}, 'Parameters'), rows.length ? el('table', {class: 'arflex-table'},
      el('tr', {}, ['Name', 'Type', 'Range', 'Unit', 'Default', 'Applied', 'Set'].map(h => el('th', {}, h))), rows) : el('p', {}, 'None.'));
  }

  // Live plot: a rolling window of the streamed samples.
  const WINDOW = 300;
  let plot = null; let series = null; let source = null;
  let watched = null; // {port, field, plot, last}
  let drawStat = () => {};
  function startStream() {
    if (typeof EventSource === 'undefined' || typeof uPlot === 'undefined') return;
    if (source) source.close();
    const keys = ['maxLatencyNs', 'meanExecNs', 'maxExecNs'];
    series = {t: [], v: keys.map(() => [])};
    const box = el('div', {class: 'arflex-plot', id: 'arflex-live-plot'});
    const counter = el('div', {id: 'arflex-live-count'}, 'waiting for samples…');
    // Any other statistic of the stream (every numeric StatsDTO field) on a second plot.
    const statSel = el('select', {id: 'arflex-stat-select'}, el('option', {value: ''}, '—'));
    const statBox = el('div', {class: 'arflex-plot', id: 'arflex-stat-plot'});
    let statPlot = null; let statKey = '';
    statSel.addEventListener('change', () => {
      statKey = statSel.value; statPlot = null; statBox.replaceChildren();
      if (statKey) statPlot = Arflex.rollingPlot(statBox, [statKey], {height: 180});
    });
    plots.replaceChildren(el('h2', {}, 'Live statistics (10 Hz)'), counter, box,
      el('p', {}, 'Plot another statistic: ', statSel), statBox);
    drawStat = (s) => {
      if (statSel.options.length === 1) {
        Object.keys(s).filter(k => typeof s[k] === 'number' && k !== 't').sort()
          .forEach(k => statSel.append(el('option', {value: k}, k)));
      }
      if (statPlot && typeof s[statKey] === 'number') {
        statPlot.push(s.t / 1000, [s[statKey]]);
        statBox.dataset.last = String(s[statKey]);
      }
    };
    plot = new uPlot({width: 800, height: 240, series: [{}, ...keys.map((k, n) => ({label: k.replace('Ns', ' (µs)'),
      stroke: ['#c62828', '#1565c0', '#2e7d32'][n]}))], axes: [{}, {label: 'µs'}]}, [[], ...keys.map(() => [])], box);
    source = new EventSource(Arflex.root + '/api/stream?' + new URLSearchParams(
      watched ? {name, ports: watched.port} : {name}));
    let n = 0;
    source.onmessage = ev => {
      const s = JSON.parse(ev.data);
      if (watched && s.ports) drawPort(s.t / 1000, s.ports[watched.port]);
      if (s.gone) { counter.textContent = 'component gone'; return; }
      n++;
      series.t.push(s.t / 1000);
      keys.forEach((k, j) => series.v[j].push(typeof s[k] === 'number' ? s[k] / 1000 : null));
      if (series.t.length > WINDOW) { series.t.shift(); series.v.forEach(a => a.shift()); }
      plot.setData([series.t, ...series.v]);
      counter.textContent = n + ' samples; cycles ' + (s.cycles ?? '-') + ', state ' + (s.state || '') +
        ', params ' + Object.entries(s.params || {}).map(([k, v]) => k + '=' + v).join(' ');
      drawHistogram(s);
      drawStat(s);
      for (const [k, v] of Object.entries(s.params || {})) {
        const a = document.getElementById('arflex-applied-' + k);
        if (a) a.textContent = v;
      }
    };
  }

  // Wake-up latency histogram of the RT half (control block, 100 ns bins), from the stream's
  // StatsDTO fields: non-empty bins (latencyHistBins/latencyHistCounts), overflow, percentiles.
  let histPlot = null; let histDrawn = 0;
  function drawHistogram(s) {
    if (!Array.isArray(s.latencyHistBins) || !Array.isArray(s.latencyHistCounts) || typeof uPlot === 'undefined') return;
    const now = Date.now();
    if (histPlot && now - histDrawn < 1000) return;
    histDrawn = now;
    const bins = s.latencyHistBins; const counts = s.latencyHistCounts; const w = s.histBinNs || 100;
    // Dense from the first to the last non-empty bin, so empty bins show as gaps.
    const xs = []; const ys = [];
    if (bins.length) {
      const lo = bins[0]; const hi = bins[bins.length - 1];
      for (let b = lo; b <= hi; b++) { xs.push(b * w / 1000); ys.push(0); }
      bins.forEach((b, k) => { ys[b - lo] = counts[k]; });
    }
    const us = ns => (ns / 1000).toFixed(1) + ' µs';
    const text = (s.latencyCount || 0) + ' samples; p50 ' + us(s.latencyP50Ns || 0) + ', p99 ' + us(s.latencyP99Ns || 0) +
      ', p99.9 ' + us(s.latencyP999Ns || 0) + ', max ' + us(s.maxLatencyNs || 0) + '; ' + (s.latencyHistOverflow || 0) +
      ' at or above ' + us(w * 2000) + ' (not drawn)';
    if (!histPlot) {
      const box = el('div', {class: 'arflex-plot', id: 'arflex-histogram-plot'});
      const summary = el('div', {id: 'arflex-histogram-summary'}, text);
      histo.replaceChildren(el('h2', {}, 'Wake-up latency histogram (RT half, ' + w + ' ns bins)'), summary, box);
      histPlot = new uPlot({width: 800, height: 200, scales: {x: {time: false}},
        axes: [{label: 'latency (µs, lower bin edge)'}, {label: 'cycles'}],
        series: [{label: 'µs'}, {label: 'cycles', stroke: '#1565c0', fill: 'rgba(21,101,192,.3)',
          paths: uPlot.paths.bars({size: [0.9, 40]})}]}, [xs, ys], box);
    } else {
      histPlot.setData([xs, ys]);
      document.getElementById('arflex-histogram-summary').textContent = text;
    }
    histo.dataset.samples = String(s.latencyCount || 0);
  }

  // Live plot of any output port value: the port's fields come from one read (api/port), the
  // values from the same stream (the sampler reads each watched port once per period, 10 Hz).
  function renderPortChooser(d) {
    const outs = ((d.contract || {}).ports || []).filter(p => p.direction === 'OUT');
    if (!outs.length) { portBox.replaceChildren(); return; }
    const portSel = el('select', {id: 'arflex-port-select'}, outs.map(p => el('option', {value: p.name}, p.name + ' (' + p.type + ', ' + p.method + ')')));
    const fieldSel = el('select', {id: 'arflex-port-field'});
    const err = el('span', {class: 'arflex-field-error', id: 'arflex-port-error'});
    async function fields() {
      err.textContent = '';
      try {
        const v = await get('port', {name, port: portSel.value});
        fieldSel.replaceChildren(...(v.fields || []).map(f => el('option', {value: f.name},
          f.name + (f.count > 1 ? '[' + f.count + ']' : '') + (f.unit ? ' (' + f.unit + ')' : ''))));
        const pref = (v.fields || []).find(f => f.name === 'value') || (v.fields || []).find(f => !/^(seq|t_ns|stamp_ns)$/.test(f.name));
        if (pref) fieldSel.value = pref.name;
        if (!(v.fields || []).length) err.textContent = v.index < 0 ? 'nothing published on this port yet' : 'no fields';
      } catch (e) { err.textContent = e.message; }
    }
    portSel.addEventListener('change', fields);
    const go = el('button', {type: 'button', id: 'arflex-port-plot-btn', onclick: () => {
      if (!fieldSel.value) { err.textContent = 'choose a field'; return; }
      watchPort(portSel.value, fieldSel.value);
    }}, 'Plot');
    portBox.replaceChildren(el('h2', {}, 'Live port values (10 Hz)'),
      el('p', {}, 'Port ', portSel, ' field ', fieldSel, ' ', go, err), el('div', {id: 'arflex-port-area'}));
    fields();
  }

  function watchPort(port, field) {
    const area = document.getElementById('arflex-port-area');
    const last = el('div', {id: 'arflex-port-last'}, 'waiting for values of ' + port + '.' + field + '…');
    const box = el('div', {class: 'arflex-plot', id: 'arflex-port-plot'});
    area.replaceChildren(last, box);
    watched = {port, field, box, last, plot: null};
    startStream();
  }

  function drawPort(t, v) {
    const w = watched;
    if (!v) return;
    if (v.error) { w.last.textContent = 'error: ' + v.error; return; }
    const values = (v.fields || {})[w.field];
    if (!Array.isArray(values)) { w.last.textContent = v.index < 0 ? 'nothing published yet' : 'no field ' + w.field; return; }
    if (!w.plot) {
      const labels = values.length === 1 ? [w.port + '.' + w.field] : values.map((_, i) => w.field + '[' + i + ']');
      w.plot = Arflex.rollingPlot(w.box, labels.slice(0, 8));
    }
    w.plot.push(t, values.slice(0, 8));
    w.box.dataset.last = values.map(Arflex.fmtNum).join(' ');
    w.last.textContent = w.port + '.' + w.field + ' = ' + values.slice(0, 8).map(Arflex.fmtNum).join(', ') +
      ' (element ' + v.index + ', ' + w.plot.count + ' samples)';
  }

  async function load() {
    try {
      const d = await get('component', {name});
      renderSummary(d);
      renderParams(d);
      if (!portBox.firstChild) renderPortChooser(d);
    } catch (e) {
      message(status, 'Component ' + name + ' is not in the cell now (' + e.message + ')', 'error');
    }
  }

  if (!name) { chooser(); return; }
  app.replaceChildren(el('h2', {id: 'arflex-component-name'}, 'Component ', el('code', {}, name)), status, commands, summary, params, plots, portBox, histo);
  load().then(startStream);
  window.addEventListener('beforeunload', () => source && source.close());
})();
