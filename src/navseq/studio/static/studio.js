// navseq studio page: plain JS over Leaflet (CRS.Simple: lat = y, lng = x, in metres).
// The mission is the navseq document the API returns (docs/studio.md); every rule about
// it (validation, pre-flight, plans, writing) is the server's: this file only draws and
// sends edits.
"use strict";

const S = {
  doc: null, version: null, name: "", units: {},
  problems: [], legs: [], route: {}, selected: null,
  undo: [], redo: [], checkSeq: 0, checkBusy: false, checkAgain: false, checkId: null,
  layers: { markers: [], legs: null, handle: null, start: null, run: null, map: null, cost: null },
  planned: false, painted: null, mapKey: null, events: null, run: null, placingStart: false, replay: null, replayTimer: null,
};
const WP_FIELDS = [
  ["name", "text"], ["x", "number"], ["y", "number"], ["yaw", "number"],
  ["pass_through", "number"], ["dwell", "number"], ["retries", "number"],
  ["on_failure", ["", "stop", "skip", "retry"]], ["goal_timeout", "number"], ["stall_timeout", "number"],
];
// Mission-wide defaults (docs/mission-format.md); empty = the loader's default.
const DEFAULT_FIELDS = [
  ["goal_timeout", "number"], ["stall_timeout", "number"], ["retries", "number"],
  ["clear_costmaps_on_retry", ["", "true", "false"]], ["recovery", "text"], ["on_failure", ["", "stop", "skip", "retry"]],
  ["pass_through", "number"], ["dwell", "number"], ["xy_tolerance", "number"], ["yaw_tolerance", "number"],
];
const $ = (id) => document.getElementById(id);
// The point the selection and the yaw handle are about: a waypoint, or the start pose.
const selectedPoint = () => (S.selected === "start" ? S.doc.start : S.selected !== null ? S.doc.waypoints[S.selected] : null);

// ---- API -------------------------------------------------------------------------------
async function api(method, path, body, signal) {
  const response = await fetch(path, {
    method, headers: body ? { "content-type": "application/json" } : {},
    body: typeof body === "string" ? body : body ? JSON.stringify(body) : undefined, credentials: "same-origin", signal,
  });
  let data = null;
  try { data = await response.json(); } catch (e) { data = { error: response.statusText }; }
  return { ok: response.ok, status: response.status, data };
}
function say(text, error) { const m = $("message"); m.textContent = text; m.className = error ? "error" : ""; }

// ---- map -------------------------------------------------------------------------------
const map = L.map("map", { crs: L.CRS.Simple, minZoom: -6, maxZoom: 9, zoomSnap: 0.25, zoomDelta: 0.5,
  attributionControl: false, doubleClickZoom: false, boxZoom: false });
L.control.scale({ metric: true, imperial: false, maxWidth: 160 }).addTo(map);
const cursorControl = L.control({ position: "bottomright" });
cursorControl.onAdd = () => { const d = L.DomUtil.create("div", "cursor-xy"); d.textContent = "x —, y —"; return d; };
cursorControl.addTo(map);
map.on("mousemove", (e) => {
  cursorControl.getContainer().textContent = `x ${e.latlng.lng.toFixed(2)} m, y ${e.latlng.lat.toFixed(2)} m`;
});
const costControl = L.control({ position: "topright" });
costControl.onAdd = () => {
  const d = L.DomUtil.create("label", "costmap-toggle");
  d.innerHTML = '<input type="checkbox" id="costmap-toggle"> inflated costmap';
  L.DomEvent.disableClickPropagation(d);
  return d;
};
costControl.addTo(map);
$("costmap-toggle").addEventListener("change", (e) => {
  if (!S.layers.cost) return;
  if (e.target.checked) S.layers.cost.addTo(map); else S.layers.cost.remove();
});
const ll = (x, y) => L.latLng(y, x);

async function loadMap(fit) {
  const key = S.doc.map || "";
  if (key === S.mapKey) return;
  S.mapKey = key;
  if (S.layers.map) S.layers.map.remove();
  if (S.layers.cost) S.layers.cost.remove();
  S.layers.map = S.layers.cost = null;
  const query = key ? `?map=${encodeURIComponent(key)}` : "";
  const info = await api("GET", `/api/map${query}`);
  if (!info.ok) { say(info.data.error, true); if (!map._loaded) map.setView([0, 0], 4); return; }
  const b = info.data.bounds_m;
  const bounds = L.latLngBounds(ll(b.xmin, b.ymin), ll(b.xmax, b.ymax));
  const sep = query ? "&" : "?";
  // Layers are added once the map has a view (Leaflet defers them until then).
  if (fit || !map._loaded) map.fitBounds(focusBounds(bounds), { padding: [20, 20] });
  // One PNG for the whole map (not a shape per cell): a 2000 x 2000 map pans and zooms
  // as smoothly as a small one. The promise settles when the image is drawn.
  const drawn = new Promise((resolve) => {
    S.layers.map = L.imageOverlay(`/api/map/image${query}${sep}layer=map`, bounds);
    S.layers.map.once("load error", resolve);
    S.layers.map.addTo(map);
  });
  S.layers.map.getElement().dataset.testid = "map-image";
  S.layers.cost = L.imageOverlay(`/api/map/image${query}${sep}layer=costmap`, bounds, { zIndex: 2 });
  if ($("costmap-toggle").checked) S.layers.cost.addTo(map);
  await drawn;
}
// Fit on the mission when it has waypoints (a small mission on a big map stays readable).
function focusBounds(mapBounds) {
  const pts = S.doc.waypoints.filter(okPoint).map((w) => ll(w.x, w.y));
  if (S.doc.start && okPoint(S.doc.start)) pts.push(ll(S.doc.start.x, S.doc.start.y));
  if (pts.length < 2) return mapBounds;
  return L.latLngBounds(pts).pad(0.25);
}
const okPoint = (p) => p && typeof p.x === "number" && typeof p.y === "number";
// The view on the whole mission (after an import: its waypoints may be anywhere).
function fitMission() {
  const pts = S.doc.waypoints.filter(okPoint).map((w) => ll(w.x, w.y));
  if (okPoint(S.doc.start)) pts.push(ll(S.doc.start.x, S.doc.start.y));
  if (pts.length > 1) map.fitBounds(L.latLngBounds(pts).pad(0.1), { padding: [20, 20] });
  else if (pts.length === 1) map.panTo(pts[0]);
}

// ---- editing ---------------------------------------------------------------------------
function snapshot() { return JSON.stringify({ doc: S.doc, selected: S.selected }); }
function edit(change) {
  S.undo.push(snapshot());
  if (S.undo.length > 200) S.undo.shift();
  S.redo = [];
  change();
  changed();
}
function restore(from, to) {
  if (!from.length) return;
  to.push(snapshot());
  const state = JSON.parse(from.pop());
  S.doc = state.doc; S.selected = state.selected;
  changed();
}
// The check goes out first: the server works on it while the page redraws.
function changed() { check(); render(); }
// Edits not saved yet: closing or reloading the tab asks first (the browser's own dialog).
const unsaved = () => S.saved !== undefined && JSON.stringify(S.doc) !== S.saved;
window.addEventListener("beforeunload", (e) => {
  if (!unsaved()) return;
  e.preventDefault();
  e.returnValue = "";
});
const round = (v, d) => Math.round(v * 10 ** d) / 10 ** d;

map.on("click", (e) => {
  if ((S.run && !S.run.done) || S.replay) return;
  if (S.placingStart) {
    placeStart(false);
    edit(() => {
      S.doc.start = { x: round(e.latlng.lng, 2), y: round(e.latlng.lat, 2), yaw: okPoint(S.doc.start) ? S.doc.start.yaw ?? 0 : 0 };
      S.selected = "start";
    });
    return;
  }
  edit(() => {
    S.doc.waypoints.push({ x: round(e.latlng.lng, 2), y: round(e.latlng.lat, 2), yaw: 0 });
    S.selected = S.doc.waypoints.length - 1;
  });
});
// Keys of the page (docs/studio.md, Keyboard). In a field (input, select) the field keeps
// its own keys: Ctrl+Z there is the browser's undo of the typed text, and the arrows step
// a number or a choice; the mission's undo is one Tab away (↶ ↷) or after Esc. With a
// waypoint selected the arrows move it, wherever the focus is (a click on the map that
// adds one focuses the map); with none, the focused map pans (Leaflet's keys); Esc
// deselects. Listened to in the capture phase, so that Leaflet's keyboard handler (on
// the document while the map has the focus) does not pan the map with the same arrows.
const ARROWS = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
const STEP_M = 0.05, BIG_STEP_M = 0.5;
document.addEventListener("keydown", (e) => {
  if (e.target.closest("input, select, textarea, dialog")) {
    if (e.key === "Escape" && e.target.closest("#fields, #settings, #defaults")) e.target.blur();
    return;
  }
  const z = e.key.toLowerCase() === "z" && (e.ctrlKey || e.metaKey);
  const busy = (S.run && !S.run.done) || S.replay;
  if (z && !e.shiftKey) { e.preventDefault(); restore(S.undo, S.redo); }
  else if ((z && e.shiftKey) || (e.key.toLowerCase() === "y" && e.ctrlKey)) { e.preventDefault(); restore(S.redo, S.undo); }
  else if ((e.key === "Delete" || e.key === "Backspace") && S.selected !== null && !busy) {
    e.preventDefault();
    if (S.selected === "start") edit(() => { delete S.doc.start; S.selected = null; });
    else removeWaypoint(S.selected);
  }
  else if (e.key in ARROWS && !e.ctrlKey && !e.altKey && !e.metaKey && !busy) {
    const p = selectedPoint();
    if (!p || !okPoint(p)) return;
    e.preventDefault();
    e.stopPropagation();
    const [dx, dy] = ARROWS[e.key], step = e.shiftKey ? BIG_STEP_M : STEP_M;
    // One edit per key press: each Ctrl+Z takes one step back.
    edit(() => { p.x = round(p.x + dx * step, 2); p.y = round(p.y + dy * step, 2); });
    say(`${S.selected === "start" ? "start pose" : `waypoint ${S.selected + 1}`} at (${p.x.toFixed(2)}, ${p.y.toFixed(2)})`);
  }
  else if (e.key === "Escape") {
    if (S.placingStart) placeStart(false);
    else if (S.selected !== null) { S.selected = null; render(); }
  }
}, true);
$("undo").onclick = () => restore(S.undo, S.redo);
$("redo").onclick = () => restore(S.redo, S.undo);
function removeWaypoint(i) {
  // From a row, the focus goes to the row that takes the removed one's place, else the one
  // before; from the map, it stays on the map.
  const n = S.doc.waypoints.length - 1;
  const onRow = (document.activeElement?.dataset?.focus || "").startsWith("row-");
  S.focusNext = onRow && n > 0 ? `row-${Math.min(i, n - 1)}` : null;
  edit(() => { S.doc.waypoints.splice(i, 1); S.selected = null; });
}
function moveWaypoint(from, to) {
  if (to < 0 || to >= S.doc.waypoints.length || from === to) return;
  // The focus follows the moved waypoint (its ▲ or ▼ again: press on to move it on).
  const part = (document.activeElement?.dataset?.focus || "").split("-")[2];
  S.focusNext = part ? `row-${to}-${part}` : `row-${to}`;
  edit(() => {
    const [w] = S.doc.waypoints.splice(from, 1);
    S.doc.waypoints.splice(to, 0, w);
    S.selected = to;
  });
}

