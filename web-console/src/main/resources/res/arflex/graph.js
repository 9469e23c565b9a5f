/* Graph page: components and their port links (cytoscape + dagre layout), coloured by state;
 * a click opens the component. */
'use strict';
(() => {
  const {app, el, get, pageUrl, message} = Arflex;
  const status = el('div', {});
  const box = el('div', {class: 'arflex-graph', id: 'arflex-graph'});
  app.replaceChildren(el('h2', {}, 'Graph'), status, box);
  const colours = {ACTIVE: '#2e7d32', UNSATISFIED: '#ef6c00', INSTALLED: '#1565c0', FAILED: '#c62828', DESTROYED: '#555'};
  if (typeof cytoscapeDagre !== 'undefined' && typeof cytoscape !== 'undefined') {
    try { cytoscape.use(cytoscapeDagre); } catch (e) { /* already registered */ }
  }
  let cy = null;
  let shown = '';

  function draw(cell) {
    const nodes = (cell.instances || []).map(i => ({data: {id: i.name, label: i.name + '\n' + i.state,
      colour: colours[i.state] || '#888'}}));
    const names = new Set(nodes.map(n => n.data.id));
    const edges = (cell.bindings || []).filter(b => names.has(b.provider) && names.has(b.consumer)).map(b => ({
      data: {id: b.provider + '.' + b.output + '->' + b.consumer + '.' + b.input, source: b.provider,
        target: b.consumer, label: b.output + ' → ' + b.input}}));
    const key = JSON.stringify([nodes, edges]);
    if (key === shown) return;
    shown = key;
    box.dataset.nodes = String(nodes.length);
    box.dataset.edges = String(edges.length);
    if (cy) cy.destroy();
    cy = cytoscape({container: box, elements: {nodes, edges}, wheelSensitivity: 0.2,
      style: [
        {selector: 'node', style: {'shape': 'round-rectangle', 'background-color': 'data(colour)', 'label': 'data(label)',
          'color': '#fff', 'text-wrap': 'wrap', 'text-valign': 'center', 'width': 150, 'height': 50, 'font-size': 12}},
        {selector: 'edge', style: {'curve-style': 'bezier', 'target-arrow-shape': 'triangle', 'label': 'data(label)',
          'font-size': 10, 'text-background-color': '#fff', 'text-background-opacity': 1, 'width': 2}}],
      layout: {name: typeof cytoscapeDagre !== 'undefined' ? 'dagre' : 'breadthfirst', rankDir: 'LR', nodeSep: 40, rankSep: 120}});
    box.arflexGraph = cy; // lets a test find where a component is drawn
    cy.on('tap', 'node', ev => { window.location.href = pageUrl('arflex-component', {name: ev.target.id()}); });
  }

  async function refresh() {
    try {
      const data = await get('cell');
      if (!data.drcr) { message(status, 'The DRCR is not running.', 'error'); return; }
      status.replaceChildren(el('p', {}, 'Click a component to open it. Colours: green Active, orange Unsatisfied, blue Installed, red Failed, grey Destroyed.'));
      draw(data.cell);
    } catch (e) {
      message(status, 'Cannot read the cell: ' + e.message, 'error');
    }
  }
  refresh();
  setInterval(refresh, 2000);
})();
