/* Audit page: who changed what through the console, when, and what it answered (newest
 * first); the security history (logins, changes, refusals summed up; issue 30) and the refusals
 * of this minute counted but not written one by one; the bundles kept from resolving because
 * their headers carry markup. */
'use strict';
(() => {
  const {app, el, get, message} = Arflex;
  const status = el('div', {id: 'arflex-audit-status'});
  const refused = el('div', {id: 'arflex-refused'});
  const log = el('div', {id: 'arflex-audit'});
  const security = el('div', {id: 'arflex-security'});
  app.replaceChildren(el('h2', {}, 'Audit'), status, refused, log, security);

  function params(p) {
    return Object.entries(p || {}).map(([k, v]) => k + '=' + v).join(' ');
  }

  function render(r) {
    if ((r.refusedBundles || []).length) {
      refused.replaceChildren(el('h3', {}, 'Bundles not resolved (markup in their headers)'),
        el('table', {class: 'arflex-table', id: 'arflex-refused-table'},
          el('tr', {}, el('th', {}, 'bundle'), el('th', {}, 'location'), el('th', {}, 'why'), el('th', {}, 'since')),
          r.refusedBundles.map(b => el('tr', {'data-bundle': b.bundleId},
            el('td', {}, String(b.bundleId)), el('td', {}, b.location), el('td', {}, b.reason), el('td', {}, b.time)))));
    } else {
      refused.replaceChildren();
    }
    log.replaceChildren(el('p', {}, 'Newest first, from ', el('code', {}, r.file), ' (rotated files included).'),
      table('arflex-audit-table', r.entries));
    const counted = Object.entries(r.refusalsNotWritten || {});
    security.replaceChildren(el('h3', {}, 'Security history'),
      el('p', {}, 'Logins, accepted changes and refusals (sampled, then counted), newest first, from ',
        el('code', {}, r.securityFile || ''), '.'),
      counted.length ? el('p', {id: 'arflex-refusals-counted'}, 'Refused this minute and counted only: ',
        counted.map(([o, n]) => o + ' ' + n).join(', ')) : '',
      table('arflex-security-table', r.security));
  }

  function table(id, entries) {
    const rows = (entries || []).map(e => el('tr', {'data-status': e.status, 'data-method': e.method, 'data-path': e.path || ''},
      el('td', {}, e.time || ''), el('td', {}, e.user || ''), el('td', {}, e.remote || ''), el('td', {}, e.method || ''),
      el('td', {}, e.path || ''), el('td', {}, params(e.params)),
      el('td', {class: e.status >= 400 ? 'arflex-bad' : ''}, String(e.status)), el('td', {}, e.reason || '')));
    return el('table', {class: 'arflex-table', id, 'data-entries': rows.length},
      el('tr', {}, ['time', 'user', 'from', 'method', 'path', 'what', 'status', 'why'].map(h => el('th', {}, h))),
      rows);
  }

  async function refresh() {
    try {
      render(await get('audit'));
      status.replaceChildren();
    } catch (e) {
      message(status, 'Cannot read the audit log: ' + e.message, 'error');
    }
  }
  refresh();
  setInterval(refresh, 5000);
})();