// ---- drawing ---------------------------------------------------------------------------
// The waypoints, the start pose and the legs are painted on one canvas (missionLayer), not
// an element each: a mission of 5000 waypoints draws in milliseconds where 5000 markers
// took seconds to build. What the mouse is on is found from the positions painted
// (hitTest); the keyboard's way is the list's rows and the focused map (the arrows move
// the selected waypoint). Leg lengths are elements (.leg-label), put only where they fit
// without covering a marker or another label.
function problemsOf(i) { return S.problems.filter((p) => p.waypoint === i); }
const MARK_R = 10;  // px: a waypoint's disc
const DOT_R = 4;    // px: a waypoint as a dot, when too many are on the screen for numbers
const START_R = MARK_R + 5;  // px: the start pose's ring, around a waypoint at the same spot
const LABEL_H = 14, LABEL_GAP = 2, MAX_LABELS = 400;
const MARK_FONT = "bold 11px system-ui, sans-serif", LABEL_FONT = "10px system-ui, sans-serif";
// Fill colours (white numbers on them: 4.5:1 at least), as the list and the CSS.
const COLOUR = {
  waypoint: "#2563eb", pass: "#7c3aed", bad: "#dc2626", start: "#111827", selected: "#facc15",
  leg: "#0ea5e9", loop: "#6b7280", noPath: "#dc2626",
  pending: "#6b7280", driving: "#c2410c", dwelling: "#c2410c", reached: "#15803d",
  skipped: "#dc2626", failed: "#dc2626", stopped: "#92400e",
};
map.createPane("mission").style.zIndex = 450;  // over the map image (400), under the yaw handle (600)
// The robot over the waypoints (seen where it stands on one); its trail and plan stay
// under them (the numbers stay readable).
map.createPane("run").style.zIndex = 460;
const MissionLayer = L.Layer.extend({
  onAdd(m) {
    const pane = m.getPane("mission");
    this.canvas = L.DomUtil.create("canvas", "mission-canvas leaflet-zoom-animated", pane);
    this.canvas.dataset.testid = "mission-canvas";
    this.canvas.setAttribute("aria-hidden", "true");  // the list says what it shows
    this.labels = L.DomUtil.create("div", "leg-labels leaflet-zoom-animated", pane);
    L.DomEvent.disableClickPropagation(this.labels);
    this.px = new Float64Array(0); this.py = new Float64Array(0);
    this.replayed = [];
    m.on("move resize viewreset zoomend", this.schedule, this);
    m.on("zoomanim", this.animateZoom, this);
  },
  // Redrawn once per frame however many moves came in it (panning, a drag).
  schedule() {
    if (!this.frame) this.frame = requestAnimationFrame(() => { this.frame = 0; this.draw(); });
  },
  // Leaflet's zoom animation scales the map pane's layers by CSS; the canvas follows it
  // (as Leaflet's own overlays do) and is painted again at the new zoom.
  animateZoom(e) {
    const offset = map._latLngBoundsToNewLayerBounds(map.getBounds(), e.zoom, e.center).min;
    const scale = map.getZoomScale(e.zoom);
    L.DomUtil.setTransform(this.canvas, offset, scale);
    L.DomUtil.setTransform(this.labels, offset, scale);
  },
  // Screen (container) point of a world point, without Leaflet's objects: CRS.Simple
  // is x * 2^zoom, -y * 2^zoom from the origin's point.
  frameOf() {
    const o = map.latLngToContainerPoint([0, 0]), s = map.getZoomScale(map.getZoom(), 0);
    return { ox: o.x, oy: o.y, s };
  },
  draw() {
    if (!this._map || !S.doc) return;
    if (this.frame) { cancelAnimationFrame(this.frame); this.frame = 0; }
    const size = map.getSize(), dpr = window.devicePixelRatio || 1;
    const c = this.canvas;
    const corner = map.containerPointToLayerPoint([0, 0]);
    L.DomUtil.setPosition(c, corner);
    L.DomUtil.setPosition(this.labels, corner);
    if (c.width !== Math.round(size.x * dpr) || c.height !== Math.round(size.y * dpr)) {
      c.width = Math.round(size.x * dpr); c.height = Math.round(size.y * dpr);
      c.style.width = `${size.x}px`; c.style.height = `${size.y}px`;
    }
    const ctx = c.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, size.x, size.y);
    const f = this.frame0 = this.frameOf();
    this.size = size;
    this.project(f);
    this.replayed = [];
    this.drawLegs(ctx, f);
    this.drawMarks(ctx, size);
    if (S.replay) this.drawReplayed(ctx, f);
    this.drawStart(ctx, f);
    this.placeLabels(ctx, f, size);
    c.dataset.drawn = String(this.shown);  // waypoints on the canvas, in the view or not
  },
  // Screen points of every waypoint (the one being dragged where the mouse is).
  project(f) {
    const wps = S.doc.waypoints, n = wps.length;
    if (this.px.length !== n) { this.px = new Float64Array(n); this.py = new Float64Array(n); }
    let shown = 0, inView = 0;
    for (let i = 0; i < n; i++) {
      const w = wps[i];
      if (!okPoint(w)) { this.px[i] = NaN; this.py[i] = NaN; continue; }
      const dragged = S.drag && S.drag.target === i;
      const x = f.ox + (dragged ? S.drag.x : w.x) * f.s, y = f.oy - (dragged ? S.drag.y : w.y) * f.s;
      this.px[i] = x; this.py[i] = y;
      shown++;
      if (x > -MARK_R && y > -MARK_R && x < this.size.x + MARK_R && y < this.size.y + MARK_R) inView++;
    }
    this.shown = shown;
    // Numbered plates while they cover under a third of the view; dots beyond (zoom in
    // to read the numbers): thousands of overlapping discs say nothing.
    this.compact = inView * (2 * MARK_R) ** 2 > (this.size.x * this.size.y) / 3;
  },
  // Where a leg's ends are now: the start pose or a waypoint (the dragged one: the mouse).
  endOf(name) {
    if (name === "start") {
      const st = S.doc.start;
      if (!okPoint(st)) return null;
      return S.drag && S.drag.target === "start" ? [S.drag.x, S.drag.y] : [st.x, st.y];
    }
    const w = S.doc.waypoints[name];
    if (!okPoint(w)) return null;
    return S.drag && S.drag.target === name ? [S.drag.x, S.drag.y] : [w.x, w.y];
  },
  // One path per kind of leg (planned, way back of a patrol, no path), each stroked once.
  // A leg touching the waypoint being dragged is a thin straight line until the check
  // plans it again; a leg with no path is dashed straight, in the problem colour.
  drawLegs(ctx, f) {
    const kinds = { leg: [], loop: [], noPath: [], moving: [] };
    const dragged = S.drag ? S.drag.target : undefined;
    const seen = this.viewBox(f, 8);
    for (const leg of S.legs) {
      let pts = leg.points, kind = leg.loop ? "loop" : "leg";
      if (dragged !== undefined && (leg.from === dragged || leg.to === dragged || (dragged === "start" && leg.from === "start"))) {
        pts = null; kind = "moving";
      } else if (!pts) kind = "noPath";
      else if (!overlaps(legBox(leg), seen)) continue;  // nothing of it in the view
      if (!pts) {
        const a = this.endOf(leg.from === "start" ? "start" : Number(leg.from)), b = this.endOf(leg.to);
        if (!a || !b) continue;
        pts = [a, b];
      }
      kinds[kind].push(pts);
    }
    const styles = {
      leg: [COLOUR.leg, 3, []], loop: [COLOUR.loop, 3, [6, 6]], noPath: [COLOUR.noPath, 3, [8, 6]], moving: ["#475569", 1.5, [3, 4]],
    };
    ctx.lineJoin = "round"; ctx.lineCap = "round";
    for (const [kind, paths] of Object.entries(kinds)) {
      if (!paths.length) continue;
      const [colour, width, dash] = styles[kind];
      ctx.beginPath();
      for (const pts of paths) {
        // A point under a pixel from the last one drawn is left out (never a leg's end):
        // zoomed out on 5000 legs of a 5 cm grid's cells, most of some 140 000 points
        // fell on the pixel before, and the canvas's raster of them took most of a redraw.
        let px = f.ox + pts[0][0] * f.s, py = f.oy - pts[0][1] * f.s;
        ctx.moveTo(px, py);
        const last = pts.length - 1;
        for (let k = 1; k <= last; k++) {
          const x = f.ox + pts[k][0] * f.s, y = f.oy - pts[k][1] * f.s;
          if (k < last && Math.abs(x - px) < 1 && Math.abs(y - py) < 1) continue;
          ctx.lineTo(x, y); px = x; py = y;
        }
      }
      ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(dash);
      ctx.globalAlpha = kind === "leg" || kind === "loop" ? 0.85 : 1;
      ctx.stroke();
    }
    ctx.setLineDash([]); ctx.globalAlpha = 1;
  },
  // The view in metres [xmin, ymin, xmax, ymax], ``margin`` pixels wider each way.
  viewBox(f, margin) {
    const size = this.size || map.getSize();
    return [(-margin - f.ox) / f.s, (f.oy - size.y - margin) / f.s, (size.x + margin - f.ox) / f.s, (f.oy + margin) / f.s];
  },
  // The colour a waypoint is filled with: its state in the run shown, else its kind.
  fillOf(i, w, bad) {
    const state = S.run && !S.replay && S.run.waypoints ? S.run.waypoints[i] : null;
    if (state && state !== "pending" && COLOUR[state]) return COLOUR[state];
    if (bad.has(i)) return COLOUR.bad;
    return w.pass_through ? COLOUR.pass : COLOUR.waypoint;
  },
  // Half the width of a waypoint's number plate: a disc, or wider for 3 and 4 digits.
  halfWidth(ctx, i) {
    const digits = String(i + 1).length;
    this.widths = this.widths || {};
    if (this.widths[digits] === undefined) {
      ctx.font = MARK_FONT;
      this.widths[digits] = Math.max(MARK_R, ctx.measureText("0".repeat(digits)).width / 2 + 5);
    }
    return this.widths[digits];
  },
  drawMarks(ctx, size) {
    const wps = S.doc.waypoints, n = wps.length;
    const bad = new Set(S.problems.map((p) => p.waypoint));
    ctx.globalAlpha = S.replay ? 0.25 : 1;  // the replayed run's own waypoints go on top
    const inView = (i, r) => this.px[i] > -r - 20 && this.py[i] > -r - 20 && this.px[i] < size.x + r + 20 && this.py[i] < size.y + r + 20;
    if (this.compact) {  // one path per colour: thousands of dots in one fill each
      const paths = new Map();
      for (let i = 0; i < n; i++) {
        if (Number.isNaN(this.px[i]) || !inView(i, DOT_R) || i === S.selected) continue;
        const colour = this.fillOf(i, wps[i], bad);
        let path = paths.get(colour);
        if (!path) { path = new Path2D(); paths.set(colour, path); }
        path.moveTo(this.px[i] + DOT_R, this.py[i]);
        path.arc(this.px[i], this.py[i], DOT_R, 0, 2 * Math.PI);
      }
      for (const [colour, path] of paths) { ctx.fillStyle = colour; ctx.fill(path); }
    } else {
      for (let i = 0; i < n; i++) {
        if (Number.isNaN(this.px[i]) || !inView(i, 2 * MARK_R) || i === S.selected) continue;
        this.drawMark(ctx, i, wps[i], this.fillOf(i, wps[i], bad), false);
      }
    }
    // The selected one on top, full size at any zoom.
    if (typeof S.selected === "number" && !Number.isNaN(this.px[S.selected] ?? NaN)) {
      this.drawMark(ctx, S.selected, wps[S.selected], this.fillOf(S.selected, wps[S.selected], bad), true);
    }
    ctx.globalAlpha = 1;
  },
  // A waypoint: its heading arrow, its numbered plate, a ring when selected.
  drawMark(ctx, i, w, fill, selected, at) {
    const x = at ? at[0] : this.px[i], y = at ? at[1] : this.py[i];
    const yawDeg = S.dragYaw && S.dragYaw.target === i ? S.dragYaw.deg : w.yaw || 0;
    const yaw = (yawDeg * Math.PI) / 180, c = Math.cos(yaw), s = -Math.sin(yaw);
    const tip = MARK_R + 9;
    ctx.strokeStyle = fill; ctx.fillStyle = fill; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x + c * tip, y + s * tip); ctx.stroke();
    ctx.beginPath();
    ctx.moveTo(x + c * (tip + 3), y + s * (tip + 3));
    ctx.lineTo(x + c * (tip - 4) - s * 4, y + s * (tip - 4) + c * 4);
    ctx.lineTo(x + c * (tip - 4) + s * 4, y + s * (tip - 4) - c * 4);
    ctx.fill();
    const half = this.halfWidth(ctx, i);
    ctx.beginPath();
    if (half > MARK_R) ctx.roundRect(x - half, y - MARK_R, 2 * half, 2 * MARK_R, MARK_R);
    else ctx.arc(x, y, MARK_R, 0, 2 * Math.PI);
    ctx.fill();
    ctx.lineWidth = 2; ctx.strokeStyle = selected ? COLOUR.selected : "white"; ctx.stroke();
    if (selected) {
      ctx.beginPath();
      if (half > MARK_R) ctx.roundRect(x - half - 3, y - MARK_R - 3, 2 * half + 6, 2 * MARK_R + 6, MARK_R + 3);
      else ctx.arc(x, y, MARK_R + 3, 0, 2 * Math.PI);
      ctx.strokeStyle = "#111827"; ctx.lineWidth = 1.5; ctx.stroke();
    }
    if (!at && hasTasks(i)) {
      // Tasks run here: a small dark square on the plate's corner (the legend's "has tasks").
      ctx.fillStyle = "#111827"; ctx.strokeStyle = "white"; ctx.lineWidth = 1;
      ctx.fillRect(x + half - 4, y - MARK_R - 3, 7, 7); ctx.strokeRect(x + half - 4, y - MARK_R - 3, 7, 7);
    }
    ctx.fillStyle = "white"; ctx.font = MARK_FONT; ctx.textAlign = "center"; ctx.textBaseline = "middle";
    ctx.fillText(String(i + 1), x, y + 0.5);
  },
  // The replayed run's waypoints (its own mission's), in their states at the slider's time.
  drawReplayed(ctx, f) {
    const R = S.replay, wps = (R.mission || {}).waypoints || [], statuses = R.cursor ? R.cursor.statuses : [];
    this.replayed = [];
    wps.forEach((w, i) => {
      if (!okPoint(w)) return;
      const at = [f.ox + w.x * f.s, f.oy - w.y * f.s], status = statuses[i] || "pending";
      this.replayed.push({ index: i, x: at[0], y: at[1], status });
      this.drawMark(ctx, i, w, COLOUR[status] || COLOUR.pending, false, at);
    });
  },
  // The start pose: a dark ring with an S tab, drawn last: a waypoint at the same spot
  // shows inside it instead of hiding it.
  drawStart(ctx, f) {
    this.start = null;
    const at = this.endOf("start");
    if (!at) return;
    const x = f.ox + at[0] * f.s, y = f.oy - at[1] * f.s;
    this.start = [x, y];
    const yawDeg = S.dragYaw && S.dragYaw.target === "start" ? S.dragYaw.deg : S.doc.start.yaw || 0;
    const yaw = (yawDeg * Math.PI) / 180, c = Math.cos(yaw), s = -Math.sin(yaw);
    ctx.lineCap = "round";
    ctx.beginPath(); ctx.moveTo(x + c * START_R, y + s * START_R); ctx.lineTo(x + c * (START_R + 10), y + s * (START_R + 10));
    ctx.strokeStyle = COLOUR.start; ctx.lineWidth = 3; ctx.stroke();
    ctx.beginPath(); ctx.arc(x, y, START_R, 0, 2 * Math.PI);
    ctx.strokeStyle = "white"; ctx.lineWidth = 6; ctx.stroke();
    ctx.strokeStyle = S.selected === "start" ? COLOUR.selected : COLOUR.start; ctx.lineWidth = 3; ctx.stroke();
    const bx = x - START_R * 0.72, by = y - START_R * 0.72;
    ctx.beginPath(); ctx.arc(bx, by, 7, 0, 2 * Math.PI);
    ctx.fillStyle = COLOUR.start; ctx.fill(); ctx.strokeStyle = "white"; ctx.lineWidth = 1.5; ctx.stroke();
    ctx.fillStyle = "white"; ctx.font = "bold 9px system-ui, sans-serif"; ctx.textAlign = "center"; ctx.textBaseline = "middle";
    ctx.fillText("S", bx, by + 0.5);
  },
  // Leg lengths where they fit: along a leg long enough on the screen for its text,
  // inside the view, over no marker and no other label (a grid of what is taken finds
  // the overlaps without comparing every pair). A leg with no path says so, with why.
  placeLabels(ctx, f, size) {
    const box = this.labels;
    box.textContent = "";
    if (!S.planned || S.drag) return;
    const CELL = 48, COLS = Math.ceil(size.x / CELL) + 2, taken = new Map();
    const hits = (a, b) => a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3];
    // Rectangles by grid cell (numbered row by row; the view's margin clamped to its edge).
    const visit = (r, each) => {
      const x0 = Math.max(-1, Math.floor(r[0] / CELL)), x1 = Math.min(COLS - 2, Math.floor((r[0] + r[2]) / CELL));
      const y0 = Math.max(-1, Math.floor(r[1] / CELL)), y1 = Math.floor((r[1] + r[3]) / CELL);
      for (let gy = y0; gy <= y1; gy++) for (let gx = x0; gx <= x1; gx++) if (each((gy + 1) * COLS + gx + 1) === false) return false;
      return true;
    };
    const free = (r) => visit(r, (key) => !(taken.get(key) || []).some((o) => hits(r, o)));
    const take = (r) => visit(r, (key) => { const list = taken.get(key); if (list) list.push(r); else taken.set(key, [r]); });
    const markR = (this.compact ? DOT_R : MARK_R) + LABEL_GAP;
    for (let i = 0; i < this.px.length; i++) {
      const x = this.px[i], y = this.py[i];
      if (Number.isNaN(x) || x < -markR || y < -markR || x > size.x + markR || y > size.y + markR) continue;
      const compact = this.compact && i !== S.selected;
      const half = compact ? DOT_R : this.halfWidth(ctx, i) + 3, high = compact ? DOT_R : MARK_R;
      take([x - half - LABEL_GAP, y - high - LABEL_GAP, 2 * (half + LABEL_GAP), 2 * (high + LABEL_GAP)]);
    }
    if (this.start) take([this.start[0] - START_R - 8, this.start[1] - START_R - 8, 2 * START_R + 16, 2 * START_R + 16]);
    for (const r of this.replayed) take([r.x - MARK_R - 4, r.y - MARK_R - 4, 2 * MARK_R + 8, 2 * MARK_R + 8]);
    ctx.font = LABEL_FONT;
    const shortest = 2 * MARK_R + 30;  // px: no label is narrower than 30 px
    const made = [];
    const seen = this.viewBox(f, 0);
    for (const leg of S.legs) {
      if (made.length >= MAX_LABELS) break;
      if (leg.points && !overlaps(legBox(leg), seen)) continue;  // its middle is not in sight
      // Too short on the screen for a label, by its length (the points' own, to the mm):
      // zoomed out, that is every leg, each measured point by point before.
      if (leg.points && typeof leg.length_m === "number" && leg.length_m * f.s + 1 < shortest) continue;
      let pts = leg.points;
      if (!pts) {
        const a = this.endOf(leg.from === "start" ? "start" : Number(leg.from)), b = this.endOf(leg.to);
        if (!a || !b) continue;
        pts = [a, b];
      }
      const mid = this.midpoint(pts, f, shortest, size);
      if (!mid) continue;
      const text = leg.points ? `${leg.length_m.toFixed(2)} m` : "no path";
      const w = Math.ceil(ctx.measureText(text).width) + 6;
      if (mid.length_px < w + 2 * MARK_R) continue;  // the leg is shorter than its label
      const r = [Math.round(mid.x - w / 2), Math.round(mid.y - LABEL_H / 2), w, LABEL_H];
      if (r[0] < 0 || r[1] < 0 || r[0] + w > size.x || r[1] + LABEL_H > size.y) continue;
      const padded = [r[0] - LABEL_GAP, r[1] - LABEL_GAP, w + 2 * LABEL_GAP, LABEL_H + 2 * LABEL_GAP];
      if (!free(padded)) continue;
      take(padded);
      const el = document.createElement("div");
      el.className = leg.points ? "leg-label" : "leg-label no-path";
      el.textContent = text;
      el.style.left = `${r[0]}px`; el.style.top = `${r[1]}px`; el.style.width = `${w}px`;
      if (!leg.points) el.title = noPathReason(leg);
      made.push(el);
    }
    box.append(...made);
  },
  // The point halfway along a leg on the screen and the leg's length there (px); null
  // when the leg is shorter than ``shortest`` or its middle is out of the view.
  midpoint(pts, f, shortest, size) {
    const sx = (k) => f.ox + pts[k][0] * f.s, sy = (k) => f.oy - pts[k][1] * f.s;
    let total = 0;
    for (let k = 1; k < pts.length; k++) total += Math.hypot(sx(k) - sx(k - 1), sy(k) - sy(k - 1));
    if (!(total >= shortest)) return null;
    let left = total / 2;
    for (let k = 1; k < pts.length; k++) {
      const d = Math.hypot(sx(k) - sx(k - 1), sy(k) - sy(k - 1));
      if (left <= d) {
        const x = sx(k - 1) + ((sx(k) - sx(k - 1)) * left) / d, y = sy(k - 1) + ((sy(k) - sy(k - 1)) * left) / d;
        return x < 0 || y < 0 || x > size.x || y > size.y ? null : { x, y, length_px: total };
      }
      left -= d;
    }
    return null;
  },
  // What is under a screen point: "start", a waypoint's index, or null. The start
  // pose's ring and tab first (drawn on top), then the waypoints from the top one down.
  hitTest(x, y) {
    if (!this.frame0) return null;
    if (this.start) {
      const d = Math.hypot(x - this.start[0], y - this.start[1]);
      const tab = Math.hypot(x - (this.start[0] - START_R * 0.72), y - (this.start[1] - START_R * 0.72));
      if ((d >= MARK_R + 1 && d <= START_R + 4) || tab <= 8) return "start";
    }
    const ctx = this.canvas.getContext("2d");
    const over = (i) => {
      if (Number.isNaN(this.px[i])) return false;
      const dx = Math.abs(x - this.px[i]), dy = Math.abs(y - this.py[i]);
      if (this.compact && i !== S.selected) return dx * dx + dy * dy <= (DOT_R + 3) ** 2;
      const half = this.halfWidth(ctx, i);
      return dy <= MARK_R && dx <= half && (half > MARK_R || dx * dx + dy * dy <= MARK_R * MARK_R);
    };
    if (typeof S.selected === "number" && S.selected < this.px.length && over(S.selected)) return S.selected;
    for (let i = this.px.length - 1; i >= 0; i--) if (over(i)) return i;
    if (this.start && Math.hypot(x - this.start[0], y - this.start[1]) <= START_R + 4) return "start";
    return null;
  },
  // What the last paint showed, for tests and tools: each waypoint's screen point
  // (container pixels), the plate's half width and state, and the start pose's point.
  drawn() {
    const ctx = this.canvas.getContext("2d"), bad = new Set(S.problems.map((p) => p.waypoint));
    const marks = [];
    for (let i = 0; i < this.px.length; i++) {
      if (Number.isNaN(this.px[i])) continue;
      const state = S.run && S.run.waypoints ? S.run.waypoints[i] || "pending" : null;
      marks.push({ index: i, x: this.px[i], y: this.py[i], half: this.compact && i !== S.selected ? DOT_R : this.halfWidth(ctx, i),
        r: this.compact && i !== S.selected ? DOT_R : MARK_R, bad: bad.has(i), selected: i === S.selected, state, tasks: hasTasks(i) });
    }
    return { marks, start: this.start, compact: this.compact, replayed: this.replayed };
  },
});
const missionLayer = new MissionLayer().addTo(map);
// A planned leg's bounding box in metres, worked out once per leg the server sent: at
// 5000 waypoints zoomed in, the legs out of the view are neither drawn nor measured for
// a label (the drag's two redraws drew and measured all 5000 with every point before).
const legBoxes = new WeakMap();
function legBox(leg) {
  let box = legBoxes.get(leg);
  if (!box) {
    box = [Infinity, Infinity, -Infinity, -Infinity];
    for (const [x, y] of leg.points) {
      if (x < box[0]) box[0] = x; if (y < box[1]) box[1] = y;
      if (x > box[2]) box[2] = x; if (y > box[3]) box[3] = y;
    }
    legBoxes.set(leg, box);
  }
  return box;
}
const overlaps = (a, b) => a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3];
// Why a leg has no path: the pre-flight's problem about its end waypoint, if it has one.
function noPathReason(leg) {
  const problem = S.problems.find((p) => p.waypoint === leg.to);
  const from = leg.from === "start" ? "the start pose" : `waypoint ${Number(leg.from) + 1}`;
  return `no path from ${from} to waypoint ${leg.to + 1}${problem ? `: ${problem.text}` : ""}`;
}

