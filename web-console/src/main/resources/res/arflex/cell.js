/* Cell page: every instance with its state and why it is not Active, RT statistics, and the
 * CPU, memory and network budgets against capacity. Refreshed once a second. */
'use strict';
(() => {
  const {app, el, get, post, fmtNs, fmtBytes, fmtNum, stateBadge, pageUrl, message, rollingPlot, stream} = Arflex;
  const status = el('div', {id: 'arflex-cell-status'});
  const body = el('div', {id: 'arflex-cell'});
  const tcp = el('div', {id: 'arflex-tcp-error'});
  // One cell-level reset (arflex:reset --cell): everything that waits, in dependency order; it
  // permits motion, it never starts it (motion sources wait for a fresh command).
  const resetStatus = el('div', {id: 'arflex-reset-cell-status'});
  const resetButton = el('button', {id: 'arflex-reset-cell', type: 'button',
    title: 'Reset every component that waits for an operator reset or is FAILED, providers first'}, 'Reset cell');
  resetButton.addEventListener('click', async () => {
    resetButton.disabled = true;
    try {
      const r = await post('reset-cell', {});
      message(resetStatus, r.result, /refused/.test(r.result) ? 'error' : 'ok');
      refresh();
    } catch (e) {
      message(resetStatus, 'reset cell: ' + e.message, 'error');
    } finally {
      resetButton.disabled = false;
    }
  });
  app.replaceChildren(el('h2', {}, 'Cell'), status, el('p', {}, resetButton), resetStatus, body, tcp);

  // Preset plot: the tool-centre error that tcp-correction publishes (output `error`,
  // arflex.Sample, mm), drawn as two series, with and without correction, split by the applied
  // value of its `enable` parameter, which the button toggles. `?error=component.port` points
  // the preset at another Sample port (another cell); the toggle appears only where the
  // component has a mutable bool parameter `enable`.
  const errorParam = new URLSearchParams(window.location.search).get('error') || 'tcp-correction.error';
  const preset = {component: errorParam.substring(0, errorParam.lastIndexOf('.')),
    port: errorParam.substring(errorParam.lastIndexOf('.') + 1), toggle: 'enable'};
  let tcpStream = null; let tcpPlot = null; let tcpShown; let tcpEnabled = null; let tcpLastIndex = -1;
  function renderTcp(cell) {
    const inst = (cell.instances || []).find(i => i.name === preset.component);
    const contract = (cell.contracts || []).find(c => c.name === preset.component);
    const port = contract && (contract.ports || []).find(p => p.direction === 'OUT' && p.name === preset.port);
    const ok = inst && port && port.type === 'arflex.Sample' && inst.state === 'ACTIVE';
    const why = ok ? null : !inst ? 'No component ' + preset.component + ' in the cell.'
      : !port ? preset.component + ' has no output port ' + preset.port + '.'
      : port.type !== 'arflex.Sample' ? preset.component + '.' + preset.port + ' is ' + port.type + ', not arflex.Sample.'
      : preset.component + ' is ' + inst.state + ', not Active.';
    const key = ok ? 'pid ' + inst.pid : why;
    if (key === tcpShown) return;
    tcpShown = key;
    if (tcpStream) { tcpStream.close(); tcpStream = null; }
    tcpPlot = null;
    tcpLastIndex = -1;
    const head = el('h2', {}, 'Tool-centre error, with and without correction');
    if (!ok) {
      tcp.replaceChildren(head, el('p', {id: 'arflex-tcp-error-none'}, why));
      return;
    }
    const tcpStatus = el('div', {id: 'arflex-tcp-status'});
    const toggleSpec = (inst.params || []).find(p => p.name === preset.toggle && p.mutable && p.type === 'BOOL');
    const last = el('div', {id: 'arflex-tcp-error-last'}, 'waiting for values…');
    const box = el('div', {class: 'arflex-plot', id: 'arflex-tcp-error-plot'});
    const toggle = toggleSpec ? el('button', {type: 'button', id: 'arflex-tcp-toggle', onclick: async () => {
      const next = tcpEnabled === 'true' ? 'false' : 'true';
      try {
        const r = await post('param', {name: preset.component, param: preset.toggle, value: next});
        message(tcpStatus, preset.component + ' ' + preset.toggle + ' applied by the RT half: ' + r.applied, 'ok');
      } catch (e) { message(tcpStatus, preset.toggle + ': ' + e.message, 'error'); }
    }}, 'Toggle correction') : '';
    tcp.replaceChildren(head, el('p', {}, el('code', {}, preset.component + '.' + preset.port), ' ', toggle), tcpStatus, last, box);
    if (typeof uPlot === 'undefined') return;
    // tcp-correction publishes its error in mm (an arflex.Sample carries no unit of its own).
    const unit = errorParam === 'tcp-correction.error' ? 'mm' : '';
    tcpPlot = toggleSpec ? rollingPlot(box, ['with correction', 'without correction'], {unit, window: 600,
      colors: ['#2e7d32', '#c62828']}) : rollingPlot(box, [preset.component + '.' + preset.port], {unit, window: 600});
    tcpStream = stream(preset.component, [preset.port], f => {
      if (f.gone || !f.ports) return;
      const v = f.ports[preset.port];
      tcpEnabled = toggleSpec ? String((f.params || {})[preset.toggle]) : null;
      const on = !toggleSpec || tcpEnabled === 'true';
      const corr = toggleSpec ? ', correction ' + (on ? 'on' : 'off') : '';
      box.dataset.correction = toggleSpec ? (on ? 'on' : 'off') : '';
      if (!v || v.error) { last.textContent = (v ? 'error: ' + v.error : 'no value') + corr; return; }
      if (v.index < 0 || !v.fields || !Array.isArray(v.fields.value)) { last.textContent = 'nothing published yet' + corr; return; }
      const x = v.fields.value[0];
      if (v.index === tcpLastIndex) return; // a state port holds its last value: plot each element once
      tcpLastIndex = v.index;
      tcpPlot.push(f.t / 1000, !toggleSpec ? [x] : on ? [x, null] : [null, x]);
      last.textContent = preset.port + ' = ' + fmtNum(x) + corr + ' (' + tcpPlot.count + ' samples)';
      box.dataset.last = String(x);
    });
  }

  function bar(used, capacity) {
    const frac = capacity > 0 ? used / capacity : (used > 0 ? 1 : 0);
    const b = el('span', {class: 'arflex-bar' + (frac > 1 ? ' arflex-over' : '')}, el('span', {}));
    b.firstChild.style.width = Math.min(100, Math.round(frac * 100)) + '%';
    return b;
  }

  function render(data) {
    if (!data.drcr) {
      message(status, 'The DRCR is not running: no DrcrService is registered.', 'error');
      body.replaceChildren();
      return;
    }
    const cell = data.cell;
    status.replaceChildren(el('div', {}, 'Runtime ', el('code', {}, cell.runtimeId || ''),
      ', generation ', String(cell.generation), ', ', String((cell.instances || []).length), ' component(s)'));
    const rows = (cell.instances || []).map(i => {
      const s = i.stats || {};
      return el('tr', {'data-component': i.name},
        el('td', {}, el('a', {href: pageUrl('arflex-component', {name: i.name})}, i.name)),
        el('td', {class: 'arflex-state-cell'}, stateBadge(i.holding && i.state === 'ACTIVE' ? 'HOLDING' : i.state)),
        el('td', {}, i.targetState || ''),
        el('td', {class: 'arflex-reason'}, i.holding || i.failureReason || ''),
        el('td', {}, String(i.restarts) + ' (' + i.restartsLeft + ' left)'),
        el('td', {}, i.pid ? String(i.pid) : ''),
        el('td', {}, i.cpu >= 0 ? String(i.cpu) : ''),
        el('td', {}, i.stats ? String(s.cycles) : ''),
        el('td', {}, i.stats ? String(s.overruns) + ' / ' + s.wcetOverruns : ''),
        el('td', {}, i.stats ? fmtNs(s.maxLatencyNs) : ''),
        el('td', {}, i.stats ? fmtNs(s.meanExecNs) + ' / ' + fmtNs(s.maxExecNs) : ''),
        el('td', {}, i.stats ? (s.rtState || '') + ' (hb ' + s.heartbeatAgeMs + ' ms)' : ''));
    });
    const table = el('table', {class: 'arflex-table', id: 'arflex-instances'},
      el('tr', {}, ['Component', 'State', 'Target', 'Why not Active', 'Restarts', 'PID', 'CPU', 'Cycles',
        'Overruns / WCET', 'Max latency', 'Exec mean / max', 'RT half'].map(h => el('th', {}, h))),
      rows.length ? rows : el('tr', {}, el('td', {colspan: 12}, 'No component installed.')));
    const res = data.resources || cell.resources;
    const resources = [];
    if (res) {
      (res.cpus || []).forEach((cpu, k) => {
        const u = (res.cpuUtilisation || [])[k] || 0;
        resources.push(el('tr', {}, el('td', {}, 'CPU ' + cpu), el('td', {}, bar(u, 1)),
          el('td', {}, (u * 100).toFixed(1) + ' % of 100 %')));
      });
      resources.push(el('tr', {}, el('td', {}, 'Memory'), el('td', {}, bar(res.memoryUsed, res.memoryBytes)),
        el('td', {}, fmtBytes(res.memoryUsed) + ' of ' + fmtBytes(res.memoryBytes))));
      resources.push(el('tr', {}, el('td', {}, 'Network'), el('td', {}, bar(res.networkUsed, res.networkBps)),
        el('td', {}, fmtBytes(res.networkUsed) + '/s of ' + fmtBytes(res.networkBps) + '/s')));
      resources.push(el('tr', {}, el('td', {}, 'WCET overruns'), el('td', {colspan: 2}, String(res.wcetOverruns))));
    }
    // a component that holds the arm is a problem people must see (SAFETY.md 5)
    const problems = (cell.instances || []).filter(i => i.holding).map(i => el('li', {class: 'arflex-holding'}, i.name + ': ' + i.holding))
      .concat((cell.problems || []).map(p => el('li', {}, p)));
    body.replaceChildren(table,
      el('h2', {}, 'Budgets'), el('table', {class: 'arflex-table', id: 'arflex-resources'}, resources),
      el('h2', {}, 'Problems'), problems.length ? el('ul', {id: 'arflex-problems'}, problems) : el('p', {}, 'None.'));
  }

  async function refresh() {
    try {
      const data = await get('cell');
      render(data);
      if (data.drcr) renderTcp(data.cell);
    } catch (e) {
      message(status, 'Cannot read the cell: ' + e.message, 'error');
    }
  }
  refresh();
  setInterval(refresh, 1000);
})();
