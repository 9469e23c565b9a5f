/* Cell page: every instance with its state and why it is not Active, RT statistics, and the
 * CPU, memory and network budgets against capacity. Refreshed once a second. */
'use strict';
(() => {
  const {app, el, get, fmtNs, fmtBytes, stateBadge, pageUrl, message} = Arflex;
  const status = el('div', {id: 'arflex-cell-status'});
  const body = el('div', {id: 'arflex-cell'});
  app.replaceChildren(el('h2', {}, 'Cell'), status, body);

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
        el('td', {class: 'arflex-state-cell'}, stateBadge(i.state)),
        el('td', {}, i.targetState || ''),
        el('td', {class: 'arflex-reason'}, i.failureReason || (i.awaitingReset ? 'waiting for operator reset' : '')),
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
    const problems = (cell.problems || []).map(p => el('li', {}, p));
    body.replaceChildren(table,
      el('h2', {}, 'Budgets'), el('table', {class: 'arflex-table', id: 'arflex-resources'}, resources),
      el('h2', {}, 'Problems'), problems.length ? el('ul', {id: 'arflex-problems'}, problems) : el('p', {}, 'None.'));
  }

  async function refresh() {
    try {
      render(await get('cell'));
    } catch (e) {
      message(status, 'Cannot read the cell: ' + e.message, 'error');
    }
  }
  refresh();
  setInterval(refresh, 1000);
})();