// The element with the focus is rebuilt by render (a row): the focus goes to the new one
// in its place (data-focus), as a keyboard user would lose it otherwise.
function render() {
  const began = performance.now();
  const focused = S.focusNext !== undefined ? S.focusNext : document.activeElement?.dataset?.focus;
  S.focusNext = undefined;
  const row = (focused || "").match(/^row-(\d+)/);
  if (row) showRow(Number(row[1]));  // built, so that it can have the focus
  renderAll();
  S.renderMs = performance.now() - began;  // read by benchmarks/bench_studio.py
  if (!focused) return;
  const el = document.querySelector(`[data-focus="${focused}"]`);
  if (el && el !== document.activeElement) el.focus({ preventScroll: true });
}
const SETTLE_MS = 250;
// The drop's wait for its answer is over: the canvas is drawn as everything else is
// (``draw``: at once, when the answer did not come in time).
function settle(settling, draw) {
  if (S.settling !== settling) return;
  S.settling = null;
  if (S.drag === settling) S.drag = null;
  if (draw) missionLayer.draw();
}
function renderAll() {
  if (!S.settling) missionLayer.draw();
  drawHandle();
  if (S.selected !== S.listedSelection) {  // a waypoint selected on the map: its row shown
    S.listedSelection = S.selected;
    if (typeof S.selected === "number") showRow(S.selected);
  }
  renderList();
  renderEditor();
  renderSettings();
  renderDefaults();
  renderProblems();
  $("undo").disabled = !S.undo.length;
  $("redo").disabled = !S.redo.length;
}

