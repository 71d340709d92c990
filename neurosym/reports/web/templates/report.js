// The episode player of a neurosym report. Reads the JSON embedded in #report-data,
// draws the map and each head's attention as SVG, and redraws on every step change.
// Text from the data is only ever set as textContent, never parsed as HTML.
(function () {
  "use strict";
  const SVG = "http://www.w3.org/2000/svg";
  const data = JSON.parse(document.getElementById("report-data").textContent);
  const P = data.player;
  const styles = data.entities;
  const palette = data.head_colours;
  const $ = (id) => document.getElementById(id);
  const api = { redrawMs: [], lastRedrawMs: null, episode: null, t: null };
  window.neurosymReport = api;

  function el(tag, attrs, parent) {
    const node = document.createElementNS(SVG, tag);
    for (const k in attrs) node.setAttribute(k, attrs[k]);
    if (parent) parent.appendChild(node);
    return node;
  }
  // a number of the data, or "not finite" where it was NaN or +-inf (null in the JSON)
  function fx(v, digits) { return typeof v === "number" && Number.isFinite(v) ? v.toFixed(digits) : "not finite"; }
  function headColour(i) { return palette[i % palette.length]; }
  function styleOf(name) {
    return styles[name] || { fill: "#cccccc", text: "black", label: String(name).slice(0, 2) };
  }

  // rows of each table by state t, built once per episode
  function prepare(ep) {
    if (ep.byT) return;
    ep.byT = {};
    for (const name in ep.tables) {
      const idx = Array.from({ length: ep.steps + 1 }, () => []);
      ep.tables[name].t.forEach((t, i) => { if (t >= 0 && t <= ep.steps) idx[t].push(i); });
      ep.byT[name] = idx;
    }
  }

  // one drawn grid: cell rects and labels, updated in place
  function makeMap(parent, cell, labels) {
    const [h, w] = P.shape;
    const svg = el("svg", { width: w * cell, height: h * cell, viewBox: `0 0 ${w * cell} ${h * cell}`,
      role: "img" }, parent);
    const cells = [], texts = [];
    for (let r = 0; r < h; r++) for (let c = 0; c < w; c++) {
      cells.push(el("rect", { x: c * cell, y: r * cell, width: cell, height: cell,
        stroke: "#ffffff", "stroke-width": 1 }, svg));
      texts.push(labels ? el("text", { x: c * cell + cell / 2, y: r * cell + cell / 2 + cell * 0.17,
        "text-anchor": "middle", "font-size": Math.round(cell * 0.5) }, svg) : null);
    }
    const marks = el("g", { class: "marks" }, svg);
    const overlay = el("g", {}, svg);
    return { svg, cell, cells, texts, marks, overlay, shown: new Array(h * w).fill(null) };
  }

  function gridAt(ep, t) {
    const [h, w] = P.shape;
    const terrain = P.terrains[ep.terrain];
    const grid = [];
    for (let r = 0; r < h; r++) for (let c = 0; c < w; c++) grid.push(terrain[r][c]);
    const pos = ep.tables.positions;
    let agent = -1;
    for (const i of ep.byT.positions[t] || []) {
      const k = pos.row[i] * w + pos.col[i];
      if (pos.type[i] === "agent") agent = k; else grid[k] = pos.type[i];
    }
    if (agent >= 0) grid[agent] = "agent";
    return { grid, agent };
  }

  function paint(map, grid) {
    for (let k = 0; k < grid.length; k++) {
      if (map.shown[k] === grid[k]) continue;
      const s = styleOf(grid[k]);
      map.cells[k].setAttribute("fill", s.fill);
      if (map.texts[k]) { map.texts[k].textContent = s.label; map.texts[k].setAttribute("fill", s.text); }
      map.shown[k] = grid[k];
    }
  }

  // Minigrid: each door's state (open: an outline in its colour; locked: a black keyhole;
  // closed: the filled cell as painted) and the agent's direction, from the facing and doors
  // tables (absent for the other envs); redrawn at every step
  const POINTS = { east: [1, 0], south: [0, 1], west: [-1, 0], north: [0, -1] };
  function drawMarks(map, ep, t, agent) {
    const g = map.marks, c = map.cell, w = P.shape[1];
    g.textContent = "";
    const doors = ep.tables.doors, pos = ep.tables.positions;
    if (doors) {
      const cellOf = {};
      for (const i of ep.byT.positions[t] || []) cellOf[pos.object[i]] = i;
      for (const i of ep.byT.doors[t] || []) {
        const p = cellOf[doors.id[i]];
        if (p === undefined || pos.row[p] * w + pos.col[p] === agent) continue;
        const r = pos.row[p], col = pos.col[p], st = doors.state[i], colour = styleOf(pos.type[p]).fill;
        const d = el("g", { class: "door", "data-row": r, "data-col": col, "data-state": st }, g);
        el("title", {}, d).textContent = `${doors.id[i]}: ${st}`;
        if (st === "open") {
          el("rect", { x: col * c + 2, y: r * c + 2, width: c - 4, height: c - 4,
            fill: (styles.empty || styleOf("empty")).fill, stroke: colour, "stroke-width": 3 }, d);
          el("text", { x: col * c + c / 2, y: r * c + c / 2 + c * 0.17, "text-anchor": "middle",
            "font-size": Math.round(c * 0.5), fill: colour }, d).textContent = styleOf(pos.type[p]).label;
        } else if (st === "locked") {
          el("rect", { x: col * c + c * 0.62, y: r * c + c * 0.6, width: c * 0.22, height: c * 0.28,
            fill: "#000000" }, d);
        }
      }
    }
    const facing = ep.tables.facing, is = facing ? ep.byT.facing[t] || [] : [];
    if (agent < 0 || !is.length || !POINTS[facing.direction[is[0]]]) return;
    const dir = facing.direction[is[0]], [dx, dy] = POINTS[dir];
    const cx = (agent % w) * c + c / 2, cy = Math.floor(agent / w) * c + c / 2;
    const tip = [cx + 0.42 * c * dx, cy + 0.42 * c * dy], back = [cx + 0.12 * c * dx, cy + 0.12 * c * dy];
    const side = [-0.2 * c * dy, 0.2 * c * dx];
    const pts = [tip, [back[0] + side[0], back[1] + side[1]], [back[0] - side[0], back[1] - side[1]]];
    const arrow = el("polygon", { class: "facing", "data-direction": dir,
      points: pts.map((q) => q.join(",")).join(" "), fill: styleOf("agent").text }, g);
    el("title", {}, arrow).textContent = `agent facing ${dir}`;
  }

  // a highlighted cell: outline (solid or dashed) and a badge, named by data-row/data-col
  // inset: a second marker on the same cell stays visible inside the first
  function marker(map, cls, colour, dashed, badge, inset) {
    const g = el("g", { class: cls, visibility: "hidden" }, map.overlay);
    const c = map.cell, o = 1.5 + (inset || 0), size = c - 2 * o;
    el("rect", { x: o, y: o, width: size, height: size, fill: "none", stroke: "#ffffff",
      "stroke-width": 5 }, g);
    el("rect", { x: o, y: o, width: size, height: size, fill: "none", stroke: colour,
      "stroke-width": 3, "stroke-dasharray": dashed ? "4 3" : "none" }, g);
    const b = el("text", { x: c - 1, y: inset ? c - 2 : 9, "text-anchor": "end", "font-size": 10,
      "font-weight": 700, fill: colour, stroke: "#ffffff", "stroke-width": 3,
      "paint-order": "stroke" }, g);
    b.textContent = badge;
    return g;
  }
  function place(g, row, col, cell, title) {
    if (row === null) { g.setAttribute("visibility", "hidden"); g.removeAttribute("data-row");
      g.removeAttribute("data-col"); return; }
    g.setAttribute("transform", `translate(${col * cell},${row * cell})`);
    g.setAttribute("data-row", row); g.setAttribute("data-col", col);
    g.setAttribute("visibility", "visible");
    let tip = g.querySelector("title");
    if (!tip) tip = el("title", {}, g);
    tip.textContent = title;
  }

  let panels = [];
  let mainMap = null;

  function buildPanels() {
    const [h, w] = P.shape;
    const main = $("map"); main.textContent = "";
    mainMap = makeMap(main, Math.max(18, Math.min(36, Math.floor(380 / Math.max(h, w)))), true);
    const box = $("panels"); box.textContent = "";
    const cell = Math.max(10, Math.min(24, Math.floor(256 / Math.max(h, w))));
    panels = P.heads.map((head, i) => {
      const fig = document.createElement("figure");
      fig.className = "panel"; fig.dataset.head = head;
      box.appendChild(fig);
      const map = makeMap(fig, cell, cell >= 16);
      const colour = headColour(i);
      const cap = document.createElement("figcaption");
      fig.appendChild(cap);
      const panel = { head, map, colour, cap, heat: null };
      if (P.module === "mhdpa") {
        panel.heat = map.cells.map((_, k) => el("rect", { x: (k % w) * cell, y: Math.floor(k / w) * cell,
          width: cell, height: cell, fill: colour, "fill-opacity": 0, class: "heat" }, map.overlay));
        panel.focus = marker(map, "att focus", "#000000", false, "A");
      } else {
        panel.a1 = marker(map, "att a1", colour, false, "1");
        panel.a2 = marker(map, "att a2", colour, true, "2", 4);
      }
      return panel;
    });
  }

  function drawPrediNet(panel, ep, t) {
    const at = ep.tables.attends, rows = ep.byT.attends[t] || [];
    const found = { 1: null, 2: null };
    for (const i of rows) if (at.head[i] === panel.head) found[at.arg[i]] = i;
    const c = panel.map.cell;
    const text = [];
    for (const arg of [1, 2]) {
      const i = found[arg], g = arg === 1 ? panel.a1 : panel.a2;
      if (i === null) { place(g, null); continue; }
      const tip = `head ${panel.head} a${arg}: ${at.entity[i]} (${at.row[i]}, ${at.col[i]}), weight ${fx(at.weight[i], 3)}`;
      place(g, at.row[i], at.col[i], c, tip);
      text.push(`a${arg} ${at.entity[i]} (${at.row[i]},${at.col[i]}) ${fx(at.weight[i], 2)}`);
    }
    panel.cap.textContent = `head ${panel.head}: ` + (text.length ? text.join(" · ") : "no step (final state)");
  }

  function drawMHDPA(panel, ep, t, agent) {
    const at = ep.tables.attention, rows = ep.byT.attention[t] || [];
    const w = P.shape[1];
    const sum = new Float64Array(panel.heat.length);
    let best = null;
    for (const i of rows) {
      if (at.head[i] !== panel.head) continue;
      sum[at.key_row[i] * w + at.key_col[i]] += at.weight[i];
      const q = at.query_row[i] * w + at.query_col[i];
      if (q === agent && (best === null || at.weight[i] > at.weight[best])) best = i;
    }
    let top = 0;
    for (const v of sum) top = Math.max(top, v);
    panel.heat.forEach((r, k) => r.setAttribute("fill-opacity", top > 0 ? (0.75 * sum[k] / top).toFixed(3) : 0));
    if (best === null) { place(panel.focus, null); } else {
      place(panel.focus, at.key_row[best], at.key_col[best], panel.map.cell,
        `head ${panel.head}: the agent's strongest key ${at.key[best]}, weight ${fx(at.weight[best], 3)}`);
    }
    panel.cap.textContent = `head ${panel.head}: ` + (rows.length === 0 ? "no step (final state)" :
      best === null ? "keys shaded by weight" : `agent -> ${at.key[best]} (${at.key_row[best]},${at.key_col[best]}) ${fx(at.weight[best], 2)}`);
  }

  let dscale = null;
  function relationScale() {
    dscale = {};
    for (const ep of P.episodes) {
      const rel = ep.tables.relations;
      rel.j.forEach((j, i) => { dscale[j] = Math.max(dscale[j] || 0, Math.abs(rel.value[i])); });
    }
  }
  function diverging(v, scale) {
    const x = scale > 0 ? Math.max(-1, Math.min(1, v / scale)) : 0;
    const end = x < 0 ? [0, 114, 178] : [213, 94, 0];
    const a = Math.abs(x);
    const mix = end.map((e) => Math.round(255 + (e - 255) * a));
    return { bg: `rgb(${mix.join(",")})`, fg: a > 0.6 ? "#ffffff" : "#1a1a1a" };
  }

  function drawRelations(ep, t) {
    const box = $("dvalues");
    if (P.module !== "predinet") { box.hidden = true; return; }
    const rel = ep.tables.relations, rows = ep.byT.relations[t] || [];
    const table = $("dtable");
    const J = P.relations;
    for (let h = 0; h < P.heads.length; h++) {
      const tr = table.tBodies[0].rows[h];
      tr.cells[1].textContent = "";
      for (let j = 0; j < J; j++) { const td = tr.cells[j + 2]; td.textContent = ""; td.style.background = "";
        td.className = ""; td.title = ""; }
    }
    for (const i of rows) {
      const h = P.heads.indexOf(rel.head[i]);
      if (h < 0 || rel.j[i] >= J) continue;
      const tr = table.tBodies[0].rows[h];
      tr.cells[1].textContent = `${rel.a[i]} - ${rel.b[i]}`;
      const td = tr.cells[rel.j[i] + 2], v = rel.value[i];
      const col = diverging(v, dscale[rel.j[i]]);
      td.textContent = fx(v, 2);
      td.style.background = col.bg; td.style.color = col.fg;
      const thr = data.thresholds[String(rel.j[i])];
      const held = typeof thr === "number" && Math.abs(v) > thr;
      td.className = held ? "held" : "";
      td.title = `D_${rel.j[i]}(${rel.a[i]}, ${rel.b[i]}) = ${v}` + (held ? ` (above threshold ${thr.toPrecision(4)}: a holds/5 fact)` : "");
    }
  }

  function drawStatus(ep, t) {
    $("stepno").textContent = `state ${t} of ${ep.steps}`;
    $("s-action").textContent = t < ep.steps ? ep.actions[t] : "none (final state)";
    $("s-reward").textContent = t < ep.steps ? (ep.rewards[t] === null ? "not finite" : String(ep.rewards[t])) : "-";
    let ret = 0;
    for (let k = 0; k < Math.min(t, ep.steps); k++) ret += ep.rewards[k] === null ? NaN : ep.rewards[k];
    $("s-return").textContent = `${fx(ret, 2)} so far (episode: ${fx(ep.return, 2)}, ${ep.outcome})`;
    const hold = ep.tables.holding, hs = ep.byT.holding[t] || [];
    $("s-holding").textContent = hs.length ? hs.map((i) => hold.item[i]).join(", ") : "nothing";
    const ev = ep.tables.events, es = ep.byT.events[t] || [];
    const ul = $("s-events"); ul.textContent = "";
    for (const i of es) { const li = document.createElement("li"); li.textContent = ev.event[i]; ul.appendChild(li); }
    if (!es.length) { const li = document.createElement("li"); li.className = "none"; li.textContent = "none"; ul.appendChild(li); }
  }

  function redraw() {
    const start = performance.now();
    const ep = P.episodes[state.ep];
    const t = state.t;
    const { grid, agent } = gridAt(ep, t);
    paint(mainMap, grid);
    drawMarks(mainMap, ep, t, agent);
    for (const panel of panels) {
      paint(panel.map, grid);
      drawMarks(panel.map, ep, t, agent);
      if (P.module === "mhdpa") drawMHDPA(panel, ep, t, agent); else drawPrediNet(panel, ep, t);
    }
    drawRelations(ep, t);
    drawStatus(ep, t);
    slider.value = t;
    api.episode = ep.episode; api.t = t;
    api.lastRedrawMs = performance.now() - start;
    api.redrawMs.push(api.lastRedrawMs);
  }

  const state = { ep: 0, t: 0, timer: null };
  const slider = $("step");
  const select = $("episode");

  function setEpisode(index) {
    state.ep = Math.max(0, Math.min(P.episodes.length - 1, index));
    const ep = P.episodes[state.ep];
    prepare(ep);
    slider.max = ep.steps;
    select.value = String(state.ep);
    state.t = Math.min(state.t, ep.steps);
  }
  function setStep(t) {
    const ep = P.episodes[state.ep];
    state.t = Math.max(0, Math.min(ep.steps, t));
    redraw();
  }
  function stop() { if (state.timer) { clearInterval(state.timer); state.timer = null; } $("play").textContent = "Play"; }
  function play() {
    if (state.timer) { stop(); return; }
    if (state.t >= P.episodes[state.ep].steps) setStep(0);
    $("play").textContent = "Pause";
    state.timer = setInterval(() => {
      if (state.t >= P.episodes[state.ep].steps) { stop(); return; }
      setStep(state.t + 1);
    }, 350);
  }
  function goTo(episode, t) {
    const index = P.episodes.findIndex((e) => e.episode === episode);
    if (index < 0) return;
    stop(); setEpisode(index); setStep(t);
  }
  function fromHash() {
    const m = /^#e=(-?\d+)&t=(\d+)$/.exec(location.hash);
    if (!m) return false;
    goTo(Number(m[1]), Number(m[2]));
    $("player").scrollIntoView();
    return true;
  }

  function start() {
    if (!P.episodes.length) { $("player-body").hidden = true; return; }
    P.episodes.forEach((ep, i) => {
      const o = document.createElement("option");
      o.value = String(i);
      o.textContent = `episode ${ep.episode}: ${ep.outcome}, return ${fx(ep.return, 2)}, ${ep.steps} steps`;
      select.appendChild(o);
    });
    relationScale();
    buildPanels();
    const legend = $("head-legend"); legend.textContent = "";
    P.heads.forEach((head, i) => {
      const s = document.createElement("span");
      const sw = document.createElement("span"); sw.className = "swatch"; sw.style.background = headColour(i);
      s.appendChild(sw); s.appendChild(document.createTextNode(`head ${head}   `));
      legend.appendChild(s);
    });
    slider.addEventListener("input", () => { stop(); setStep(Number(slider.value)); });
    select.addEventListener("change", () => { stop(); setEpisode(Number(select.value)); setStep(0); });
    $("play").addEventListener("click", play);
    $("prev").addEventListener("click", () => { stop(); setStep(state.t - 1); });
    $("next").addEventListener("click", () => { stop(); setStep(state.t + 1); });
    window.addEventListener("hashchange", fromHash);
    api.setEpisode = (e) => goTo(e, 0);
    api.setStep = (t) => setStep(t);
    if (!fromHash()) { setEpisode(0); setStep(0); }
  }
  start();
})();
