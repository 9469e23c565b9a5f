/* Change sets page (D46): the actions of a set, one per line; Plan shows the DRCR's dry run of
 * the whole set (what starts, stops, restarts, rebinds or holds and why, the admission per CPU,
 * what is refused and why) and changes nothing; Apply the plan shown applies exactly that plan,
 * or is refused when the cell changed since; then the outcome (committed, refused, rejected in
 * shadow, rolled back, torn down) and the history of the sets applied in this runtime. While a
 * set is applied, its live progress (D53) from the DRCR: the phases gone through, what it does
 * now, an update's shadow or window cycles and the worst deviation so far, then the outcome;
 * a set of several updates gets a row for each (D60), kept with the outcome; the history shows
 * each update of a set as the DRCR kept it (D62), a cancelled one naming whose rejection.
 * Everything goes into the DOM through textContent and attribute setters only. */
'use strict';
(() => {
  const {app, el, get, post, message} = Arflex;
  const status = el('div', {id: 'arflex-cs-status'});
  const planBox = el('div', {id: 'arflex-cs-plan'});
  const progress = el('div', {id: 'arflex-cs-progress'});
  const historyBox = el('div', {id: 'arflex-cs-history'});
  const live = el('div', {id: 'arflex-cs-live'});
  const actions = el('textarea', {id: 'arflex-cs-actions', rows: 6, cols: 90, spellcheck: 'false',
    placeholder: 'install teach\nuninstall trajectory\nset tcp-correction enable true\n'
      + 'update tcp-correction file:/…/tcp-correction-1.0.1.jar <sha256> shadow 200 tolerance corrected.q 0.000001'});
  // The plan on the page: the text it was made for and its id; editing the text withdraws it.
  let shown = null;
  let historyKey = null;
  // the "Applying the set…" note, cleared once the outcome is shown
  let applyingShown = false;

  const OUTCOME_TEXT = {
    'committed': 'committed', 'applied': 'applied (no verdict of the window)', 'refused': 'refused, nothing changed',
    'rejected-in-shadow': 'rejected in its shadow run, nothing changed', 'rolled-back': 'rolled back after the switch',
    'torn-down': 'torn down during its preparation, nothing changed', 'unknown': 'unknown'
  };
  const PHASE_TEXT = {
    'checking': 'checking the set', 'preparing': 'preparing the new RT halves', 'shadow': 'shadow run',
    'switching': 'switching', 'window': 'rollback window', 'bundles': 'bundles', 'done': 'outcome'
  };
  // the live progress: polled every 250 ms while the DRCR applies a set, once a second otherwise
  let livePolling = false;
  const when = ms => ms ? new Date(ms).toISOString().replace('T', ' ').replace(/\.\d+Z$/, ' UTC') : '';

  function table(id, head, rows, empty) {
    return el('table', {class: 'arflex-table', id},
      el('tr', {}, head.map(h => el('th', {}, h))),
      rows.length ? rows : el('tr', {}, el('td', {colspan: head.length}, empty)));
  }

  /** The parts of a plan: steps by kind, orders, wiring, CPUs, what is not active. */
  function planParts(p, prefix) {
    const steps = p.steps || [];
    const count = op => steps.filter(s => s.op === op).length;
    const summary = ['START', 'STOP', 'RESTART', 'REBIND', 'HOLD'].filter(op => count(op))
      .map(op => op.toLowerCase() + ' ' + count(op)).join(', ') || 'no component starts, stops or is rebound';
    return el('div', {},
      p.title ? el('p', {}, 'Plan: ', el('strong', {}, p.title), ' — ', el('span', {id: prefix + '-summary'}, summary)) : '',
      table(prefix + '-steps', ['what', 'component', 'why'], steps.map(s =>
        el('tr', {'data-op': s.op, 'data-component': s.component, class: s.op === 'HOLD' ? 'arflex-bad' : ''},
          el('td', {}, s.op), el('td', {}, s.component), el('td', {}, s.reason))), 'no step'),
      el('p', {}, 'Stop order: ', p.stopOrder || '(none)', el('br'), 'Start order: ', p.startOrder || '(none)'),
      (p.wiring || []).length ? el('div', {}, el('h4', {}, 'Wiring after the set'),
        el('ul', {id: prefix + '-wiring'}, p.wiring.map(w => el('li', {}, w)))) : '',
      (p.cpus || []).length ? el('div', {}, el('h4', {}, 'Admission per CPU'),
        table(prefix + '-cpus', ['cpu', 'utilisation', 'cap', 'test', 'tasks', 'while both halves of an update run'],
          p.cpus.map(c =>
            el('tr', {'data-cpu': c.cpu, class: c.utilisation > c.cap
                || (c.transient || []).some(t => t.test === 'not schedulable') ? 'arflex-bad' : ''},
              el('td', {}, c.cpu), el('td', {}, c.utilisation.toFixed(2)), el('td', {}, c.cap.toFixed(2)),
              el('td', {}, c.test), el('td', {}, (c.tasks || []).join(', ')),
              el('td', {}, (c.transient || []).map(t => el('div', {'data-phase': t.phase},
                t.phase + ' (' + t.cycles + ' cycles): U=' + t.utilisation.toFixed(2) + ', ' + t.test
                + ' (' + (t.tasks || []).join(', ') + ')'))))), ''),
          (p.transientRefusals || []).length ? el('ul', {id: prefix + '-transient-refusals', class: 'arflex-bad'},
            p.transientRefusals.map(r => el('li', {}, r))) : '') : '',
      p.memory ? el('p', {}, 'Memory: ', p.memory) : '',
      (p.notActive || []).length ? el('div', {}, el('h4', {}, 'Not active after the set'),
        table(prefix + '-inactive', ['component', 'why'], p.notActive.map(n =>
          el('tr', {}, el('td', {}, n.component), el('td', {}, n.reason))), '')) : '',
      (p.notes || []).length ? el('ul', {}, p.notes.map(n => el('li', {}, n))) : '');
  }

  function showPlan(r, text) {
    const parts = r.parts || {};
    const admitted = r.admitted;
    const head = admitted
      ? el('div', {class: 'arflex-msg arflex-msg-ok', id: 'arflex-cs-admission'},
        'Admitted (dry run: nothing changed). Review the plan, then apply it.')
      : el('div', {class: 'arflex-msg arflex-msg-error', id: 'arflex-cs-admission'},
        'Refused' + (r.refusedLine ? ' (line ' + r.refusedLine + ')' : '') + ': ' + (r.refusal || ''));
    const apply = el('button', {type: 'button', id: 'arflex-cs-apply', onclick: async () => {
      apply.disabled = true;
      try {
        await post('changeset-apply', null, new URLSearchParams({actions: text, plan: r.planId}),
          'application/x-www-form-urlencoded');
        message(status, 'Applying the set…', 'info');
        applyingShown = true;
        pollLive();
        planBox.replaceChildren();
        shown = null;
      } catch (e) {
        message(status, 'Not applied: ' + e.message, 'error');
      }
      refresh();
    }}, 'Apply the plan shown');
    shown = {text, planId: r.planId};
    planBox.replaceChildren(el('h3', {}, 'Plan of the whole set'), head,
      el('div', {id: 'arflex-cs-plan-parts', 'data-plan-id': r.planId, 'data-admitted': String(admitted)},
        planParts(parts, 'arflex-cs-plan')),
      el('details', {}, el('summary', {}, 'As the DRCR wrote it'), el('div', {class: 'arflex-plan', id: 'arflex-cs-plan-text'}, r.text || '')),
      admitted ? el('p', {}, apply, ' nothing happens before this; the plan is made again and must be the same')
        : el('p', {}, 'Nothing to apply: change the set and plan again.'));
  }

  const planBtn = el('button', {type: 'button', id: 'arflex-cs-plan-btn', onclick: async () => {
    const text = actions.value;
    planBtn.disabled = true;
    try {
      showPlan(await post('changeset-plan', null, new URLSearchParams({actions: text}),
        'application/x-www-form-urlencoded'), text);
      status.replaceChildren();
    } catch (e) {
      shown = null;
      planBox.replaceChildren(el('div', {class: 'arflex-msg arflex-msg-error', id: 'arflex-cs-plan-error'}, e.message));
      status.replaceChildren();
    } finally { planBtn.disabled = false; }
  }}, 'Plan');
  actions.addEventListener('input', () => {
    if (shown && shown.text !== actions.value) {
      shown = null;
      planBox.replaceChildren(el('p', {}, 'The actions changed: plan them again.'));
    }
  });

  /**
   * An update of a set in the history (D62), as the DRCR's progress last showed it: its phase,
   * cycle k of K, its shadow run's worst deviation, its verdict (a cancelled one names the update
   * whose rejection cancelled it). The numbers also as data-* attributes for a browser test.
   */
  function historyEntry(u) {
    return el('div', {class: 'arflex-cs-history-update', 'data-component': u.component, 'data-phase': u.phase || '',
      'data-cycle': u.cycle, 'data-cycles': u.cycles, 'data-worst': u.worstField ? u.worstDeviation : '',
      'data-verdict': u.verdict || '', title: u.why || ''},
      u.component + ': ' + (u.phase ? (PHASE_TEXT[u.phase] || u.phase) + ' cycle ' + u.cycle + ' of ' + u.cycles
        : 'no shadow run or window')
      + (u.worstField ? ', worst ' + u.worstField + ' ' + Number(u.worstDeviation).toPrecision(3)
        + ' (tolerance ' + u.tolerance + ')' : '')
      + '; ' + verdictText(u, false));
  }

  function outcomeRow(o, i) {
    const ups = (o.updates || []).map(u => u.component + ': ' + u.verdict.replace(/-/g, ' ')
      + (u.cycles !== null && u.cycles !== undefined ? ' after ' + u.cycles + ' cycles' : '')).join('; ');
    const entries = o.entries || [];
    return el('tr', {'data-outcome': o.outcome, 'data-index': i},
      el('td', {}, when(o.finishedMillis)),
      el('td', {}, (o.actions || []).join('; ')),
      el('td', {class: o.outcome === 'committed' ? '' : 'arflex-bad'}, OUTCOME_TEXT[o.outcome] || o.outcome),
      el('td', {}, o.why || ''), el('td', {}, entries.length ? entries.map(historyEntry) : ups),
      el('td', {}, o.applied ? (o.prepareMs.toFixed(1) + ' ms / ' + (o.switchUs / 1000).toFixed(1) + ' ms') : ''),
      el('td', {}, el('details', {}, el('summary', {}, 'text'), el('div', {class: 'arflex-plan'}, o.text || ''))));
  }

  function render(s) {
    if (!s.drcr) { message(status, 'The DRCR is not running: no change set can be planned or applied.', 'error'); }
    if (s.applying) {
      progress.replaceChildren(el('div', {class: 'arflex-msg', id: 'arflex-cs-applying'},
        'Applying: ' + s.applying.actions.join('; ') + ' — since ' + when(s.applying.startedMillis)
        + ' (' + (s.applying.forMs / 1000).toFixed(1) + ' s; prepared halves, shadow runs and rollback windows take their cycles)'));
    } else if (s.last) {
      if (applyingShown) { status.replaceChildren(); applyingShown = false; }
      const o = s.last;
      progress.replaceChildren(el('div', {class: 'arflex-msg ' + (o.outcome === 'committed' ? 'arflex-msg-ok' : 'arflex-msg-error'),
        id: 'arflex-cs-outcome', 'data-outcome': o.outcome},
        'Last set applied here: ' + (o.actions || []).join('; ') + ' — ' + (OUTCOME_TEXT[o.outcome] || o.outcome)
        + (o.cycles !== null && o.cycles !== undefined ? ' after ' + o.cycles + ' cycles' : '')
        + (o.why ? ': ' + o.why : '')
        + (o.planAsShown === false ? ' (warning: the plan the DRCR applied differs from the one shown)' : '')));
    } else {
      progress.replaceChildren();
    }
    // redrawn only when it changed, so a history entry opened to read its text stays open
    const key = JSON.stringify(s.history || []);
    if (key === historyKey) return;
    historyKey = key;
    const rows = (s.history || []).map(outcomeRow);
    historyBox.replaceChildren(el('h3', {}, 'Sets applied in this runtime (newest first, the last 50)'),
      table('arflex-cs-history-table', ['finished', 'actions', 'outcome', 'why', 'updates', 'prepared / switch', ''],
        rows, 'No set applied yet.'));
  }

  const VERDICT_TEXT = {'committed': 'committed', 'rolled-back': 'rolled back', 'rejected-in-shadow': 'rejected in shadow',
    'refused': 'refused before its shadow run'};

  /** An update's verdict in words; a cancelled one says whose rejection cancelled it (its why, D62). */
  function verdictText(u, running) {
    if (u.verdict === 'cancelled' && u.why) return u.why;
    return u.verdict ? VERDICT_TEXT[u.verdict] || u.verdict : running ? '' : 'no verdict of its own';
  }

  /**
   * One row per update of a set of several (D60), in the set's order: its phase, a bar with cycle
   * k of K, its shadow run's worst deviation, its verdict. Each row carries the numbers as data-*
   * attributes for a browser test.
   */
  function updateRows(p) {
    const updates = p.updates || [];
    if (updates.length < 2) return '';
    return table('arflex-cs-live-updates', ['update', 'phase', 'cycles', 'worst deviation in shadow', 'verdict'],
      updates.map(u => el('tr', {'data-component': u.component, 'data-phase': u.phase || '', 'data-cycle': u.cycle,
        'data-cycles': u.cycles, 'data-worst': u.worstField ? u.worstDeviation : '', 'data-verdict': u.verdict || '',
        class: 'arflex-cs-live-update' + (u.verdict && u.verdict !== 'committed' ? ' arflex-bad' : '')},
      el('td', {}, u.component),
      el('td', {}, u.phase ? PHASE_TEXT[u.phase] || u.phase : p.running ? 'not yet' : '—'),
      el('td', {}, u.cycles > 0 ? el('progress', {max: u.cycles, value: Math.min(u.cycle, u.cycles)}) : '',
        u.cycles > 0 ? ' cycle ' + u.cycle + ' of ' + u.cycles : ''),
      el('td', {}, u.worstField ? u.worstField + ' ' + Number(u.worstDeviation).toPrecision(3)
        + ' (tolerance ' + u.tolerance + ')' : ''),
      el('td', {title: u.why || ''}, verdictText(u, p.running)))), 'no update');
  }

  /** The DRCR's progress of the set being applied (or of the last one): phases, step, cycles, outcome. */
  function renderLive(r) {
    const p = r.progress;
    if (!p) { live.replaceChildren(); return; }
    const phases = p.phases || [];
    const ok = p.outcome === 'committed';
    live.replaceChildren(el('div', {id: 'arflex-cs-live-box', 'data-phase': p.phase, 'data-running': String(p.running),
      'data-outcome': p.outcome || '', class: 'arflex-msg' + (p.running ? '' : ok ? ' arflex-msg-ok' : ' arflex-msg-error')},
      el('strong', {}, p.running ? 'Applying now: ' : 'Last set applied in this runtime: '), (p.actions || []).join('; '),
      p.running ? ' (' + (p.forMs / 1000).toFixed(1) + ' s since it began)'
        : ' (took ' + ((p.phaseMillis - p.startedMillis) / 1000).toFixed(1) + ' s, finished ' + when(p.phaseMillis) + ')',
      el('ol', {id: 'arflex-cs-live-phases'}, phases.map((ph, i) => el('li', {'data-phase': ph},
        i === phases.length - 1 && p.running ? el('strong', {}, PHASE_TEXT[ph] || ph) : (PHASE_TEXT[ph] || ph)))),
      el('div', {id: 'arflex-cs-live-step'}, p.running ? p.step
        : (OUTCOME_TEXT[p.outcome] || p.outcome) + (p.why ? ': ' + p.why : '')),
      p.running && p.cycles > 0 ? el('div', {id: 'arflex-cs-live-cycles', 'data-cycle': p.cycle, 'data-cycles': p.cycles},
        el('progress', {max: p.cycles, value: Math.min(p.cycle, p.cycles)}),
        ' cycle ' + p.cycle + ' of ' + p.cycles + (p.component ? ' (' + p.component + ')' : '')) : '',
      p.running && p.worstField ? el('div', {id: 'arflex-cs-live-worst'}, 'Worst deviation so far: ' + p.worstField + ' '
        + Number(p.worstDeviation).toPrecision(3) + ' from the running version\'s (tolerance ' + p.tolerance + ')') : '',
      updateRows(p)));
  }

  async function pollLive() {
    if (livePolling) return;
    livePolling = true;
    let sawRunning = false;
    try {
      for (;;) {
        const r = await get('changeset-progress');
        renderLive(r);
        if (!r.progress || !r.progress.running) break;
        sawRunning = true;
        await new Promise(done => setTimeout(done, 250));
      }
      // the apply is over: the outcome and the history below follow without waiting for the next second
      if (sawRunning) setTimeout(refresh, 200);
    } catch (e) {
      live.replaceChildren(el('div', {class: 'arflex-msg arflex-msg-error'}, 'Cannot read the progress: ' + e.message));
    } finally { livePolling = false; }
  }

  async function refresh() {
    pollLive();
    try { render(await get('changesets')); } catch (e) { message(status, 'Cannot read the change sets: ' + e.message, 'error'); }
  }

  app.replaceChildren(el('h2', {}, 'Change sets'), status,
    el('fieldset', {}, el('legend', {}, 'Actions, one per line'), actions, el('br'),
      el('small', {}, 'install <component> · uninstall <component> · set <component> <parameter> <value> · '
        + 'update <component> <jar URL> [<sha256>] [window N] [shadow K] [envelope <port>.<field> <min> <max>] '
        + '[tolerance <port>.<field> <max>]'), el('br'), planBtn),
    planBox, live, progress, historyBox);
  refresh();
  setInterval(refresh, 1000);
})();