// ---- the mouse on the map: select, drag (hit-tested on the painted positions) ----------
const mapBox = map.getContainer();
mapBox.setAttribute("aria-describedby", "keys-help");
const busyNow = () => (S.run && !S.run.done) || S.replay;
function pointerHit(e) {
  const box = mapBox.getBoundingClientRect();
  return missionLayer.hitTest(e.clientX - box.left, e.clientY - box.top);
}
// A press on a marker is the marker's, not the map's: Leaflet neither pans nor adds a
// waypoint with it (listened to in the capture phase, before Leaflet's own listeners).
for (const type of ["pointerdown", "touchstart"]) {
  mapBox.addEventListener(type, (e) => { if (S.doc && pointerHit(e.touches ? e.touches[0] : e) !== null) e.stopPropagation(); }, true);
}
mapBox.addEventListener("mousedown", (e) => {
  if (e.button !== 0 || !S.doc || S.placingStart) return;
  const hit = pointerHit(e);
  if (hit === null) return;
  e.stopPropagation();
  e.preventDefault();
  mapBox.focus({ preventScroll: true });  // the arrows then move what was pressed
  S.press = { hit, x0: e.clientX, y0: e.clientY, moved: false };
}, true);
document.addEventListener("mousemove", (e) => {
  const p = S.press;
  if (!p) {
    if (S.doc && e.target.closest && e.target.closest("#map")) mapBox.classList.toggle("over-mark", pointerHit(e) !== null);
    return;
  }
  if (busyNow()) return;
  if (!p.moved && Math.hypot(e.clientX - p.x0, e.clientY - p.y0) < 3) return;
  if (!p.moved) { p.moved = true; S.selected = p.hit; drawHandle(); }
  const at = map.mouseEventToLatLng(e);
  S.drag = { target: p.hit, x: at.lng, y: at.lat };
  const point = selectedPoint();
  moveHandle(at.lng, at.lat, (point && point.yaw) || 0);
  missionLayer.schedule();
});
document.addEventListener("mouseup", () => {
  const p = S.press;
  if (!p) return;
  S.press = null;
  // The click that follows the press is not the map's (it would add a waypoint).
  S.swallowClick = true;
  setTimeout(() => { S.swallowClick = false; }, 0);
  const drag = S.drag;
  S.drag = null;
  const began = performance.now();
  if (p.moved && drag) {
    // The canvas keeps the drag's last frame (the point where it was dropped, its legs
    // straight and dashed) until the check's answer is drawn, SETTLE_MS at most: at 5000
    // waypoints each redraw is rasterised whole, on the page's thread in a browser
    // without a GPU, and the answer waited behind the drop's own redraw (40-140 ms).
    const settling = { target: drag.target, x: round(drag.x, 2), y: round(drag.y, 2) };
    S.drag = S.settling = settling;
    setTimeout(() => settle(settling, true), SETTLE_MS);
    edit(() => {
      const point = drag.target === "start" ? S.doc.start : S.doc.waypoints[drag.target];
      point.x = settling.x; point.y = settling.y;
      S.selected = drag.target;
    });
  } else { S.selected = p.hit; render(); }
  S.dragDropMs = performance.now() - began;  // the page's own part (benchmarks/bench_studio.py)
}, true);
mapBox.addEventListener("click", (e) => { if (S.swallowClick) { S.swallowClick = false; e.stopPropagation(); } }, true);

// The yaw handle of the selected waypoint: drag it around the point to set the heading.
function handleOffset() { return 40 / 2 ** map.getZoom(); }  // 40 px in metres
function drawHandle() {
  if (S.layers.handle) S.layers.handle.remove();
  S.layers.handle = null;
  const w = selectedPoint();
  if (!w || !okPoint(w)) return;
  const yaw = ((w.yaw || 0) * Math.PI) / 180;
  const r = handleOffset();
  S.layers.handle = L.marker(ll(w.x + r * Math.cos(yaw), w.y + r * Math.sin(yaw)), {
    icon: L.divIcon({ className: "yaw-handle", iconSize: [12, 12] }), draggable: true, zIndexOffset: 1000,
    title: "drag to set the heading",
    // Not a Tab stop: it is worked by dragging only; the keyboard sets the heading in the
    // form's yaw field.
    keyboard: false,
  }).addTo(map);
  S.layers.handle.getElement().dataset.testid = "yaw-handle";
  S.layers.handle.on("click", (e) => L.DomEvent.stopPropagation(e));
  S.layers.handle.on("drag", (e) => {
    const p = e.target.getLatLng();
    S.dragYaw = { target: S.selected, deg: Math.round((Math.atan2(p.lat - w.y, p.lng - w.x) * 180) / Math.PI) };
    missionLayer.schedule();
  });
  S.layers.handle.on("dragend", (e) => {
    const p = e.target.getLatLng();
    S.dragYaw = null;
    edit(() => { w.yaw = Math.round((Math.atan2(p.lat - w.y, p.lng - w.x) * 180) / Math.PI); });
  });
}
function moveHandle(x, y, yawDeg) {
  if (!S.layers.handle) return;
  const r = handleOffset(), yaw = (yawDeg * Math.PI) / 180;
  S.layers.handle.setLatLng(ll(x + r * Math.cos(yaw), y + r * Math.sin(yaw)));
}
map.on("zoomend", drawHandle);

