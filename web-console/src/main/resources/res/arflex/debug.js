/* Debug monitor page: install the debug-monitor component (bundles/debug-monitor) watching the
 * state ports the engineer chooses, watch the values it republishes (last, and min/max/mean per
 * window) live, change its window, and uninstall it again. Every install/uninstall shows the
 * DRCR's plan first. The watched components are never restarted or rewired: the monitor maps
 * their segments read-only. */
'use strict';
(() => {
  const {app, el, get, post, stateBadge, pageUrl, message, fmtNum} = Arflex;
  const status = el('div', {id: 'arflex-debug-status'});
  const bundle = el('div', {id: 'arflex-debug-bundle'});
  const plan = el('div', {id: 'arflex-plan'});
  const body = el('div', {id: 'arflex-debug'});
  app.replaceChildren(el('h2', {}, 'Debug monitor'), status, bundle, plan, body);
  const STATS = ['last', 'min', 'max', 'mean'];
  let source = null; let shownFor = null; let plot = null;

  // The plan waiting for Confirm; replacing or dropping it cancels it (a staged jar is discarded).
  let pending = null;
  function dropPending() {
    const p = pending;
    pending = null;
    if (p && p.onCancel) p.onCancel();
  }

  function showPlan(title, text, onConfirm, onCancel) {
    dropPending();
    const mine = {onCancel};
    pending = mine;
    const confirm = el('button', {type: 'button', id: 'arflex-debug-confirm', onclick: async () => {
      confirm.disabled = true;
      if (pending === mine) pending = null;
      try { await onConfirm(); } finally { plan.replaceChildren(); refresh(); }
    }}, 'Confirm');
    const cancel = el('button', {type: 'button', id: 'arflex-debug-cancel', onclick: async () => {
      if (pending === mine) pending = null;
      if (onCancel) await onCancel();
      plan.replaceChildren();
    }}, 'Cancel');
    plan.replaceChildren(el('h2', {}, title), el('div', {class: 'arflex-plan', id: 'arflex-plan-text'}, text),
      el('p', {}, confirm, ' ', cancel));
  }

  function stopStream() {
    if (source) source.close();
    source = null; shownFor = null; plot = null;
  }

  async function chooser() {
    const ports = (await get('ports')).ports.filter(p => p.type === 'arflex.Sample' && p.method === 'STATE' &&
      p.component !== 'debug-monitor');
    if (!ports.length) {
      body.replaceChildren(el('p', {id: 'arflex-debug-none'}, 'The debug monitor is not installed.'),
        el('p', {}, 'No state port of type arflex.Sample in the cell to watch.'));
      return;
    }
    const opts = (none) => [none ? el('option', {value: ''}, '—') : null,
      ...ports.map(p => el('option', {value: p.component + '.' + p.port}, p.component + '.' + p.port))];
    const sels = [0, 1, 2, 3].map(k => el('select', {id: 'arflex-debug-target-' + k}, opts(k > 0)));
    const go = el('button', {type: 'button', id: 'arflex-debug-plan', onclick: async () => {
      const targets = sels.map(s => s.value).filter(v => v);
      try {
        const r = await post('debug-stage', {targets: targets.join(',')});
        message(status, 'Built the debug monitor for ' + r.targets.join(', ') + '; review the plan below.', 'info');
        showPlan('Plan: install the debug monitor (' + r.symbolicName + ')', r.plan, async () => {
          try {
            const done = await post('install', {id: r.id});
            message(status, 'debug monitor ' + done.action + ' (bundle ' + done.bundleId + ')', 'ok');
          } catch (e) { message(status, 'Install failed: ' + e.message, 'error'); }
        }, async () => { try { await post('discard', {id: r.id}); } catch (e) { /* gone */ } });
      } catch (e) {
        // Refused, or the DRCR could not plan it: no plan (and nothing to confirm) stays.
        dropPending();
        plan.replaceChildren();
        message(status, 'Refused: ' + e.message, 'error');
      }
    }}, 'Plan install');
    body.replaceChildren(el('p', {id: 'arflex-debug-none'}, 'The debug monitor is not installed.'), el('h2', {}, 'Watch'),
      el('p', {}, 'Choose up to four state ports (arflex.Sample) to watch; the monitor maps them read-only.'),
      el('table', {class: 'arflex-table'}, sels.map((s, k) => el('tr', {}, el('th', {}, 'm' + k), el('td', {}, s)))),
      el('p', {}, go));
  }

  function slotsOf(inst) {
    // m<k> <- provider.output, from the instance's bindings; slots from the contract's outputs.
    const wired = {};
    for (const b of inst.bindings || []) wired[b.input] = b.provider + '.' + b.output;
    return wired;
  }

  function monitorView(d) {
    const inst = d.instance;
    const outs = ((d.contract || {}).ports || []).filter(p => p.direction === 'OUT').map(p => p.name);
    const slots = [0, 1, 2, 3].filter(k => outs.includes('m' + k + '_last'));
    const wired = slotsOf(inst);
    const key = inst.pid + ':' + slots.join(',');
    if (shownFor === key) {
      document.getElementById('arflex-debug-state').replaceChildren(stateBadge(inst.state), ' pid ' + (inst.pid || '-'),
        inst.failureReason ? ' — ' + inst.failureReason : '');
      slots.forEach(k => { document.getElementById('arflex-debug-m' + k + '-target').textContent = wired['m' + k] || 'not bound'; });
      return;
    }
    stopStream();
    shownFor = key;
    const wparam = (inst.params || []).find(p => p.name === 'window');
    const win = el('input', {type: 'text', id: 'arflex-debug-window', size: 8, value: wparam ? wparam.value : ''});
    const winErr = el('span', {class: 'arflex-field-error'});
    const apply = el('button', {type: 'button', id: 'arflex-debug-window-apply', onclick: async () => {
      winErr.textContent = '';
      try {
        const r = await post('param', {name: 'debug-monitor', param: 'window', value: win.value});
        message(status, 'window applied by the RT half: ' + r.applied, 'ok');
      } catch (e) { winErr.textContent = e.message; }
    }}, 'Apply');
    const uninstall = el('button', {type: 'button', id: 'arflex-debug-uninstall', onclick: async () => {
      try {
        const p = await get('plan-uninstall', {name: 'debug-monitor'});
        showPlan('Plan: uninstall the debug monitor', p.plan, async () => {
          try {
            await post('uninstall', {name: 'debug-monitor'});
            message(status, 'debug monitor uninstalled', 'ok');
          } catch (e) { message(status, 'Uninstall failed: ' + e.message, 'error'); }
        });
      } catch (e) { dropPending(); plan.replaceChildren(); message(status, 'Cannot plan the uninstall: ' + e.message, 'error'); }
    }}, 'Uninstall the debug monitor');
    const rows = slots.map(k => el('tr', {}, el('td', {}, 'm' + k), el('td', {id: 'arflex-debug-m' + k + '-target'}, wired['m' + k] || 'not bound'),
      STATS.map(s => el('td', {id: 'arflex-debug-m' + k + '-' + s, 'data-index': '-1'}, '–'))));
    const box = el('div', {class: 'arflex-plot', id: 'arflex-debug-plot'});
    body.replaceChildren(
      el('p', {id: 'arflex-debug-state'}, stateBadge(inst.state), ' pid ' + (inst.pid || '-'), inst.failureReason ? ' — ' + inst.failureReason : ''),
      el('p', {}, el('a', {href: pageUrl('arflex-component', {name: 'debug-monitor'})}, 'component page'), ' · ', uninstall),
      el('p', {}, 'Window (values per min/max/mean): ', win, ' ', apply, winErr),
      el('table', {class: 'arflex-table', id: 'arflex-debug-values'},
        el('tr', {}, ['Slot', 'Watching', 'last', 'min', 'max', 'mean'].map(h => el('th', {}, h))), rows),
      el('h2', {}, 'Last values (10 Hz)'), box);
    if (!slots.length || typeof uPlot === 'undefined') return;
    plot = Arflex.rollingPlot(box, slots.map(k => 'm' + k + ' ' + (wired['m' + k] || '')));
    const ports = slots.flatMap(k => STATS.map(s => 'm' + k + '_' + s));
    source = Arflex.stream('debug-monitor', ports, f => {
      if (f.gone || !f.ports) return;
      const lasts = [];
      for (const k of slots) {
        for (const s of STATS) {
          const v = f.ports['m' + k + '_' + s];
          const cell = document.getElementById('arflex-debug-m' + k + '-' + s);
          if (!cell) continue;
          if (v && v.error) { cell.textContent = 'error: ' + v.error; continue; }
          const x = v && v.fields && Array.isArray(v.fields.value) ? v.fields.value[0] : null;
          if (v && v.index >= 0 && x !== null) {
            cell.textContent = fmtNum(x);
            cell.dataset.index = String(v.index);
            cell.dataset.value = String(x);
          }
          if (s === 'last') lasts.push(v && v.index >= 0 && v.fields ? v.fields.value[0] : null);
        }
      }
      if (plot) plot.push(f.t / 1000, lasts);
    });
  }

  async function refresh() {
    try {
      const d = await get('debug');
      bundle.replaceChildren(d.jar ? el('p', {}, 'Bundle: ', el('code', {id: 'arflex-debug-jar'}, d.jar))
        : el('div', {class: 'arflex-msg arflex-msg-error', id: 'arflex-debug-jar-problem'}, d.jarProblem));
      if (d.instance && d.instance.state !== 'DESTROYED') {
        monitorView(d);
      } else {
        if (shownFor !== 'chooser') {
          stopStream();
          shownFor = 'chooser';
          body.replaceChildren(el('p', {id: 'arflex-debug-none'}, 'The debug monitor is not installed.'));
          if (d.jar) await chooser().catch(e => message(status, e.message, 'error'));
        }
      }
    } catch (e) { message(status, e.message, 'error'); }
  }

  refresh();
  setInterval(refresh, 1000);
})();
