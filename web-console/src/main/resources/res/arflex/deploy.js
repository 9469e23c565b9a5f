/* Deploy page: install from an uploaded jar or a URL (https or file, SHA-256 pinned), update,
 * uninstall; every change shows the DRCR's plan first and waits for the user to confirm. When
 * the DRCR cannot plan, the page shows why and offers nothing to confirm. */
'use strict';
(() => {
  const {app, el, get, post, stateBadge, message} = Arflex;
  const status = el('div', {id: 'arflex-deploy-status'});
  const plan = el('div', {id: 'arflex-plan'});
  const installed = el('div', {id: 'arflex-installed'});

  // The plan waiting for Confirm; replacing it (another plan, or an error) cancels it, so a
  // staged jar is discarded and never left behind a plan that is no longer shown.
  let pending = null;
  function dropPending() {
    const p = pending;
    pending = null;
    if (p && p.onCancel) p.onCancel();
  }

  function showPlan(title, text, details, onConfirm, onCancel) {
    dropPending();
    const mine = {onCancel};
    pending = mine;
    const confirm = el('button', {type: 'button', id: 'arflex-confirm', onclick: async () => {
      confirm.disabled = true;
      if (pending === mine) pending = null;
      try { await onConfirm(); } finally { plan.replaceChildren(); refresh(); }
    }}, 'Confirm');
    const cancel = el('button', {type: 'button', id: 'arflex-cancel', onclick: async () => {
      if (pending === mine) pending = null;
      if (onCancel) await onCancel();
      plan.replaceChildren();
    }}, 'Cancel');
    plan.replaceChildren(el('h2', {}, title), details || '', el('div', {class: 'arflex-plan', id: 'arflex-plan-text'}, text),
      el('p', {}, confirm, ' ', cancel));
  }

  /** The DRCR could not plan: the error instead of a plan, and nothing to confirm. */
  function showPlanError(title, text) {
    dropPending();
    const close = el('button', {type: 'button', id: 'arflex-plan-close', onclick: () => plan.replaceChildren()}, 'Close');
    plan.replaceChildren(el('h2', {}, title),
      el('div', {class: 'arflex-msg arflex-msg-error', id: 'arflex-plan-error'}, text),
      el('p', {}, 'Nothing can be confirmed: nothing was changed. ', close));
  }

  /** A stage (upload or URL) was refused or could not be planned: no plan stays on the page. */
  function stageRefused(what, e) {
    dropPending();
    plan.replaceChildren();
    message(status, what + ': ' + e.message, 'error');
  }

  async function staged(r) {
    showPlan('Plan: install ' + r.symbolicName + ' ' + r.version, r.plan,
      el('p', {}, 'From ' + r.origin + ', SHA-256 ', el('code', {id: 'arflex-staged-sha'}, r.sha256)),
      async () => {
        try {
          const done = await post('install', {id: r.id});
          message(status, done.symbolicName + ' ' + done.action + ' (bundle ' + done.bundleId + ')', 'ok');
        } catch (e) { message(status, 'Install failed: ' + e.message, 'error'); }
      },
      async () => { try { await post('discard', {id: r.id}); } catch (e) { /* already gone */ } });
  }

  const file = el('input', {type: 'file', id: 'arflex-upload-file', accept: '.jar'});
  const uploadBtn = el('button', {type: 'button', id: 'arflex-upload', onclick: async () => {
    if (!file.files.length) { message(status, 'Choose a jar first.', 'error'); return; }
    const f = file.files[0];
    try {
      staged(await post('stage-upload', {file: f.name}, f, 'application/java-archive'));
      message(status, 'Uploaded ' + f.name + '; review the plan below.', 'info');
    } catch (e) { stageRefused('Upload refused', e); }
  }}, 'Upload and plan');
  const url = el('input', {type: 'text', id: 'arflex-url', size: 60, placeholder: 'https://… or file:/…'});
  const sha = el('input', {type: 'text', id: 'arflex-sha256', size: 66, placeholder: 'pinned SHA-256 (64 hex digits)'});
  const urlBtn = el('button', {type: 'button', id: 'arflex-fetch', onclick: async () => {
    try {
      staged(await post('stage-url', {url: url.value, sha256: sha.value}));
      message(status, 'Fetched and checked; review the plan below.', 'info');
    } catch (e) { stageRefused('Refused', e); }
  }}, 'Fetch and plan');

  async function refresh() {
    try {
      const data = await get('cell');
      if (!data.drcr) { installed.replaceChildren(el('p', {}, 'The DRCR is not running.')); return; }
      const rows = (data.cell.instances || []).map(i => {
        const un = el('button', {type: 'button', id: 'arflex-uninstall-' + i.name, onclick: async () => {
          try {
            const p = await get('plan-uninstall', {name: i.name});
            showPlan('Plan: uninstall ' + i.name, p.plan, '', async () => {
              try { await post('uninstall', {name: i.name}); message(status, i.name + ' uninstalled', 'ok'); }
              catch (e) { message(status, 'Uninstall failed: ' + e.message, 'error'); }
            });
          } catch (e) { status.replaceChildren(); showPlanError('Uninstall ' + i.name + ': no plan', e.message); }
        }}, 'Uninstall…');
        const up = el('button', {type: 'button', id: 'arflex-update-' + i.name, onclick: async () => {
          // The DRCR's dry run: it downloads from the contract's update URL, checks the pinned
          // SHA-256 and the new contracts, and plans the replacement; nothing is installed yet.
          up.disabled = true;
          let p;
          try {
            p = await post('plan-update', {name: i.name});
          } catch (e) {
            status.replaceChildren();
            showPlanError('Update ' + i.name + ': no plan', e.message);
            return;
          } finally { up.disabled = false; }
          message(status, 'Planned the update of ' + i.name + '; review the plan below.', 'info');
          showPlan('Plan: update ' + i.name + ' ' + (p.version || ''), p.plan,
            el('p', {}, 'From ' + p.updateUrl + ', pinned SHA-256 ', el('code', {id: 'arflex-update-sha'}, p.sha256)),
            async () => {
              // The pin the plan was made for: a contract that pins something else by now is refused.
              try { const r = await post('update', p.sha256 ? {name: i.name, sha256: p.sha256} : {name: i.name}); message(status, r.report, 'ok'); }
              catch (e) { message(status, 'Update failed: ' + e.message, 'error'); }
            });
        }}, 'Update…');
        return el('tr', {'data-component': i.name}, el('td', {}, i.name), el('td', {}, stateBadge(i.state)),
          el('td', {}, String(i.bundleId)), el('td', {}, up, ' ', un));
      });
      installed.replaceChildren(el('table', {class: 'arflex-table', id: 'arflex-deployed'},
        el('tr', {}, ['Component', 'State', 'Bundle', ''].map(h => el('th', {}, h))),
        rows.length ? rows : el('tr', {}, el('td', {colspan: 4}, 'No component installed.'))));
    } catch (e) { message(status, 'Cannot read the cell: ' + e.message, 'error'); }
  }

  app.replaceChildren(el('h2', {}, 'Deploy'), status,
    el('fieldset', {}, el('legend', {}, 'Install from an uploaded jar'), file, ' ', uploadBtn),
    el('fieldset', {}, el('legend', {}, 'Install from a URL (https or file, pinned SHA-256)'), url, el('br'), sha, ' ', urlBtn),
    plan, el('h2', {}, 'Installed components'), installed);
  refresh();
})();