// ---- the waypoint list: only the rows in sight are built ---------------------------------
// The list scrolls in a box of its own; rows have one height, so the rows in sight follow
// from the scroll position: a mission of 5000 waypoints builds some forty rows, not 5000.
// Tab goes through the rows built; focusing one near the box's edge scrolls it in, which
// builds the next ones. Each row says its place (aria-posinset of aria-setsize).
const ROW_H = 24, ROW_SPARE = 8;
function showRow(i) {
  const list = $("waypoint-box");
  const height = list.clientHeight || listHeight();
  if (i * ROW_H < list.scrollTop) list.scrollTop = i * ROW_H;
  else if ((i + 1) * ROW_H > list.scrollTop + height) list.scrollTop = (i + 1) * ROW_H - height;
}
const listHeight = () => Math.min(S.doc.waypoints.length * ROW_H, Math.max(window.innerHeight * 0.4, 8 * ROW_H));
function rowsInSight() {
  const list = $("waypoint-box"), n = S.doc.waypoints.length;
  const height = list.clientHeight || listHeight();
  const first = Math.max(0, Math.floor(list.scrollTop / ROW_H) - ROW_SPARE);
  const last = Math.min(n, Math.ceil((list.scrollTop + height) / ROW_H) + ROW_SPARE);
  return [first, last];
}
function renderList() {
  const list = $("waypoints"), n = S.doc.waypoints.length;
  const [first, last] = rowsInSight();
  const kept = S.rows && S.rows[0] === first && S.rows[1] === last && S.rows[2] === n && list.children.length === last - first;
  S.rows = [first, last, n];
  list.style.paddingTop = `${first * ROW_H}px`;
  list.style.paddingBottom = `${(n - last) * ROW_H}px`;
  if (kept) {
    // The same rows in sight: each brought up to date in place, touching only what changed,
    // so that the row with the focus keeps it (moving the focus to a new row made the
    // browser lay the page out again: 120 ms of a typed change at 5000 waypoints).
    for (let i = first; i < last; i++) updateRow(list.children[i - first], i, n);
    return;
  }
  const made = [];
  for (let i = first; i < last; i++) made.push(waypointRow(i, n));
  list.replaceChildren(...made);
}
$("waypoint-box").addEventListener("scroll", () => {
  if (S.listFrame) return;
  S.listFrame = requestAnimationFrame(() => {
    S.listFrame = 0;
    const [first, last] = rowsInSight();
    if (S.rows && S.rows[0] === first && S.rows[1] === last && S.rows[2] === S.doc.waypoints.length) return;
    // A focused row scrolled out of the box: the focus goes to the nearest row built.
    const focused = (document.activeElement?.dataset?.focus || "").match(/^row-(\d+)(-.*)?$/);
    renderList();
    if (!focused) return;
    const i = Math.min(Math.max(Number(focused[1]), first), last - 1);
    const el = document.querySelector(`[data-focus="row-${i}${focused[2] || ""}"]`);
    if (el) el.focus({ preventScroll: true });
  });
});
// A row reached with Tab is scrolled in and the rows after it built at once (not at the
// next frame): a fast Tab would otherwise leave the list at the last row built.
$("waypoints").addEventListener("focusin", (e) => {
  const key = e.target.dataset?.focus || "";
  const row = key.match(/^row-(\d+)/);
  if (!row) return;
  showRow(Number(row[1]));
  const [first, last] = rowsInSight();
  if (S.rows && S.rows[0] === first && S.rows[1] === last && S.rows[2] === S.doc.waypoints.length) return;
  renderList();
  const el = document.querySelector(`[data-focus="${key}"]`);
  if (el && el !== document.activeElement) el.focus({ preventScroll: true });
});
function waypointRow(i, n) {
  const li = document.createElement("li");
  li.dataset.testid = "waypoint-row";
  li.dataset.index = String(i);
  li.draggable = true;
  // The row's waypoint is a button (Tab reaches it, Enter or Space selects it); ▲ ▼ ✕
  // are named for a screen reader by what they do, not by their glyph.
  li.innerHTML = `<button type="button" class="pick"><span class="num"></span><span class="label"></span><span class="state"></span></button>
    <button type="button" class="up">▲</button><button type="button" class="down">▼</button><button type="button" class="del">✕</button>`;
  li.querySelector(".num").textContent = i + 1;
  const [pick, up, down, del] = li.querySelectorAll("button");
  pick.dataset.focus = `row-${i}`;
  for (const [button, part, what] of [[up, "up", "move waypoint # up"], [down, "down", "move waypoint # down"], [del, "del", "delete waypoint #"]]) {
    button.dataset.focus = `row-${i}-${part}`;
    button.setAttribute("aria-label", what.replace("#", String(i + 1)));
    button.title = what.replace(" #", "");
  }
  up.onclick = (e) => { e.stopPropagation(); moveWaypoint(i, i - 1); };
  down.onclick = (e) => { e.stopPropagation(); moveWaypoint(i, i + 1); };
  del.onclick = (e) => { e.stopPropagation(); removeWaypoint(i); };
  li.onclick = () => {
    S.selected = i; S.listedSelection = i; render();
    const w = S.doc.waypoints[i];  // looked up now: undo replaces the document
    if (okPoint(w)) map.panTo(ll(w.x, w.y));
  };
  li.ondragstart = (e) => { e.dataTransfer.setData("text/plain", String(i)); };
  li.ondragover = (e) => { e.preventDefault(); li.classList.add("drop-target"); };
  li.ondragleave = () => li.classList.remove("drop-target");
  li.ondrop = (e) => { e.preventDefault(); moveWaypoint(Number(e.dataTransfer.getData("text/plain")), i); };
  updateRow(li, i, n);
  return li;
}
// What a row shows of waypoint i (of n), set only where it differs from what it shows.
function updateRow(li, i, n) {
  const w = S.doc.waypoints[i];
  const attribute = (el, name, value) => {
    if (value === null) { if (el.hasAttribute(name)) el.removeAttribute(name); } else if (el.getAttribute(name) !== value) el.setAttribute(name, value);
  };
  const text = (el, value) => { if (el.textContent !== value) el.textContent = value; };
  attribute(li, "aria-setsize", String(n));
  attribute(li, "aria-posinset", String(i + 1));
  li.classList.toggle("selected", i === S.selected);
  li.classList.toggle("bad", problemsOf(i).length > 0);
  const state = S.run && S.run.waypoints[i] ? S.run.waypoints[i] : "";
  const xy = okPoint(w) ? `(${w.x.toFixed(2)}, ${w.y.toFixed(2)}, ${w.yaw ?? 0}°)` : "(?)";
  text(li.querySelector(".label"), `${w.name ? w.name + " " : ""}${xy}`);
  const stateEl = li.querySelector(".state");
  text(stateEl, state);
  const flag = li.querySelector(".task-flag"), wanted = hasTasks(i) ? taskFlag(i) : null;
  if (flag && (!wanted || flag.title !== wanted.title)) flag.remove();
  if (wanted && (!flag || flag.title !== wanted.title)) stateEl.before(wanted);
  attribute(li.querySelector(".pick"), "aria-current", i === S.selected ? "true" : null);
}
// The forms are built once for their set of fields and then updated in place: rebuilding
// them at every edit replaced the input being typed in, so Enter or Tab dropped the focus
// and the next value typed went nowhere. The input that has the focus keeps what the user
// typed; the others show the mission.
function fillForm(form, specs) {
  const shape = specs.map((s) => s.label).join("|");
  if (form.dataset.shape !== shape) {
    form.textContent = "";
    form.dataset.shape = shape;
    form.onChange = {};
    for (const s of specs) field(form, s);
  }
  for (const s of specs) {
    const input = $(`${form.id}-${s.key}`);
    form.onChange[s.key] = s.onChange;  // closes over the current document (undo replaces it)
    if (input !== document.activeElement) input.value = s.value ?? "";
    if (s.placeholder !== undefined) input.placeholder = s.placeholder;
  }
}
function field(form, { key, label, kind }) {
  const l = document.createElement("label");
  l.textContent = label;
  let input;
  if (Array.isArray(kind)) {
    input = document.createElement("select");
    for (const option of kind) {
      const o = document.createElement("option");
      o.value = option; o.textContent = option || "(default)";
      input.appendChild(o);
    }
  } else {
    input = document.createElement("input");
    input.type = kind; if (kind === "number") input.step = "any";
  }
  input.name = label;
  input.id = `${form.id}-${key}`;
  l.htmlFor = input.id;  // every input named by its visible label
  input.addEventListener("change", () => form.onChange[key](input.value));
  form.append(l, input);
}
// Enter commits a field (its change event); it never submits a form (nothing to send).
for (const id of ["fields", "settings", "defaults"]) $(id).addEventListener("submit", (e) => e.preventDefault());
function fieldValue(kind, text) {
  if (text === "") return undefined;
  if (kind === "number") { const n = Number(text); return Number.isFinite(n) ? n : text; }
  return text;
}
function renderEditor() {
  const w = typeof S.selected === "number" ? S.doc.waypoints[S.selected] : null;
  $("editor").hidden = !w;
  if (!w) return;
  $("editor-title").textContent = `${S.selected + 1}`;
  const defaults = S.doc.defaults || {};
  fillForm($("fields"), WP_FIELDS.map(([key, kind]) => {
    const unit = S.units[key] ? ` [${S.units[key]}]` : "";
    const inherited = defaults[key] === undefined || defaults[key] === null ? "" : `default ${defaults[key]}`;
    return { key, label: key + unit, kind, value: w[key], placeholder: ["x", "y", "yaw", "name"].includes(key) ? "" : inherited,
      onChange: (text) => edit(() => {
        const value = fieldValue(kind, text);
        if (value === undefined) delete w[key]; else w[key] = value;
      }) };
  }));
  renderTaskList($("wp-tasks"), waypointTasks(S.selected));
}
function renderSettings() {
  const st = S.doc.start;
  fillForm($("settings"), [
    { key: "loops", label: "loops", kind: "text", value: S.doc.loops, onChange: (t) => edit(() => {
      S.doc.loops = t === "forever" ? "forever" : fieldValue("number", t) ?? 1;
    }) },
    { key: "frame", label: "frame", kind: "text", value: S.doc.frame, onChange: (t) => edit(() => { S.doc.frame = t; }) },
    { key: "map", label: "map", kind: "text", value: S.doc.map, onChange: (t) => edit(() => { S.doc.map = t || null; }) },
    { key: "start", label: "start x,y,yaw", kind: "text", value: okPoint(st) ? `${st.x}, ${st.y}, ${st.yaw ?? 0}` : "",
      placeholder: "none: the simulator's", onChange: (t) => edit(() => {
        const parts = t.split(",").map((v) => Number(v.trim()));
        if (!t.trim()) delete S.doc.start;
        else S.doc.start = { x: parts[0], y: parts[1], yaw: parts[2] || 0 };
      }) },
  ]);
}
// The recovery list (docs/mission-format.md, Recoveries before a retry) typed as the file
// writes it inside its brackets: "spin: 90, backup: 0.15, clear_costmaps". Entries are
// kept as typed (a number where one is given): the server names a bad one.
function recoveryText(list) {
  if (!Array.isArray(list)) return list == null ? "" : String(list);
  return list.map((r) => (r && typeof r === "object" ? Object.entries(r).map(([k, v]) => `${k}: ${v}`).join(", ") : String(r))).join(", ");
}
function recoveryList(text) {
  const entries = text.split(",").map((part) => part.trim()).filter((part) => part);
  if (!entries.length) return undefined;
  return entries.map((entry) => {
    const colon = entry.indexOf(":");
    if (colon < 0) return entry;
    const amount = entry.slice(colon + 1).trim();
    return { [entry.slice(0, colon).trim()]: fieldValue("number", amount) ?? null };
  });
}
function renderDefaults() {
  const defaults = S.doc.defaults || {};
  fillForm($("defaults"), DEFAULT_FIELDS.map(([key, kind]) => {
    const unit = S.units[key] ? ` [${S.units[key]}]` : "";
    const recovery = key === "recovery";
    return { key, label: key + unit, kind, placeholder: recovery ? "none, e.g. spin: 90, wait: 2, clear_costmaps" : "loader's default",
      value: recovery ? recoveryText(defaults[key]) : typeof defaults[key] === "boolean" ? String(defaults[key]) : defaults[key],
      onChange: (text) => edit(() => {
        const d = { ...(S.doc.defaults || {}) };
        const value = key === "clear_costmaps_on_retry" && text !== "" ? text === "true"
          : recovery ? recoveryList(text) : fieldValue(kind, text);
        if (value === undefined) delete d[key]; else d[key] = value;
        S.doc.defaults = d;
      }) };
  }));
  renderTaskList($("default-tasks"), defaultTasks);
}
function placeStart(on) {
  S.placingStart = on;
  $("place-start").classList.toggle("active", on);
  $("map").style.cursor = on ? "copy" : "";
  if (on) say("click the map to put the start pose there (Esc: cancel)");
}
$("place-start").onclick = () => placeStart(!S.placingStart);
function renderProblems() {
  const list = $("problems");
  list.textContent = "";
  // The first ones listed (a mission of thousands may have thousands): the rest are
  // counted, and each waypoint's own are on its row (red) and marker.
  for (const p of S.problems.slice(0, MAX_PROBLEMS_LISTED)) {
    const li = document.createElement("li");
    li.dataset.testid = "problem";
    if (p.waypoint !== null) {
      // A button: the keyboard reaches it and Enter selects the waypoint concerned.
      const b = document.createElement("button");
      b.type = "button"; b.className = "problem-link"; b.textContent = p.text;
      b.onclick = () => { S.selected = p.waypoint; render(); };
      li.appendChild(b);
    } else li.textContent = p.text;
    if (p.fix) li.appendChild(fixButton(p));
    list.appendChild(li);
  }
  if (S.problems.length > MAX_PROBLEMS_LISTED) {
    const more = document.createElement("li");
    more.textContent = `and ${S.problems.length - MAX_PROBLEMS_LISTED} more`;
    list.appendChild(more);
  }
  $("problem-count").textContent = S.problems.length ? `(${S.problems.length})` : "";
  const save = $("save");
  save.classList.toggle("warn", S.problems.length > 0);
  save.textContent = S.problems.length ? `Save (${S.problems.length} problem${S.problems.length > 1 ? "s" : ""})` : "Save";
  $("route").textContent = routeText();
}
const MAX_PROBLEMS_LISTED = 100;
// The route's length; with legs that have no path, the planned legs' total and which legs
// are left out (they are drawn dashed, in red).
function routeText() {
  const r = S.route, n = `${S.doc.waypoints.length} waypoints`;
  if (r.total_length_m != null) return `${n} · ${r.total_length_m.toFixed(2)} m · ${r.estimated_duration}`;
  if (!S.planned) return `${n} · checking and planning…`;
  if (!r.unplanned_legs) return n;
  const legs = S.legs.filter((leg) => !leg.loop);
  const open = legs.filter((leg) => leg.length_m == null);
  const planned = legs.reduce((sum, leg) => sum + (leg.length_m ?? 0), 0);
  const name = (leg) => `${leg.from === "start" ? "S" : Number(leg.from) + 1}→${leg.to + 1}`;
  const named = open.slice(0, 5).map(name).join(", ") + (open.length > 5 ? ` and ${open.length - 5} more` : "");
  return `${n} · ${planned.toFixed(2)} m planned, not counting ${open.length} leg${open.length > 1 ? "s" : ""} with no path (${named}; dashed red)`;
}

