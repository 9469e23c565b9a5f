/* ARFLEX console: helpers shared by every page. All data goes into the DOM through
 * textContent or attribute setters, never through innerHTML, so nothing the runtime or a
 * contract says can become markup. */
'use strict';
const Arflex = (() => {
  const app = document.getElementById('arflex-app');
  const root = app.dataset.root;
  const appRoot = app.dataset.appRoot;
  const csrf = app.dataset.csrf;

  /** Element builder: el('td', {class: 'x'}, 'text', childNode, ...). */
  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v === undefined || v === null || v === false) continue;
      if (k.startsWith('on')) e.addEventListener(k.substring(2), v);
      else if (k === 'class') e.className = v;
      else e.setAttribute(k, v === true ? '' : String(v));
    }
    for (const c of children.flat()) {
      if (c === undefined || c === null) continue;
      e.append(c instanceof Node ? c : document.createTextNode(String(c)));
    }
    return e;
  }

  async function request(method, path, params, body, contentType) {
    const q = params ? '?' + new URLSearchParams(params).toString() : '';
    const headers = {'Accept': 'application/json'};
    if (method !== 'GET') {
      headers['X-Arflex-Csrf'] = csrf;
      if (contentType) headers['Content-Type'] = contentType;
    }
    const r = await fetch(root + '/api/' + path + q, {method, headers, body, credentials: 'same-origin'});
    let data;
    try { data = await r.json(); } catch (e) { data = {error: 'HTTP ' + r.status}; }
    if (!r.ok) {
      const err = new Error(data.error || ('HTTP ' + r.status));
      err.status = r.status; err.data = data;
      throw err;
    }
    return data;
  }

  const get = (path, params) => request('GET', path, params);
  const post = (path, params, body, contentType) => request('POST', path, params, body, contentType);

  function fmtNs(ns) {
    if (ns === null || ns === undefined) return '';
    if (ns >= 1e9) return (ns / 1e9).toFixed(2) + ' s';
    if (ns >= 1e6) return (ns / 1e6).toFixed(2) + ' ms';
    if (ns >= 1e3) return (ns / 1e3).toFixed(1) + ' µs';
    return ns + ' ns';
  }

  function fmtBytes(b) {
    if (b === null || b === undefined) return '';
    const u = ['B', 'KiB', 'MiB', 'GiB'];
    let i = 0; let v = b;
    while (v >= 1024 && i < u.length - 1) { v /= 1024; i++; }
    return (i ? v.toFixed(1) : v) + ' ' + u[i];
  }

  function stateBadge(state) {
    return el('span', {class: 'arflex-state arflex-state-' + String(state || 'unknown').toLowerCase()}, state || '?');
  }

  function pageUrl(label, params) {
    return appRoot + '/' + label + (params ? '?' + new URLSearchParams(params).toString() : '');
  }

  function message(box, text, kind) {
    box.replaceChildren(el('div', {class: 'arflex-msg arflex-msg-' + (kind || 'info')}, text));
  }

  function clear(node) { node.replaceChildren(); return node; }

  const COLORS = ['#c62828', '#1565c0', '#2e7d32', '#6a1b9a', '#ef6c00', '#00838f', '#5d4037', '#455a64'];

  /** A rolling uPlot of the last `opts.window` points in `box`: push(tSeconds, [v1, v2, ...]). */
  function rollingPlot(box, labels, opts) {
    const o = opts || {};
    const keep = o.window || 300;
    const data = [[], ...labels.map(() => [])];
    const plot = new uPlot({width: o.width || 800, height: o.height || 220,
      series: [{}, ...labels.map((l, n) => ({label: l, stroke: (o.colors || COLORS)[n % COLORS.length]}))],
      axes: [{}, {label: o.unit || ''}]}, data, box);
    let n = 0;
    box.dataset.samples = '0';
    return {
      push(t, values) {
        data[0].push(t);
        values.forEach((v, j) => data[j + 1].push(typeof v === 'number' && isFinite(v) ? v : null));
        if (data[0].length > keep) data.forEach(a => a.shift());
        plot.setData(data);
        n++;
        box.dataset.samples = String(n);
      },
      get count() { return n; },
      plot
    };
  }

  /** Live stream of a component (and some of its output ports): EventSource, one JSON frame per message. */
  function stream(name, ports, onFrame) {
    if (typeof EventSource === 'undefined') return null;
    const q = {name};
    if (ports && ports.length) q.ports = ports.join(',');
    const src = new EventSource(root + '/api/stream?' + new URLSearchParams(q));
    src.onmessage = ev => onFrame(JSON.parse(ev.data));
    window.addEventListener('beforeunload', () => src.close());
    return src;
  }

  /** Formats a number for display (short, finite). */
  function fmtNum(v) {
    if (typeof v !== 'number' || !isFinite(v)) return String(v);
    if (Number.isInteger(v)) return String(v);
    return Math.abs(v) >= 1e4 || Math.abs(v) < 1e-3 ? v.toExponential(4) : v.toFixed(5);
  }

  return {app, root, appRoot, el, get, post, fmtNs, fmtBytes, fmtNum, stateBadge, pageUrl, message, clear, rollingPlot, stream};
})();
