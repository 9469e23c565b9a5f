/* Deploy page: install from an uploaded jar or a URL (https or file, SHA-256 pinned), update,
 * uninstall; every change shows the DRCR's plan first and waits for the user to confirm. */
'use strict';
(() => {
  const {app, el, get, post, stateBadge, message} = Arflex;
  const status = el('div', {id: 'arflex-deploy-status'});
  const plan = el('div', {id: 'arflex-plan'});
  const installed = el('div', {id: 'arflex-installed'});

  function showPlan(title, text, details, onConfirm, onCancel) {
    const confirm = el('button', {type: 'button', id: 'arflex-confirm', onclick: async () => {
      confirm.disabled = true;
      try { await onConfirm(); } finally { plan.replaceChildren(); refresh(); }
    }}, 'Confirm');
    const cancel = el('button', {type: 'button', id: 'arflex-cancel', onclick: async () => {
      if (onCancel) await onCancel();
      plan.replaceChildren();
    }}, 'Cancel');
    plan.replaceChildren(el('h2', {}, title), details || '', el('div', {class: 'arflex-plan', id: 'arflex-plan-text'}, text),
      el('p', {}, confirm, ' ', cancel));
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
    } catch (e) { message(status, 'Upload refused: ' + e.message, 'error'); }
  }}, 'Upload and plan');
  const url = el('input', {type: 'text', id: 'arflex-url', size: 60, placeholder: 'https://… or file:/…'});
  const sha = el('input', {type: 'text', id: 'arflex-sha256', size: 66, placeholder: 'pinned SHA-256 (64 hex digits)'});
  const urlBtn = el('button', {type: 'button', id: 'arflex-fetch', onclick: async () => {
    try {
      staged(await post('stage-url', {url: url.value, sha256: sha.value}));
      message(status, 'Fetched and checked; review the plan below.', 'info');
    } catch (e) { message(status, 'Refused: ' + e.message, 'error'); }
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
          } catch (e) { message(status, 'Cannot plan: ' + e.message, 'error'); }
        }}, 'Uninstall…');
        const up = el('button', {type: 'button', id: 'arflex-update-' + i.name, onclick: async () => {
          showPlan('Update ' + i.name, 'Download the jar from the update URL of the contract (https or file), check its pinned SHA-256 and update the bundle; on any failure the old version keeps running.', '',
            async () => {
              try { const r = await post('update', {name: i.name}); message(status, r.report, 'ok'); }
              catch (e) { message(status, e.message, 'error'); }
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