// ---- tasks at waypoints (docs/mission-format.md, Tasks at waypoints) -------------------
// A task is a document item {KIND: VALUE, timeout?}; the page edits wait's seconds,
// input's prompt and any task's timeout, adds wait and input tasks, removes and reorders
// any: the other kinds' values are kept as they are (the server checks them all).
const TASK_KINDS = ["wait", "wait_for", "input", "snapshot", "call", "publish", "run"];
// The kinds without a time limit when the file gives no timeout (the others: 60 s).
const UNLIMITED_KINDS = ["wait", "input"];
const taskKind = (t) => (t && typeof t === "object" ? Object.keys(t).find((k) => TASK_KINDS.includes(k)) : undefined);
// The task in a few words, as navseq says it ("wait 5 s", "input: Load the tray").
function describeTask(t) {
  const kind = taskKind(t);
  const v = kind ? t[kind] : null;
  const o = v && typeof v === "object" ? v : {};
  switch (kind) {
    case "wait": return `wait ${v} s`;
    case "input": return `input: ${o.prompt || "confirm to go on"}`;
    case "wait_for": {
      const relation = ["equals", "above", "below"].find((r) => r in o) || "?";
      return `wait for ${o.topic} ${o.field} ${relation} ${JSON.stringify(o[relation])}`;
    }
    case "snapshot": return `snapshot of ${o.topic}`;
    case "call": return `call ${o.service}`;
    case "publish": return `publish on ${o.topic}`;
    case "run": return `run ${Array.isArray(o.argv) ? o.argv.join(" ") : "?"}`;
    default: return "unknown task (see Problems)";
  }
}
// The tasks a waypoint runs: its own list, else the defaults' (an own [] runs none).
function tasksOf(i) {
  const w = S.doc.waypoints[i];
  if (w && Array.isArray(w.tasks)) return w.tasks;
  const d = (S.doc.defaults || {}).tasks;
  return Array.isArray(d) ? d : [];
}
function hasTasks(i) { return tasksOf(i).length > 0; }
// The small flag on a waypoint's row (the marker gets the class "tasks").
function taskFlag(i) {
  const span = document.createElement("span");
  span.className = "task-flag";
  const n = tasksOf(i).length;
  span.title = `${n} task${n > 1 ? "s" : ""}: ${tasksOf(i).map(describeTask).join("; ")}`;
  span.innerHTML = '<span aria-hidden="true"></span><span class="sr-only"></span>';
  span.firstChild.textContent = `⚑${n}`;
  span.lastChild.textContent = `, ${n} task${n > 1 ? "s" : ""}`;
  return span;
}
// Whose list a task panel edits, looked up again at each change (undo replaces S.doc).
function waypointTasks(i) {
  return { id: `wp${i}`, name: `waypoint ${i + 1}`, own: () => S.doc.waypoints[i].tasks,
    set: (list) => { if (list === undefined) delete S.doc.waypoints[i].tasks; else S.doc.waypoints[i].tasks = list; },
    problems: () => S.problems.filter((p) => p.waypoint === i) };
}
const defaultTasks = {
  id: "defaults", name: "defaults", own: () => (S.doc.defaults || {}).tasks,
  set: (list) => {
    const d = { ...(S.doc.defaults || {}) };
    if (list === undefined || !list.length) delete d.tasks; else d.tasks = list;
    S.doc.defaults = d;
  },
  problems: () => S.problems.filter((p) => p.key === "defaults"),
};
// The problem of task n (1-based) of a list, from its subject ("…, task 2 (wait)").
function taskProblem(problems, n) {
  return problems.find((p) => new RegExp(`(^|, )task ${n}( |$|,)`).test(p.subject || ""));
}
function renderTaskList(box, owner) {
  const own = owner.own();
  const problems = owner.problems();
  // Rebuilt only when the list (or its problems) changed: a rebuild while a value is typed
  // would drop it. Handlers find the list through box.owner, set at every render.
  box.owner = owner;
  const shape = JSON.stringify([owner.id, own, problems.map((p) => p.text), (S.doc.defaults || {}).tasks]);
  if (box.dataset.shape === shape) return;
  box.dataset.shape = shape;
  box.textContent = "";
  const list = Array.isArray(own) ? own : [];
  if (!Array.isArray(own) && owner.id !== "defaults") {
    const inherited = (S.doc.defaults || {}).tasks || [];
    const p = document.createElement("p");
    p.className = "none";
    p.textContent = inherited.length ? `none of its own: the defaults' (${inherited.map(describeTask).join("; ")})` : "none";
    box.appendChild(p);
  } else if (!list.length) {
    const p = document.createElement("p");
    p.className = "none";
    p.textContent = owner.id === "defaults" ? "none" : "none here (the defaults' tasks do not run here)";
    box.appendChild(p);
  }
  const ol = document.createElement("ol");
  list.forEach((t, k) => ol.appendChild(taskRow(box, t, k, list.length, taskProblem(problems, k + 1))));
  if (list.length) box.appendChild(ol);
  box.appendChild(taskAdder(box, own));
}
function changeTasks(box, change) {
  const owner = box.owner;
  edit(() => {
    const list = JSON.parse(JSON.stringify(owner.own() || []));
    owner.set(change(list));
  });
}
function taskRow(box, t, k, count, problem) {
  const id = `${box.id}-${k}`;
  const kind = taskKind(t);
  const li = document.createElement("li");
  li.dataset.testid = "task";
  li.dataset.kind = kind || "";
  if (problem) li.classList.add("bad");
  const head = document.createElement("div");
  head.className = "task-head";
  const text = document.createElement("span");
  text.className = "task-text";
  const timeout = t.timeout === undefined ? "" : t.timeout === null ? " (no time limit)" : ` (timeout ${t.timeout} s)`;
  text.textContent = `${k + 1}. ${describeTask(t)}${timeout}`;
  text.title = text.textContent;
  head.appendChild(text);
  const what = `task ${k + 1}`;
  for (const [glyph, part, label, to] of [["▲", "up", `move ${what} up`, k - 1], ["▼", "down", `move ${what} down`, k + 1], ["✕", "del", `remove ${what}`, null]]) {
    const b = document.createElement("button");
    b.type = "button"; b.textContent = glyph; b.title = label;
    b.setAttribute("aria-label", label);
    b.dataset.focus = `${id}-${part}`;
    if (to !== null && (to < 0 || to >= count)) b.disabled = true;
    b.onclick = () => {
      if (to === null) {
        // The focus goes to the task taking its place, else the add choice.
        S.focusNext = count > 1 ? `${box.id}-${Math.min(k, count - 2)}-del` : `${box.id}-add`;
        changeTasks(box, (list) => { list.splice(k, 1); return list.length || box.owner.id === "defaults" ? list : undefined; });
      } else {
        S.focusNext = `${box.id}-${to}-${part}`;
        changeTasks(box, (list) => { const [moved] = list.splice(k, 1); list.splice(to, 0, moved); return list; });
      }
    };
    head.appendChild(b);
  }
  li.appendChild(head);
  const fields = document.createElement("div");
  fields.className = "task-fields";
  if (kind === "wait") taskField(fields, box, k, "seconds", "number", t.wait, "", (task, v) => { task.wait = v; });
  if (kind === "input") {
    const prompt = t.input && typeof t.input === "object" ? t.input.prompt : "";
    taskField(fields, box, k, "prompt", "text", prompt, "confirm to go on", (task, v) => {
      if (v === undefined) task.input = null; else task.input = { ...(task.input || {}), prompt: String(v) };
    });
  }
  if (kind) {
    const fallback = UNLIMITED_KINDS.includes(kind) ? "no limit" : "default 60; none: no limit";
    taskField(fields, box, k, "timeout [s]", "text", t.timeout === null ? "none" : t.timeout, fallback, (task, v) => {
      if (v === undefined) delete task.timeout;
      else if (String(v).trim().toLowerCase() === "none") task.timeout = null;
      else task.timeout = fieldValue("number", String(v));
    });
  }
  li.appendChild(fields);
  if (problem) {
    const p = document.createElement("div");
    p.className = "task-problem";
    p.textContent = problem.message;
    li.appendChild(p);
  }
  return li;
}
function taskField(fields, box, k, label, kind, value, placeholder, apply) {
  const id = `${box.id}-${k}-${label.split(" ")[0]}`;
  const l = document.createElement("label");
  l.textContent = label;
  l.htmlFor = id;
  const input = document.createElement("input");
  input.id = id; input.type = kind === "number" ? "number" : "text";
  if (kind === "number") input.step = "any";
  input.dataset.focus = id;
  input.value = value ?? "";
  input.placeholder = placeholder;
  input.addEventListener("change", () => {
    const v = fieldValue(kind, input.value);
    changeTasks(box, (list) => { apply(list[k], v); return list; });
  });
  input.addEventListener("keydown", (e) => { if (e.key === "Enter") input.blur(); });
  fields.append(l, input);
}
// Add a wait or an input task (the other kinds are written in the file); for a waypoint,
// "none here" too, which keeps the defaults' tasks from running there.
function taskAdder(box, own) {
  const wrap = document.createElement("div");
  wrap.className = "task-add";
  const select = document.createElement("select");
  select.id = `${box.id}-add`;
  select.dataset.focus = `${box.id}-add`;
  select.dataset.testid = "task-add";
  select.setAttribute("aria-label", `add a task (${box.owner.name})`);
  const choices = [["", "add a task…"], ["wait", "wait 5 s"], ["input", "input: ask the operator to confirm"]];
  if (box.owner.id !== "defaults") {
    if (!Array.isArray(own) || own.length) choices.push(["none", "no tasks here (not the defaults')"]);
    if (Array.isArray(own)) choices.push(["inherit", "the defaults' tasks (drop its own)"]);
  }
  for (const [value, text] of choices) {
    const o = document.createElement("option");
    o.value = value; o.textContent = text;
    select.appendChild(o);
  }
  select.onchange = () => {
    const choice = select.value;
    select.value = "";
    if (!choice) return;
    const owner = box.owner;
    if (choice === "none") { edit(() => owner.set([])); return; }
    if (choice === "inherit") { edit(() => owner.set(undefined)); return; }
    const task = choice === "wait" ? { wait: 5 } : { input: { prompt: "confirm to go on" } };
    const n = (owner.own() || []).length;
    S.focusNext = `${box.id}-${n}-${choice === "wait" ? "seconds" : "prompt"}`;
    changeTasks(box, (list) => { list.push(task); return list; });
  };
  wrap.appendChild(select);
  return wrap;
}

// A problem's one-click fix: the waypoint (or start pose) moved to pre-flight's nearest
// free spot, one undoable edit.
function fixButton(p) {
  const b = document.createElement("button");
  b.type = "button"; b.className = "fix"; b.dataset.testid = "fix";
  const what = p.waypoint !== null ? `waypoint ${p.waypoint + 1}` : "the start pose";
  b.textContent = "move to nearest free spot";
  b.title = `move ${what} to (${p.fix.x.toFixed(2)}, ${p.fix.y.toFixed(2)}); undo: Ctrl+Z`;
  b.setAttribute("aria-label", `move ${what} to the nearest free spot (${p.fix.x.toFixed(2)}, ${p.fix.y.toFixed(2)})`);
  b.onclick = () => {
    if ((S.run && !S.run.done) || S.replay) return;
    const point = p.waypoint !== null ? S.doc.waypoints[p.waypoint] : p.key === "start" ? S.doc.start : null;
    if (!okPoint(point)) return;
    edit(() => { point.x = p.fix.x; point.y = p.fix.y; });
    say(`${what} moved to (${p.fix.x.toFixed(2)}, ${p.fix.y.toFixed(2)}); undo: Ctrl+Z`);
  };
  return b;
}

// ---- checking (the same code as navseq validate --map) ----------------------------------
// An edit of a few waypoints goes as those waypoints only, against the draft the server
// checked for the answer the page holds (S.sent: what was sent for it, copied): a drag
// sends one waypoint, not the 180 kB of a mission of 5000 for the server to read and
// compare. Past this many, or when anything else changed, the whole draft goes.
const MAX_CHANGES = 64;
const otherKeys = (doc) => JSON.stringify({ ...doc, waypoints: null });
const sameValue = (a, b) => a === b || (typeof a === "object" && typeof b === "object" && JSON.stringify(a) === JSON.stringify(b));
// Key by key, allocating nothing: it runs over every waypoint at each edit.
function sameWaypoint(a, b) {
  if (a === b) return true;
  if (!a || !b || typeof a !== "object" || typeof b !== "object" || Array.isArray(a) !== Array.isArray(b)) return false;
  let keys = 0;
  for (const key in a) {
    if (!Object.prototype.hasOwnProperty.call(b, key) || !sameValue(a[key], b[key])) return false;
    keys++;
  }
  for (const key in b) keys--;
  return keys === 0;
}
// [[index, waypoint], ...] changed since the draft sent for S.checkId, or null (send whole).
function draftChanges() {
  const sent = S.sent, wps = S.doc.waypoints;
  if (!sent || S.checkId === null || sent.check !== S.checkId || !Array.isArray(wps)) return null;
  if (wps.length !== sent.waypoints.length || otherKeys(S.doc) !== sent.rest) return null;
  const changes = [];
  for (let i = 0; i < wps.length; i++) {
    if (sameWaypoint(wps[i], sent.waypoints[i])) continue;
    if (changes.length === MAX_CHANGES) return null;
    changes.push([i, wps[i]]);
  }
  return changes;
}
async function check() {
  if (S.checkBusy) { S.checkAgain = true; return; }
  S.checkBusy = true;
  const seq = ++S.checkSeq;
  // Written out once, now: the draft (or its changes) as it is at this moment (edits may
  // follow while the answer is on its way). "base": the answer whose legs the page
  // holds; the server then sends only the legs that differ from them (a drag: two of 5000).
  const changes = draftChanges();
  const body = changes ? JSON.stringify({ base: S.checkId, changes }) : JSON.stringify({ mission: S.doc, base: S.checkId ?? null });
  // What the server will hold as this answer's draft: the sent one with the changes, or
  // the whole draft as sent (copies: the page edits its own in place).
  const sending = changes
    ? { rest: S.sent.rest, waypoints: S.sent.waypoints.slice() }
    : { rest: otherKeys(S.doc), waypoints: Array.isArray(S.doc.waypoints) ? JSON.parse(body).mission.waypoints : [] };
  if (changes) for (const [i, w] of changes) sending.waypoints[i] = JSON.parse(JSON.stringify(w));
  const answer = await api("POST", "/api/check", body);
  S.checkBusy = false;
  // Taken in even when a newer edit is to be checked: the next answer is sent against it.
  if (answer.status === 409 && answer.data.conflict === "base") {
    // The server no longer holds that draft (restarted, or other pages' checks pushed it
    // out): the whole draft goes at once.
    S.sent = null; S.checkId = null; S.legs = []; S.checkAgain = true;
  } else if (!answer.ok) {
    S.problems = answer.data.problems || [{ text: answer.data.error, waypoint: null }];
    S.legs = []; S.route = {}; S.checkId = null; S.sent = null;
  } else {
    const data = answer.data;
    let held = true;
    if (!data.legs_changed) S.legs = data.legs;
    else if (data.base === S.checkId) for (const [position, leg] of data.legs_changed) S.legs[position] = leg;
    else { held = false; S.legs = []; S.checkAgain = true; }  // not the legs it was sent against: ask whole
    S.problems = data.problems;
    S.checkId = held ? data.check : null;
    S.sent = held ? { ...sending, check: data.check } : null;
    S.route = data;
  }
  if (S.checkAgain) { S.checkAgain = false; check(); return; }
  if (seq !== S.checkSeq) return;
  if (S.settling) settle(S.settling, false);  // drawn below, with the answer
  S.planned = true;
  await S.painted;  // Leaflet draws nothing before the map has its view
  await loadMap(false);
  render();
  document.body.dataset.checked = String(seq);
  document.body.dataset.planned = "true";  // the first check's plans are drawn
}

// ---- files -------------------------------------------------------------------------------
async function save(path) {
  const body = { mission: S.doc, version: path ? null : S.version };
  if (path) body.path = path;
  if (!path && S.exists) {
    // The opened file is replaced only once the user says so (and the server still
    // refuses if it changed on disk since it was opened).
    if (!window.confirm(`${S.name} exists; replace it with this mission?`)) { say("not saved"); return; }
    body.overwrite = true;
  }
  let answer = await api("POST", "/api/save", body);
  if (answer.status === 409 && answer.data.conflict === "exists") {
    if (!window.confirm(`${answer.data.error}?`)) { say("not saved"); return; }
    answer = await api("POST", "/api/save", { ...body, overwrite: true });
  }
  if (!answer.ok) { say(answer.data.error, true); return; }
  S.version = answer.data.version;
  S.saved = JSON.stringify(body.mission);
  if (!path) S.exists = true;
  if (path) { S.name = answer.data.path; $("mission-name").textContent = S.name; }
  const n = answer.data.problems.length;
  say(`saved ${answer.data.path}${n ? ` (with ${n} problem${n > 1 ? "s" : ""})` : ""}`);
}
$("save").onclick = () => save(null);
$("save-as").onclick = () => {
  const path = window.prompt("Save as (a .yaml file in the mission's folder):", "mission.yaml");
  if (path) save(path);
};

