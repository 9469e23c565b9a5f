/* Contract editor: a form (ports, properties, timing, resources, fault policy, update) with the
 * XML beside it, kept in step both ways; validated on the server by the same ContractParser the
 * DRCR uses, each problem shown at its field; saved on the server or downloaded. */
'use strict';
(() => {
  const {app, el, get, post, message} = Arflex;
  const NS = 'urn:arflex:contract:1';
  const status = el('div', {id: 'arflex-contract-status'});
  const problemsBox = el('div', {id: 'arflex-problems'});
  const xmlArea = el('textarea', {id: 'arflex-xml', spellcheck: 'false'});
  const form = el('form', {id: 'arflex-contract-form', onsubmit: e => e.preventDefault()});

  const blank = () => ({name: 'my-component', version: '1.0.0', description: '', executable: 'my-component', task: 'periodic',
    movesHardware: 'false', motionThrough: '', ports: [], props: [], timing: {period: '1ms', deadline: '1ms', wcet: '100us', priority: '80', cpus: ''},
    resources: {memory: '8MiB', network: '0'}, criticality: '5',
    fault: {restart: 'permanent', intensity: '3', window: '10s', backoff: '100ms', safe: 'hold', heartbeatTimeout: '100ms'},
    update: {url: '', sha256: ''}});
  let model = blank();

  // ---- form ----------------------------------------------------------------------------
  function input(path, value, onchange, attrs) {
    const i = el('input', Object.assign({type: 'text', 'data-field': path, value: value ?? ''}, attrs || {}));
    i.addEventListener('input', () => { onchange(i.value); toXml(); });
    return i;
  }
  function select(path, value, options, onchange) {
    const s = el('select', {'data-field': path}, options.map(o => el('option', {value: o, selected: o === value}, o)));
    s.addEventListener('change', () => { onchange(s.value); toXml(); });
    return s;
  }
  function labelled(text, control) {
    return el('label', {}, text + ' ', control, el('span', {class: 'arflex-field-error'}));
  }

  function renderForm() {
    const m = model;
    const portRows = m.ports.map((p, k) => {
      const f = 'ports/' + p.dir + '[' + p.name + ']';
      return el('div', {class: 'arflex-port', 'data-field': f},
        labelled('dir', select(f + '/@dir', p.dir, ['in', 'out'], v => { p.dir = v; renderForm(); })),
        labelled('name', input(f + '/@name', p.name, v => { p.name = v; }, {size: 8, id: 'arflex-port-name-' + k})),
        labelled('type', input(f + '/@type', p.type, v => { p.type = v; }, {size: 14, id: 'arflex-port-type-' + k})),
        labelled('version', input(f + '/@typeVersion', p.typeVersion, v => { p.typeVersion = v; }, {size: 4})),
        labelled('method', select(f + '/@method', p.method, ['state', 'stream', 'frame'], v => { p.method = v; })),
        p.dir === 'out' ? [labelled('depth', input(f + '/@depth', p.depth, v => { p.depth = v; }, {size: 4})),
          labelled('overflow', select(f + '/@overflow', p.overflow, ['', 'drop-oldest', 'drop-newest'], v => { p.overflow = v; }))]
          : [labelled('optional', select(f + '/@optional', p.optional, ['false', 'true'], v => { p.optional = v; })),
            labelled('bind component', input(f + '/bind/@component', p.bindComponent, v => { p.bindComponent = v; }, {size: 12})),
            labelled('port', input(f + '/bind/@port', p.bindPort, v => { p.bindPort = v; }, {size: 6}))],
        el('button', {type: 'button', onclick: () => { m.ports.splice(k, 1); renderForm(); toXml(); }}, 'remove'));
    });
    const propRows = m.props.map((p, k) => {
      const f = 'properties/property[' + p.name + ']';
      return el('div', {class: 'arflex-prop', 'data-field': f},
        labelled('name', input(f + '/@name', p.name, v => { p.name = v; }, {size: 8})),
        labelled('type', select(f + '/@type', p.type, ['double', 'int', 'bool'], v => { p.type = v; })),
        labelled('default', input(f + '/@default', p.default, v => { p.default = v; }, {size: 6, id: 'arflex-prop-default-' + k})),
        labelled('min', input(f + '/@min', p.min, v => { p.min = v; }, {size: 5, id: 'arflex-prop-min-' + k})),
        labelled('max', input(f + '/@max', p.max, v => { p.max = v; }, {size: 5, id: 'arflex-prop-max-' + k})),
        labelled('unit', input(f + '/@unit', p.unit, v => { p.unit = v; }, {size: 4})),
        labelled('mutable', select(f + '/@mutable', p.mutable, ['true', 'false'], v => { p.mutable = v; })),
        labelled('text', input(f, p.text, v => { p.text = v; }, {size: 20})),
        el('button', {type: 'button', onclick: () => { m.props.splice(k, 1); renderForm(); toXml(); }}, 'remove'));
    });
    form.replaceChildren(
      el('fieldset', {'data-field': 'component'}, el('legend', {}, 'Component'),
        labelled('name', input('component/@name', m.name, v => { m.name = v; }, {id: 'arflex-f-name'})),
        labelled('version', input('component/@version', m.version, v => { m.version = v; }, {size: 8, id: 'arflex-f-version'})),
        labelled('description', input('description', m.description, v => { m.description = v; }, {size: 40}))),
      el('fieldset', {'data-field': 'implementation'}, el('legend', {}, 'Implementation'),
        labelled('executable', input('implementation/@executable', m.executable, v => { m.executable = v; })),
        labelled('task', select('implementation/@task', m.task, ['periodic', 'sporadic', 'service'], v => { m.task = v; })),
        labelled('moves hardware', select('implementation/@movesHardware', m.movesHardware, ['false', 'true'], v => { m.movesHardware = v; })),
        labelled('motion through', select('implementation/@motionThrough', m.motionThrough, ['', 'device', 'outputs'], v => { m.motionThrough = v; }))),
      el('fieldset', {'data-field': 'ports'}, el('legend', {}, 'Ports'), portRows,
        el('button', {type: 'button', id: 'arflex-add-port', onclick: () => { m.ports.push({dir: 'out', name: 'y', type: 'arflex.Sample', typeVersion: '1.0', method: 'stream', depth: '64', overflow: 'drop-oldest', optional: 'false', bindComponent: '', bindPort: ''}); renderForm(); toXml(); }}, 'add port')),
      el('fieldset', {'data-field': 'properties'}, el('legend', {}, 'Properties'), propRows,
        el('button', {type: 'button', id: 'arflex-add-prop', onclick: () => { m.props.push({name: 'gain', type: 'double', default: '1.0', min: '', max: '', unit: '1', mutable: 'true', text: ''}); renderForm(); toXml(); }}, 'add property')),
      el('fieldset', {'data-field': 'timing'}, el('legend', {}, 'Timing'),
        ['period', 'deadline', 'wcet', 'priority', 'cpus'].map(a => labelled(a, input('timing/@' + a, m.timing[a], v => { m.timing[a] = v; }, {size: 6, id: 'arflex-f-timing-' + a})))),
      el('fieldset', {'data-field': 'resources'}, el('legend', {}, 'Resources'),
        ['memory', 'network'].map(a => labelled(a, input('resources/@' + a, m.resources[a], v => { m.resources[a] = v; }, {size: 8}))),
        labelled('criticality', input('criticality', m.criticality, v => { m.criticality = v; }, {size: 4}))),
      el('fieldset', {'data-field': 'fault'}, el('legend', {}, 'Fault policy'),
        labelled('restart', select('fault/@restart', m.fault.restart, ['permanent', 'transient', 'temporary'], v => { m.fault.restart = v; })),
        ['intensity', 'window', 'backoff', 'heartbeatTimeout'].map(a => labelled(a, input('fault/@' + a, m.fault[a], v => { m.fault[a] = v; }, {size: 6}))),
        labelled('safe', select('fault/@safe', m.fault.safe, ['hold', 'zero'], v => { m.fault.safe = v; }))),
      el('fieldset', {'data-field': 'update'}, el('legend', {}, 'Update (optional)'),
        labelled('url', input('update/@url', m.update.url, v => { m.update.url = v; }, {size: 40})),
        labelled('sha256', input('update/@sha256', m.update.sha256, v => { m.update.sha256 = v; }, {size: 66}))));
  }

  // ---- XML <-> model --------------------------------------------------------------------
  function toXml() {
    const m = model;
    const doc = document.implementation.createDocument(NS, 'component', null);
    const root = doc.documentElement;
    const add = (parent, name, attrs, text) => {
      const e = doc.createElementNS(NS, name);
      for (const [k, v] of Object.entries(attrs || {})) if (v !== '' && v !== undefined && v !== null) e.setAttribute(k, v);
      if (text) e.textContent = text;
      parent.appendChild(e);
      return e;
    };
    root.setAttribute('name', m.name); root.setAttribute('version', m.version);
    if (m.description) add(root, 'description', {}, m.description);
    add(root, 'implementation', {executable: m.executable, task: m.task, movesHardware: m.movesHardware, motionThrough: m.motionThrough});
    if (m.ports.length) {
      const ports = add(root, 'ports');
      for (const p of m.ports) {
        if (p.dir === 'in') {
          const e = add(ports, 'in', {name: p.name, type: p.type, typeVersion: p.typeVersion, method: p.method, optional: p.optional});
          if (p.bindComponent || p.bindPort) add(e, 'bind', {component: p.bindComponent, port: p.bindPort});
        } else {
          add(ports, 'out', {name: p.name, type: p.type, typeVersion: p.typeVersion, method: p.method, depth: p.depth, overflow: p.overflow});
        }
      }
    }
    if (m.props.length) {
      const props = add(root, 'properties');
      for (const p of m.props) add(props, 'property', {name: p.name, type: p.type, default: p.default, min: p.min, max: p.max, unit: p.unit, mutable: p.mutable}, p.text);
    }
    if (m.task !== 'service' || m.timing.period) add(root, 'timing', m.timing);
    add(root, 'resources', m.resources);
    add(root, 'criticality', {}, m.criticality);
    add(root, 'fault', m.fault);
    if (m.update.url || m.update.sha256) add(root, 'update', m.update);
    xmlArea.value = pretty(doc);
  }

  function pretty(doc) {
    const out = ['<?xml version="1.0" encoding="UTF-8"?>'];
    const ser = new XMLSerializer();
    const walk = (node, depth, isRoot) => {
      const pad = '  '.repeat(depth);
      const attrs = Array.from(node.attributes).map(a => ' ' + a.name + '="' + esc(a.value) + '"').join('');
      const ns = isRoot ? ' xmlns="' + NS + '"' : '';
      const kids = Array.from(node.children);
      if (!kids.length) {
        const text = node.textContent;
        out.push(pad + '<' + node.localName + ns + attrs + (text ? '>' + esc(text) + '</' + node.localName + '>' : '/>'));
      } else {
        out.push(pad + '<' + node.localName + ns + attrs + '>');
        kids.forEach(k => walk(k, depth + 1, false));
        out.push(pad + '</' + node.localName + '>');
      }
    };
    void ser;
    walk(doc.documentElement, 0, true);
    return out.join('\n') + '\n';
  }
  function esc(s) { return String(s).replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;').replace(/"/g, '&quot;'); }

  function fromXml() {
    const doc = new DOMParser().parseFromString(xmlArea.value, 'application/xml');
    if (doc.getElementsByTagName('parsererror').length) { message(status, 'The XML is not well-formed; the form was left as it was.', 'error'); return false; }
    const r = doc.documentElement;
    const one = (name) => Array.from(r.children).find(c => c.localName === name);
    const at = (e, a) => (e && e.getAttribute(a)) ?? '';
    const m = blank();
    m.name = at(r, 'name'); m.version = at(r, 'version');
    m.description = one('description') ? one('description').textContent : '';
    const impl = one('implementation');
    m.executable = at(impl, 'executable'); m.task = at(impl, 'task') || 'periodic'; m.movesHardware = at(impl, 'movesHardware') || 'false'; m.motionThrough = at(impl, 'motionThrough') || '';
    m.ports = one('ports') ? Array.from(one('ports').children).map(p => {
      const b = Array.from(p.children).find(c => c.localName === 'bind');
      return {dir: p.localName, name: at(p, 'name'), type: at(p, 'type'), typeVersion: at(p, 'typeVersion'), method: at(p, 'method'),
        depth: at(p, 'depth'), overflow: at(p, 'overflow'), optional: at(p, 'optional') || 'false', bindComponent: at(b, 'component'), bindPort: at(b, 'port')};
    }) : [];
    m.props = one('properties') ? Array.from(one('properties').children).map(p => ({name: at(p, 'name'), type: at(p, 'type'),
      default: at(p, 'default'), min: at(p, 'min'), max: at(p, 'max'), unit: at(p, 'unit'), mutable: at(p, 'mutable') || 'false', text: p.textContent.trim()})) : [];
    const t = one('timing');
    m.timing = {period: at(t, 'period'), deadline: at(t, 'deadline'), wcet: at(t, 'wcet'), priority: at(t, 'priority'), cpus: at(t, 'cpus')};
    const res = one('resources'); m.resources = {memory: at(res, 'memory'), network: at(res, 'network')};
    m.criticality = one('criticality') ? one('criticality').textContent.trim() : '';
    const f = one('fault');
    m.fault = {restart: at(f, 'restart'), intensity: at(f, 'intensity'), window: at(f, 'window'), backoff: at(f, 'backoff'), safe: at(f, 'safe'), heartbeatTimeout: at(f, 'heartbeatTimeout')};
    const u = one('update'); m.update = {url: at(u, 'url'), sha256: at(u, 'sha256')};
    model = m;
    renderForm();
    return true;
  }

  // ---- validation -------------------------------------------------------------------------
  function clearProblems() {
    form.querySelectorAll('.arflex-invalid').forEach(e => e.classList.remove('arflex-invalid'));
    form.querySelectorAll('.arflex-field-error').forEach(e => { e.textContent = ''; });
    problemsBox.replaceChildren();
  }

  function fieldFor(path) {
    let best = null; let bestLen = -1;
    for (const e of form.querySelectorAll('[data-field]')) {
      const f = e.getAttribute('data-field');
      if ((path === f || path.startsWith(f + '/') || path.startsWith(f + '[')) && f.length > bestLen) { best = e; bestLen = f.length; }
    }
    return best;
  }

  function showProblems(problems) {
    clearProblems();
    if (!problems.length) { message(status, 'Valid: the DRCR would accept this contract.', 'ok'); return; }
    message(status, problems.length + ' problem(s); each is shown at its field.', 'error');
    problemsBox.replaceChildren(el('ul', {}, problems.map(p => el('li', {class: 'arflex-problem', 'data-field': p.field},
      'line ' + p.line + ':' + p.column + ' [§' + p.section + '] ' + p.field + ': ' + p.message))));
    for (const p of problems) {
      const target = fieldFor(p.field);
      if (!target) continue;
      target.classList.add('arflex-invalid');
      const holder = target.tagName === 'INPUT' || target.tagName === 'SELECT' ? target.parentElement : target;
      let err = holder.querySelector(':scope > .arflex-field-error');
      if (!err) { err = el('span', {class: 'arflex-field-error'}); holder.appendChild(err); }
      err.textContent = (err.textContent ? err.textContent + '; ' : '') + p.message;
    }
  }

  async function validate() {
    try { showProblems((await post('validate', null, xmlArea.value, 'application/xml')).problems); }
    catch (e) { message(status, 'Cannot validate: ' + e.message, 'error'); }
  }

  async function save() {
    try {
      const r = await post('save', {name: model.name}, xmlArea.value, 'application/xml');
      if (r.saved) { clearProblems(); message(status, 'Saved to ' + r.path, 'ok'); loadList(); }
      else showProblems(r.problems);
    } catch (e) { message(status, 'Cannot save: ' + e.message, 'error'); }
  }

  function download() {
    const a = el('a', {href: URL.createObjectURL(new Blob([xmlArea.value], {type: 'application/xml'})), download: (model.name || 'contract') + '.xml'});
    document.body.appendChild(a); a.click(); a.remove();
  }

  const savedList = el('select', {id: 'arflex-saved'});
  async function loadList() {
    try {
      const r = await get('contracts');
      savedList.replaceChildren(el('option', {value: ''}, '(saved contracts)'), r.saved.map(n => el('option', {value: n}, n)));
    } catch (e) { /* listed when the server answers */ }
  }
  savedList.addEventListener('change', async () => {
    if (!savedList.value) return;
    try { xmlArea.value = (await get('contract', {name: savedList.value})).xml; fromXml(); clearProblems(); }
    catch (e) { message(status, e.message, 'error'); }
  });

  const toolbar = el('p', {},
    el('button', {type: 'button', id: 'arflex-validate', onclick: validate}, 'Validate'), ' ',
    el('button', {type: 'button', id: 'arflex-save', onclick: save}, 'Save'), ' ',
    el('button', {type: 'button', id: 'arflex-download', onclick: download}, 'Download'), ' ',
    el('button', {type: 'button', id: 'arflex-from-xml', onclick: () => { if (fromXml()) toXml(); }}, 'XML → form'), ' ',
    el('button', {type: 'button', id: 'arflex-new', onclick: () => { model = blank(); renderForm(); toXml(); clearProblems(); }}, 'New'), ' ',
    savedList);
  app.replaceChildren(el('h2', {}, 'Contract editor'), status, toolbar, problemsBox,
    el('div', {class: 'arflex-editor'}, el('div', {}, form), el('div', {}, el('h3', {}, 'XML'), xmlArea)));
  renderForm();
  toXml();
  loadList();
})();