// ---- import / export ---------------------------------------------------------------------
// Import: a dialog listing the files the studio may read (GET /api/files), each with its
// format, chosen with the keyboard (Tab, Enter) or the mouse. The format is told by the
// file's ending: a .yaml is a navseq mission or the tutorial's rosparam file, which only
// the loader tells apart when it reads it.
function formatOf(path) {
  const ext = path.slice(path.lastIndexOf(".")).toLowerCase();
  if (ext === ".launch" || ext === ".xml") return "launch file";
  if (ext === ".csv") return "CSV";
  return "YAML: navseq or rosparam";
}
async function openImport(note, preferred) {
  const dialog = $("import-dialog");
  const list = $("import-files");
  $("import-note").textContent = note || "";
  list.textContent = "";
  const files = await api("GET", "/api/files");
  if (!files.ok) { say(files.data.error, true); return; }
  const names = files.data.missions;
  if (!names.length) $("import-note").textContent = "No file the loader reads under the studio's folders.";
  for (const path of names) {
    const li = document.createElement("li");
    const b = document.createElement("button");
    b.type = "button";
    b.dataset.testid = "import-file";
    b.dataset.path = path;
    const name = document.createElement("span");
    name.textContent = path;
    const format = document.createElement("span");
    format.className = "format";
    format.textContent = formatOf(path);
    b.append(name, format);
    b.onclick = () => { dialog.close(); importFile(path); };
    li.appendChild(b);
    list.appendChild(li);
  }
  if (!dialog.open) dialog.showModal();
  // The first file (or the one named by a dropped file) has the focus: Enter imports it.
  const first = list.querySelector(preferred ? `button[data-path$="/${CSS.escape(preferred)}"], button[data-path="${CSS.escape(preferred)}"]` : "button")
    || list.querySelector("button");
  if (first) first.focus();
}
async function importFile(path) {
  if ((S.run && !S.run.done) || S.replay) return;
  const answer = await api("POST", "/api/import", { path });
  if (!answer.ok) {
    const first = (answer.data.problems || [])[0];
    say(first ? `${answer.data.error}: ${first.text}` : answer.data.error, true);
    return;
  }
  const imported = answer.data.mission;
  // A tutorial file names no map: the mission stays on the map it is made on.
  if (!imported.map && S.doc.map) imported.map = S.doc.map;
  if (!Array.isArray(imported.waypoints)) imported.waypoints = [];
  edit(() => { S.doc = imported; S.selected = null; });
  fitMission();
  say(`imported ${imported.waypoints.length} waypoints from ${answer.data.path} (undo: Ctrl+Z); save to keep them`);
}
// ---- shortest order ----------------------------------------------------------------------
$("order").onchange = async (e) => {
  const choice = e.target.value;
  e.target.value = "";
  if (!choice || (S.run && !S.run.done) || S.replay || S.ordering) return;
  // Seconds to minutes on a big map: the server orders as a job, the page shows how
  // far its searches got, and Cancel stops them (the mission stays as it was).
  const count = S.doc.waypoints.length, began = performance.now();
  let cancelled = false, job = null, view = { state: "measuring", searches: 0 };
  const tell = () => {
    const seconds = `${Math.round((performance.now() - began) / 1000)} s`;
    let doing = `finding the shortest order of ${count} waypoints…`;
    if (view.state === "solving") doing = `choosing the shortest order of ${count} waypoints…`;
    else if (view.searches) doing = `measuring the ways between ${count} waypoints: ${view.searches_done} of ${view.searches} searches…`;
    say(`${doing} ${seconds} (Cancel stops it)`);
  };
  const ticker = setInterval(tell, 1000);
  const cancel = $("order-cancel");
  const finish = () => { clearInterval(ticker); S.ordering = null; cancel.hidden = true; $("order").disabled = false; };
  const stopJob = () => { if (job !== null) api("POST", `/api/order/jobs/${job}/cancel`, {}); };
  S.ordering = true;
  tell();
  cancel.hidden = false;
  $("order").disabled = true;
  // Cancel gives the page back at once; the server's searches stop at the next one.
  cancel.onclick = () => {
    cancelled = true;
    stopJob();
    finish();
    say("ordering cancelled: the waypoints are as they were");
  };
  let answer;
  try {
    answer = await api("POST", "/api/order/jobs", { mission: S.doc, keep_last: choice === "keep-last" });
    if (answer.ok) { job = answer.data.job; view = answer.data; }
    if (cancelled) { stopJob(); return; }
    while (answer.ok && ["measuring", "solving"].includes(answer.data.state)) {
      view = answer.data;
      tell();
      await new Promise((done) => setTimeout(done, 250));
      if (cancelled) return;
      answer = await api("GET", `/api/order/jobs/${job}`);
      if (cancelled) return;
    }
  } catch (error) {
    answer = { ok: false, data: { error: `ordering failed: ${error}` } };
  }
  finish();
  if (answer.ok && answer.data.state === "cancelled") { say("ordering cancelled: the waypoints are as they were"); return; }
  if (answer.ok && answer.data.state === "failed") answer = { ok: false, status: answer.data.status, data: answer.data.failure };
  if (!answer.ok) {
    const first = (answer.data.problems || [])[0];
    say(first ? `${answer.data.error}: ${first.text}` : answer.data.error, true);
    return;
  }
  const { order, length_m: after, length_before_m: before } = answer.data;
  if (order.every((index, k) => index === k)) { say("the waypoints already are in the shortest order"); return; }
  // The page's own waypoints, moved: every field it holds stays as it is.
  edit(() => {
    S.doc.waypoints = order.map((index) => S.doc.waypoints[index]);
    S.selected = null;
  });
  const saving = after !== null && before ? ` (${after.toFixed(2)} m instead of ${before.toFixed(2)} m)` : "";
  say(`waypoints put in the shortest order${saving}; undo: Ctrl+Z`);
};
async function exportLaunch() {
  const stem = (S.name || "mission").replace(/\.[^.]*$/, "");
  const path = window.prompt("Export the tutorial's launch file (p_seq / yea_seq) as:", `${stem}.launch`);
  if (!path) return;
  let answer = await api("POST", "/api/export", { mission: S.doc, path });
  if (answer.status === 409 && answer.data.conflict === "exists") {
    if (!window.confirm(`${answer.data.error}?`)) { say("not exported"); return; }
    answer = await api("POST", "/api/export", { mission: S.doc, path, overwrite: true });
  }
  if (!answer.ok) { say(answer.data.error, true); return; }
  const left = answer.data.left_out;
  say(`exported ${answer.data.path}${left.length ? `; the tutorial's format has no place for: ${left.join("; ")}` : ""}`);
}
$("import").onclick = () => openImport();
// A file dropped on the page: the studio imports only files it reads itself, by their path
// under its folders (POST /api/import takes a path, not a file's text), and the browser
// does not tell a dropped file's path. The drop opens the Import list instead (the file of
// the same name, if listed, has the focus), and the browser does not leave the page to
// show the file.
const dropsFile = (e) => e.dataTransfer && [...e.dataTransfer.types].includes("Files");
document.addEventListener("dragover", (e) => { if (dropsFile(e)) e.preventDefault(); });
document.addEventListener("drop", (e) => {
  if (!dropsFile(e)) return;
  e.preventDefault();
  const file = e.dataTransfer.files[0];
  if (!file) return;
  openImport(`${file.name} was dropped: the studio reads files only under its folders, by their path; choose it below if it is there.`, file.name);
});
$("export").onclick = exportLaunch;

// ---- past runs: replay with a time slider ------------------------------------------------
async function loadRuns() {
  const answer = await api("GET", "/api/runs");
  if (!answer.ok) return;
  const select = $("runs");
  const chosen = select.value;
  select.length = 1;
  for (const run of answer.data.runs) {
    const o = document.createElement("option");
    o.value = run.folder;
    const verdict = run.reached != null ? ` · ${run.reached}/${run.visits} reached` : run.reason ? ` · ${run.reason}` : "";
    o.textContent = `${run.folder}${run.fleet ? ` · fleet of ${run.robots} robots` : ""}${verdict}`;
    if (run.fleet) o.dataset.fleet = "true";  // replayed by fleet.js
    select.appendChild(o);
  }
  select.value = chosen;
}
$("runs-refresh").onclick = loadRuns;
$("runs").onchange = async (e) => {
  if (!e.target.value) { closeReplay(); if (FLEET.mode === "replay") closeFleet(); return; }
  if (e.target.selectedOptions[0].dataset.fleet) { closeReplay(); openFleetReplay(e.target.value); return; }
  if (FLEET.mode === "replay") closeFleet();
  const answer = await api("GET", `/api/replay?folder=${encodeURIComponent(e.target.value)}`);
  if (!answer.ok) { say(answer.data.error, true); return; }
  stopReplayPlay();
  S.replay = answer.data;
  S.replay.markedAt = undefined;
  $("replay").hidden = false;
  $("map").classList.add("replaying");
  const slider = $("replay-time");
  slider.max = String(S.replay.duration_s);
  slider.value = "0";
  drawReplay(0);
  say(`replaying ${S.replay.folder}${S.replay.finish_reason ? ` (${S.replay.finish_reason})` : ""}`);
};
$("replay-time").oninput = (e) => drawReplay(Number(e.target.value));
$("replay-close").onclick = () => { $("runs").value = ""; closeReplay(); };
$("replay-play").onclick = () => {
  if (S.replayTimer) { stopReplayPlay(); return; }
  const slider = $("replay-time");
  if (Number(slider.value) >= Number(slider.max)) slider.value = "0";
  let last = performance.now();
  $("replay-play").textContent = "❚❚";
  // Ten times real time: a five-minute run replays in half a minute.
  const step = (now) => {
    const t = Math.min(Number(slider.value) + ((now - last) / 1000) * 10, Number(slider.max));
    last = now;
    slider.value = String(t);
    drawReplay(t);
    if (t >= Number(slider.max)) stopReplayPlay(); else S.replayTimer = requestAnimationFrame(step);
  };
  S.replayTimer = requestAnimationFrame(step);
};
function stopReplayPlay() {
  if (S.replayTimer) cancelAnimationFrame(S.replayTimer);
  S.replayTimer = null;
  $("replay-play").textContent = "▶";
}
function closeReplay() {
  stopReplayPlay();
  S.replay = null;
  $("replay").hidden = true;
  $("map").classList.remove("replaying");
  if (S.layers.replay) { S.layers.replay.remove(); S.layers.replay = null; }
  missionLayer.draw();
}
// Index of the last item (sorted by time) at or before t, or null; key: its time field.
function lastAt(items, t, key) {
  let lo = 0, hi = items.length - 1, found = null;
  while (lo <= hi) {
    const mid = (lo + hi) >> 1;
    const at = key ? items[mid][key] : items[mid][0];
    if (at <= t) { found = mid; lo = mid + 1; } else hi = mid - 1;
  }
  return found;
}
// The waypoints' states after the si-th change (null: before the first). The server sends
// only what each change changed; going forward from the last answer costs only the new ones.
function replayStatuses(R, si) {
  let from = R.cursor && R.cursor.si !== null && si !== null && R.cursor.si <= si ? R.cursor : { si: null, statuses: [] };
  const statuses = from.statuses.slice();
  for (let k = from.si === null ? 0 : from.si + 1; si !== null && k <= si; k++) {
    const change = R.states[k];
    if (change.reset) statuses.length = 0;
    for (const [i, status] of change.changes) statuses[i] = status;
  }
  R.cursor = { si, statuses };
  return statuses;
}
// The replayed mission's waypoints, painted again only when their states change (not at
// every frame): the canvas draws them in their states (missionLayer.drawReplayed).
function drawReplayMarks(R, statuses, si) {
  R.markedAt = si;
  missionLayer.draw();
}
// The run at time t: waypoint states, driven path so far, plan of the current leg, robot.
function drawReplay(t) {
  const R = S.replay;
  if (!R) return;
  if (!S.layers.replay) S.layers.replay = L.layerGroup().addTo(map);
  S.layers.replay.clearLayers();
  const si = lastAt(R.states, t, "t");
  const state = si === null ? { current: null, loop: 0, status: "starting" } : R.states[si];
  const statuses = replayStatuses(R, si);
  if (R.markedAt !== si) drawReplayMarks(R, statuses, si);
  const pi = lastAt(R.poses, t);
  if (pi !== null) {
    const trail = R.poses.slice(0, pi + 1).map(([, px, py]) => ll(px, py));
    // Between two journal poses (about a second apart) the robot is drawn in between.
    let [t0, x, y, deg] = R.poses[pi];
    const next = R.poses[pi + 1];
    if (next && next[0] > t0 && t > t0) {
      const f = Math.min((t - t0) / (next[0] - t0), 1);
      x += (next[1] - x) * f; y += (next[2] - y) * f;
      let turn = next[3] - deg; turn -= 360 * Math.round(turn / 360);
      deg += turn * f;
    }
    trail.push(ll(x, y));
    if (trail.length > 1) L.polyline(trail, { color: "#16a34a", weight: 3, interactive: false }).addTo(S.layers.replay);
    const plan = R.plans[lastAt(R.plans, t, "t")];
    if (plan && plan.index === state.current && plan.points.length > 1) {
      L.polyline(plan.points.map(([px, py]) => ll(px, py)), { color: "#f97316", weight: 2, dashArray: "4 4", interactive: false }).addTo(S.layers.replay);
    }
    const yaw = (deg * Math.PI) / 180, c = Math.cos(yaw), s = Math.sin(yaw);
    const outline = R.footprint_m.map(([fx, fy]) => ll(x + c * fx - s * fy, y + s * fx + c * fy));
    const body = L.polygon(outline, { color: "#111827", weight: 2, fillColor: "#facc15", fillOpacity: 0.9, interactive: false, pane: "run" }).addTo(S.layers.replay);
    body.getElement().dataset.testid = "replay-robot";
  }
  const at = state.current !== null && state.current !== undefined ? ` · waypoint ${state.current + 1} ${statuses[state.current] || "pending"}` : "";
  $("replay-clock").textContent = `${t.toFixed(1)} / ${R.duration_s.toFixed(1)} s${at}`;
}

// ---- running -----------------------------------------------------------------------------
// The visible status holds the clock (20 updates a second); the live region, read out by
// screen readers, says only what changed: the status and the waypoint driven to.
function setStatus(status, text, spoken) {
  const el = $("run-status");
  el.dataset.status = status;
  el.textContent = text;
  const live = $("run-live");
  const task = runTaskWords(S.run && !S.run.done ? S.run : null);
  const words = (spoken ?? text) + (task ? ` · ${task}` : "");
  if (live.textContent !== words) live.textContent = words;
}
$("run").onclick = async () => {
  const speed = $("speed").value;
  const answer = await api("POST", "/api/run", { mission: S.doc, realtime: speed ? Number(speed) : null,
    simulate_tasks: $("simulate-tasks").checked });
  if (!answer.ok) {
    if (answer.data.problems) { S.problems = answer.data.problems; render(); }
    setStatus("error", "not started"); say(answer.data.error, true); return;
  }
  say(`running; outputs in ${answer.data.folder}`);
  $("report").hidden = true;
  setStatus("starting", "starting");
  watchRun();
};
$("stop").onclick = () => api("POST", "/api/run/stop");
$("skip").onclick = () => api("POST", "/api/run/skip");
$("pause").onclick = () => api("POST", S.run && S.run.status === "paused" ? "/api/run/resume" : "/api/run/pause");

function watchRun() {
  if (S.events) S.events.close();
  S.events = new EventSource("/api/run/events");
  S.events.onmessage = (e) => {
    const run = JSON.parse(e.data);
    run.done = ["completed", "failed", "stopped", "error"].includes(run.status);
    const before = S.run ? S.run.waypoints : null;
    S.run = run;
    S.runUpdates = (S.runUpdates || 0) + 1;  // counted for benchmarks/bench_studio.py
    drawRun(run, before);
    showRunTask(run);
    if (run.report && !run.done) showReport(run);  // written before the picture: shown now
    if (run.done) { S.events.close(); S.events = null; }
  };
  S.events.onerror = () => { if (S.events && S.run && S.run.done) S.events.close(); };
}
// Only what changed: the rows in sight whose state changed (rebuilding the list at every
// update, 20 a second, would stall the page on a mission of thousands of waypoints), and
// the canvas once when a waypoint's state changed (its colour).
function updateRowStates(states, before) {
  if (!before || before.length !== states.length) { renderList(); missionLayer.draw(); return; }
  let changes = false;
  for (let i = 0; i < states.length; i++) if (before[i] !== states[i]) { changes = true; break; }
  if (!changes) return;
  for (const row of $("waypoints").children) {
    const i = Number(row.dataset.index);
    const cell = row.querySelector(".state");
    if (cell && cell.textContent !== (states[i] || "")) cell.textContent = states[i] || "";
  }
  missionLayer.draw();
}
function drawRun(run, before) {
  if (!S.layers.run) S.layers.run = L.layerGroup().addTo(map);
  S.layers.run.clearLayers();
  if (run.trail.length > 1) L.polyline(run.trail.map(([x, y]) => ll(x, y)), { color: "#16a34a", weight: 3, interactive: false }).addTo(S.layers.run);
  if (run.plan.length > 1) L.polyline(run.plan.map(([x, y]) => ll(x, y)), { color: "#f97316", weight: 2, dashArray: "4 4", interactive: false }).addTo(S.layers.run);
  if (run.pose) {
    const { x_m: x, y_m: y, yaw_deg: deg } = run.pose;
    const yaw = (deg * Math.PI) / 180, c = Math.cos(yaw), s = Math.sin(yaw);
    const outline = run.footprint_m.map(([fx, fy]) => ll(x + c * fx - s * fy, y + s * fx + c * fy));
    const body = L.polygon(outline, { color: "#111827", weight: 2, fillColor: "#facc15", fillOpacity: 0.9, interactive: false, pane: "run" }).addTo(S.layers.run);
    body.getElement().dataset.testid = "robot";
    L.polyline([ll(x, y), ll(x + 0.25 * c, y + 0.25 * s)], { color: "#111827", weight: 2, interactive: false, pane: "run" }).addTo(S.layers.run);
  }
  const busy = !run.done;
  $("stop").disabled = !busy; $("skip").disabled = !busy; $("pause").disabled = !busy;
  $("pause").textContent = run.status === "paused" ? "Resume" : "Pause";
  $("run").disabled = busy;
  const at = run.current !== null ? ` · waypoint ${run.current + 1} ${run.waypoints[run.current]}` : "";
  const loop = run.loop ? ` · loop ${run.loop + 1}` : "";
  const eta = busy && run.eta_s != null ? ` · ends in ~${Math.round(run.eta_s)} s` : "";
  let text = `${run.status} · ${run.clock_s.toFixed(1)} s${at}${loop}${eta}`;
  if (run.done && run.report) text = `${run.status} · ${run.report.totals.reached}/${run.report.totals.visits} reached · ${run.report.totals.duration_s} s`;
  if (run.error) text += ` · ${run.error}`;
  setStatus(run.status, text, run.done ? text : `${run.status}${at}${loop}`);
  updateRowStates(run.waypoints, before);
  if (run.done) { showReport(run); say(`${run.status}; outputs in ${run.folder}`, run.status === "error"); loadRuns(); }
}
// The report as soon as the run wrote it (the picture is drawn after it), scrolled into
// view once per run; each visit's tasks on lines of their own under it.
function showReport(run) {
  const r = run.report;
  const key = `${run.folder}|${run.done}`;
  if (S.reportShown === key) return;  // the same report again (20 updates a second)
  S.reportShown = key;
  $("report").hidden = false;
  const body = $("report-body");
  body.textContent = "";
  const note = document.createElement("div");
  note.textContent = `${run.reason || run.status}; folder ${run.folder}${run.done ? "" : " (drawing the picture…)"}`;
  body.appendChild(note);
  if (r) body.appendChild(reportTable(r));
  if (S.reportScrolled !== run.folder) {  // once the table is there: all of it in view
    S.reportScrolled = run.folder;
    $("report").scrollIntoView({ block: "start" });
  }
}
function reportTable(r) {
  const table = document.createElement("table");
  table.innerHTML = "<thead><tr><th>#</th><th>name</th><th>outcome</th><th>tries</th><th>time [s]</th><th>dist [m]</th></tr></thead><tbody></tbody>";
  const tbody = table.querySelector("tbody");
  for (const v of r.visits) {
    const tr = document.createElement("tr");
    for (const [value, numeric] of [[v.number, true], [v.name || "", false], [v.outcome + (v.passed_through ? " (through)" : ""), false],
      [v.attempts.length, true], [v.duration_s, true], [v.distance_m, true]]) {
      const td = document.createElement("td");
      td.textContent = value; if (numeric) td.className = "n";
      tr.appendChild(td);
    }
    tbody.appendChild(tr);
    for (const t of v.tasks || []) tbody.appendChild(reportTaskRow(t));
  }
  const t = r.totals;
  const tr = document.createElement("tr");
  tr.innerHTML = `<th></th><th>total</th><th>${t.reached} reached</th><th></th><th class="n">${t.duration_s}</th><th class="n">${t.distance_m}</th>`;
  tbody.appendChild(tr);
  return table;
}

function reportTaskRow(t) {
  const tr = document.createElement("tr");
  tr.className = `task-row ${t.outcome}`;
  tr.dataset.testid = "report-task";
  const more = [t.detail, t.files && t.files.length ? `files: ${t.files.join(", ")}` : ""].filter(Boolean).join(" · ");
  const cells = [["", false], [`↳ task ${t.number}: ${t.kind}${more ? ` · ${more}` : ""}`, false], [t.outcome, false],
    [t.attempt, true], [t.duration_s, true], ["", false]];
  for (const [value, numeric] of cells) {
    const td = document.createElement("td");
    td.textContent = value ?? ""; if (numeric) td.className = "n";
    tr.appendChild(td);
  }
  return tr;
}
// The task the run is at ("waypoint 3: input — Load the tray"), for the status line and
// the live region; "" when none runs.
function runTaskWords(run) {
  const t = run && run.task;
  if (!t) return "";
  const where = `waypoint ${t.index + 1}`;
  if (t.kind === "input") {
    const prompt = t.description.replace(/^input: /, "");
    return `${where}: input — ${prompt}${t.asks && !t.answered ? " (Confirm or Refuse)" : ""}`;
  }
  return `${where}: ${t.description}`;
}
// The task shown beside the status, Confirm / Refuse while an input task waits, and how
// the last task ended once it did.
function showRunTask(run) {
  const el = $("run-task");
  const t = run.done ? null : run.task;
  const waiting = !!(t && t.asks && !t.answered);
  let text = t ? runTaskWords(run) : "";
  const last = run.last_task;
  if (!t && last && !run.done && last.index === run.current) {
    text = `waypoint ${last.index + 1}: ${last.kind} ${last.outcome}${last.detail ? ` (${last.detail})` : ""}`;
  }
  el.hidden = !text;
  if (el.textContent !== text) el.textContent = text;
  el.dataset.asks = String(waiting);
  $("task-confirm").hidden = !waiting;
  $("task-refuse").hidden = !waiting;
}
async function answerTask(confirmed) {
  $("task-confirm").hidden = true; $("task-refuse").hidden = true;  // one answer
  const answer = await api("POST", "/api/run/confirm", { confirmed });
  if (!answer.ok) say(answer.data.message || answer.data.error, true);
  else say(answer.data.message);
}
$("task-confirm").onclick = () => answerTask(true);
$("task-refuse").onclick = () => answerTask(false);

// ---- start -------------------------------------------------------------------------------
async function main() {
  const answer = await api("GET", "/api/mission");
  if (!answer.ok) {
    say(answer.data.error, true);
    (answer.data.problems || []).forEach((p) => say(`${answer.data.error}: ${p.text}`, true));
    return;
  }
  S.doc = answer.data.mission;
  S.saved = JSON.stringify(S.doc);
  S.version = answer.data.version;
  S.units = answer.data.units;
  S.name = answer.data.name;
  S.exists = answer.data.exists;
  S.problems = answer.data.problems;
  S.allowRun = answer.data.allow_run;
  if (!S.allowRun) $("run").title = "run: tasks need the studio started with --allow-run";
  $("mission-name").textContent = answer.data.path || S.name;
  if (!Array.isArray(S.doc.waypoints)) S.doc.waypoints = [];
  // The page is ready (map drawn, markers placed, the file's own problems listed)
  // without waiting for the first check (pre-flight problems and every leg planned: a
  // second or more on a big map). That check goes out once the page is painted: worked
  // on beside the first paint, it took the cores the browser draws with (the studio's
  // warm-up waits for it too).
  S.painted = loadMap(true).then(() => {
    render();
    document.body.dataset.ready = "true";
  });
  await S.painted;
  await check();
  loadRuns();
}
main();
