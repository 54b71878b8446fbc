// navseq studio page: plain JS over Leaflet (CRS.Simple: lat = y, lng = x, in metres).
// The mission is the navseq document the API returns (docs/studio.md); every rule about
// it (validation, pre-flight, plans, writing) is the server's: this file only draws and
// sends edits.
"use strict";

const S = {
  doc: null, version: null, name: "", units: {},
  problems: [], legs: [], route: {}, selected: null,
  undo: [], redo: [], checkSeq: 0, checkBusy: false, checkAgain: false,
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
  ["clear_costmaps_on_retry", ["", "true", "false"]], ["on_failure", ["", "stop", "skip", "retry"]],
  ["pass_through", "number"], ["dwell", "number"], ["xy_tolerance", "number"], ["yaw_tolerance", "number"],
];
const $ = (id) => document.getElementById(id);
// The point the selection and the yaw handle are about: a waypoint, or the start pose.
const selectedPoint = () => (S.selected === "start" ? S.doc.start : S.selected !== null ? S.doc.waypoints[S.selected] : null);

// ---- API -------------------------------------------------------------------------------
async function api(method, path, body) {
  const response = await fetch(path, {
    method, headers: body ? { "content-type": "application/json" } : {},
    body: body ? JSON.stringify(body) : undefined, credentials: "same-origin",
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
function changed() { render(); check(); }
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
  // The focus goes to the row (or the marker, from a marker) that takes the removed one's
  // place, else the one before.
  const n = S.doc.waypoints.length - 1;
  const kind = (document.activeElement?.dataset?.focus || "").startsWith("marker-") ? "marker" : "row";
  S.focusNext = n > 0 ? `${kind}-${Math.min(i, n - 1)}` : null;
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
function problemsOf(i) { return S.problems.filter((p) => p.waypoint === i); }
function wpIcon(w, i, extra) {
  const yaw = typeof w.yaw === "number" ? w.yaw : 0;
  const cls = ["wp-icon", extra || ""];
  if (w.pass_through) cls.push("pass");
  if (i !== null && hasTasks(i)) cls.push("tasks");
  if (i !== null && problemsOf(i).length) cls.push("bad");
  if ((i !== null && i === S.selected) || (i === null && S.selected === "start")) cls.push("selected");
  return L.divIcon({
    className: cls.join(" "), iconSize: [26, 26], iconAnchor: [13, 13],
    html: `<div class="arrow" style="transform: rotate(${-yaw}deg)"></div><div class="dot">${i === null ? "S" : i + 1}</div>`,
  });
}
// The element with the focus is rebuilt by render (a row, a marker): the focus goes to the
// new one in its place (data-focus), as a keyboard user would lose it otherwise.
function render() {
  const focused = S.focusNext !== undefined ? S.focusNext : document.activeElement?.dataset?.focus;
  S.focusNext = undefined;
  renderAll();
  if (!focused) return;
  const el = document.querySelector(`[data-focus="${focused}"]`);
  if (el && el !== document.activeElement) el.focus({ preventScroll: true });
}
// Enter or Space on a focused marker selects it, as a click does.
function keySelects(marker, select) {
  marker.getElement().addEventListener("keydown", (e) => {
    if (e.key !== "Enter" && e.key !== " ") return;
    e.preventDefault();
    e.stopPropagation();
    select();
  });
}
function renderAll() {
  S.layers.markers.forEach((m) => m.remove());
  S.layers.markers = [];
  if (S.layers.start) S.layers.start.remove();
  S.layers.start = null;
  const start = S.doc.start;
  if (okPoint(start)) {
    S.layers.start = L.marker(ll(start.x, start.y), { icon: wpIcon(start, null, "start"), draggable: true,
      title: "start pose", zIndexOffset: -100 }).addTo(map);
    S.layers.start.getElement().dataset.testid = "start-marker";
    S.layers.start.getElement().dataset.focus = "marker-start";
    S.layers.start.getElement().setAttribute("aria-label", `start pose${S.selected === "start" ? ", selected" : ""}`);
    keySelects(S.layers.start, () => { S.selected = "start"; render(); });
    S.layers.start.on("dragstart", () => { S.selected = "start"; drawHandle(); });
    S.layers.start.on("drag", (e) => { const p = e.target.getLatLng(); moveHandle(p.lng, p.lat, start.yaw || 0); });
    S.layers.start.on("dragend", (e) => {
      const p = e.target.getLatLng();
      edit(() => { S.doc.start.x = round(p.lng, 2); S.doc.start.y = round(p.lat, 2); });
    });
    S.layers.start.on("click", (e) => { L.DomEvent.stopPropagation(e); S.selected = "start"; render(); });
  }
  S.doc.waypoints.forEach((w, i) => {
    if (!okPoint(w)) return;
    const m = L.marker(ll(w.x, w.y), { icon: wpIcon(w, i), draggable: true, title: w.name || `waypoint ${i + 1}` });
    m.addTo(map);
    const el = m.getElement();
    el.dataset.testid = "waypoint-marker";
    el.dataset.index = String(i);
    el.dataset.focus = `marker-${i}`;
    el.setAttribute("aria-label", `waypoint ${i + 1}${w.name ? ` ${w.name}` : ""}${i === S.selected ? ", selected" : ""}`);
    keySelects(m, () => { S.selected = i; render(); });
    m.on("click", (e) => { L.DomEvent.stopPropagation(e); S.selected = i; render(); });
    m.on("dragstart", () => { S.selected = i; drawHandle(); });
    m.on("drag", (e) => { const p = e.target.getLatLng(); moveHandle(p.lng, p.lat, w.yaw || 0); });
    m.on("dragend", (e) => {
      const p = e.target.getLatLng();
      edit(() => { w.x = round(p.lng, 2); w.y = round(p.lat, 2); });
    });
    S.layers.markers.push(m);
  });
  drawLegs();
  drawHandle();
  renderList();
  renderEditor();
  renderSettings();
  renderDefaults();
  renderProblems();
  $("undo").disabled = !S.undo.length;
  $("redo").disabled = !S.redo.length;
}
function drawLegs() {
  if (S.layers.legs) S.layers.legs.remove();
  S.layers.legs = L.layerGroup().addTo(map);
  for (const leg of S.legs) {
    if (!leg.points) continue;
    const line = L.polyline(leg.points.map(([x, y]) => ll(x, y)),
      { color: leg.loop ? "#6b7280" : "#0ea5e9", weight: 3, opacity: 0.85, dashArray: leg.loop ? "6 6" : null, interactive: false });
    line.addTo(S.layers.legs);
    const mid = leg.points[Math.floor(leg.points.length / 2)];
    L.tooltip({ permanent: true, direction: "center", className: "leg-label", interactive: false })
      .setLatLng(ll(mid[0], mid[1])).setContent(`${leg.length_m.toFixed(2)} m`).addTo(S.layers.legs);
  }
}
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
    const deg = Math.round((Math.atan2(p.lat - w.y, p.lng - w.x) * 180) / Math.PI);
    const arrow = S.selected === "start" ? S.layers.start
      : S.layers.markers.find((m) => m.getElement().dataset.index === String(S.selected));
    if (arrow) arrow.getElement().querySelector(".arrow").style.transform = `rotate(${-deg}deg)`;
  });
  S.layers.handle.on("dragend", (e) => {
    const p = e.target.getLatLng();
    edit(() => { w.yaw = Math.round((Math.atan2(p.lat - w.y, p.lng - w.x) * 180) / Math.PI); });
  });
}
function moveHandle(x, y, yawDeg) {
  if (!S.layers.handle) return;
  const r = handleOffset(), yaw = (yawDeg * Math.PI) / 180;
  S.layers.handle.setLatLng(ll(x + r * Math.cos(yaw), y + r * Math.sin(yaw)));
}
map.on("zoomend", drawHandle);

function renderList() {
  const list = $("waypoints");
  list.textContent = "";
  S.doc.waypoints.forEach((w, i) => {
    const li = document.createElement("li");
    li.dataset.testid = "waypoint-row";
    li.draggable = true;
    if (i === S.selected) li.classList.add("selected");
    if (problemsOf(i).length) li.classList.add("bad");
    const state = S.run && S.run.waypoints[i] ? S.run.waypoints[i] : "";
    const xy = okPoint(w) ? `(${w.x.toFixed(2)}, ${w.y.toFixed(2)}, ${w.yaw ?? 0}°)` : "(?)";
    // The row's waypoint is a button (Tab reaches it, Enter or Space selects it); ▲ ▼ ✕
    // are named for a screen reader by what they do, not by their glyph.
    li.innerHTML = `<button type="button" class="pick"><span class="num"></span><span class="label"></span><span class="state"></span></button>
      <button type="button" class="up">▲</button><button type="button" class="down">▼</button><button type="button" class="del">✕</button>`;
    li.querySelector(".num").textContent = i + 1;
    li.querySelector(".label").textContent = `${w.name ? w.name + " " : ""}${xy}`;
    li.querySelector(".state").textContent = state;
    if (hasTasks(i)) li.querySelector(".state").before(taskFlag(i));
    const [pick, up, down, del] = li.querySelectorAll("button");
    pick.dataset.focus = `row-${i}`;
    if (i === S.selected) pick.setAttribute("aria-current", "true");
    for (const [button, part, what] of [[up, "up", "move waypoint # up"], [down, "down", "move waypoint # down"], [del, "del", "delete waypoint #"]]) {
      button.dataset.focus = `row-${i}-${part}`;
      button.setAttribute("aria-label", what.replace("#", String(i + 1)));
      button.title = what.replace(" #", "");
    }
    up.onclick = (e) => { e.stopPropagation(); moveWaypoint(i, i - 1); };
    down.onclick = (e) => { e.stopPropagation(); moveWaypoint(i, i + 1); };
    del.onclick = (e) => { e.stopPropagation(); removeWaypoint(i); };
    li.onclick = () => { S.selected = i; render(); if (okPoint(w)) map.panTo(ll(w.x, w.y)); };
    li.ondragstart = (e) => { e.dataTransfer.setData("text/plain", String(i)); };
    li.ondragover = (e) => { e.preventDefault(); li.classList.add("drop-target"); };
    li.ondragleave = () => li.classList.remove("drop-target");
    li.ondrop = (e) => { e.preventDefault(); moveWaypoint(Number(e.dataTransfer.getData("text/plain")), i); };
    list.appendChild(li);
  });
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
function renderDefaults() {
  const defaults = S.doc.defaults || {};
  fillForm($("defaults"), DEFAULT_FIELDS.map(([key, kind]) => {
    const unit = S.units[key] ? ` [${S.units[key]}]` : "";
    return { key, label: key + unit, kind, placeholder: "loader's default",
      value: typeof defaults[key] === "boolean" ? String(defaults[key]) : defaults[key],
      onChange: (text) => edit(() => {
        const d = { ...(S.doc.defaults || {}) };
        const value = key === "clear_costmaps_on_retry" && text !== "" ? text === "true" : fieldValue(kind, text);
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
  for (const p of S.problems) {
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
  $("problem-count").textContent = S.problems.length ? `(${S.problems.length})` : "";
  const save = $("save");
  save.classList.toggle("warn", S.problems.length > 0);
  save.textContent = S.problems.length ? `Save (${S.problems.length} problem${S.problems.length > 1 ? "s" : ""})` : "Save";
  const r = S.route;
  $("route").textContent = r.total_length_m != null
    ? `${S.doc.waypoints.length} waypoints · ${r.total_length_m.toFixed(2)} m · ${r.estimated_duration}`
    : `${S.doc.waypoints.length} waypoints${!S.planned ? " · checking and planning…" : r.unplanned_legs ? " · some legs have no path" : ""}`;
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
async function check() {
  if (S.checkBusy) { S.checkAgain = true; return; }
  S.checkBusy = true;
  const seq = ++S.checkSeq;
  const sent = JSON.parse(JSON.stringify(S.doc));
  const answer = await api("POST", "/api/check", { mission: sent });
  S.checkBusy = false;
  if (S.checkAgain) { S.checkAgain = false; check(); return; }
  if (seq !== S.checkSeq) return;
  if (!answer.ok) {
    S.problems = answer.data.problems || [{ text: answer.data.error, waypoint: null }];
    S.legs = []; S.route = {};
  } else {
    S.problems = answer.data.problems;
    S.legs = answer.data.legs;
    S.route = answer.data;
  }
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
  say(`imported ${imported.waypoints.length} waypoints from ${answer.data.path} (undo: Ctrl+Z); save to keep them`);
}
// ---- shortest order ----------------------------------------------------------------------
$("order").onchange = async (e) => {
  const choice = e.target.value;
  e.target.value = "";
  if (!choice || (S.run && !S.run.done) || S.replay) return;
  say("finding the shortest order…");
  const answer = await api("POST", "/api/order", { mission: S.doc, keep_last: choice === "keep-last" });
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
    o.textContent = `${run.folder}${verdict}`;
    select.appendChild(o);
  }
  select.value = chosen;
}
$("runs-refresh").onclick = loadRuns;
$("runs").onchange = async (e) => {
  if (!e.target.value) { closeReplay(); return; }
  const answer = await api("GET", `/api/replay?folder=${encodeURIComponent(e.target.value)}`);
  if (!answer.ok) { say(answer.data.error, true); return; }
  stopReplayPlay();
  S.replay = answer.data;
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
  if (S.layers.replayMarks) { S.layers.replayMarks.remove(); S.layers.replayMarks = null; }
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
// The waypoint markers, redrawn only when their states change (not at every frame).
function drawReplayMarks(R, statuses, si) {
  if (!S.layers.replayMarks) S.layers.replayMarks = L.layerGroup().addTo(map);
  S.layers.replayMarks.clearLayers();
  R.markedAt = si;
  const wps = (R.mission || {}).waypoints || [];
  wps.forEach((w, i) => {
    if (!okPoint(w)) return;
    const status = statuses[i] || "pending";
    const icon = L.divIcon({ className: `wp-icon replay ${status}`, iconSize: [26, 26], iconAnchor: [13, 13],
      html: `<div class="arrow" style="transform: rotate(${-(w.yaw || 0)}deg)"></div><div class="dot">${i + 1}</div>` });
    const m = L.marker(ll(w.x, w.y), { icon, interactive: false }).addTo(S.layers.replayMarks);
    m.getElement().dataset.testid = "replay-waypoint";
    m.getElement().dataset.status = status;
  });
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
  if (R.markedAt !== si || !S.layers.replayMarks) drawReplayMarks(R, statuses, si);
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
    const body = L.polygon(outline, { color: "#111827", weight: 2, fillColor: "#facc15", fillOpacity: 0.9, interactive: false }).addTo(S.layers.replay);
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
    drawRun(run, before);
    showRunTask(run);
    if (run.report && !run.done) showReport(run);  // written before the picture: shown now
    if (run.done) { S.events.close(); S.events = null; }
  };
  S.events.onerror = () => { if (S.events && S.run && S.run.done) S.events.close(); };
}
// Only the rows whose state changed: rebuilding the whole list at every update (20 a
// second) would stall the page on a mission of thousands of waypoints.
function updateRowStates(states, before) {
  const rows = $("waypoints").children;
  if (!before || rows.length !== S.doc.waypoints.length) { renderList(); return; }
  states.forEach((state, i) => {
    if (before[i] === state) return;
    const cell = rows[i] && rows[i].querySelector(".state");
    if (cell) cell.textContent = state || "";
  });
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
    const body = L.polygon(outline, { color: "#111827", weight: 2, fillColor: "#facc15", fillOpacity: 0.9, interactive: false }).addTo(S.layers.run);
    body.getElement().dataset.testid = "robot";
    L.polyline([ll(x, y), ll(x + 0.25 * c, y + 0.25 * s)], { color: "#111827", weight: 2, interactive: false }).addTo(S.layers.run);
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
  // The first check (pre-flight problems and every leg planned: a second or more on a
  // big map) goes out now and is worked on while the map is drawn; the page is ready
  // (map drawn, markers placed, the file's own problems listed) without waiting for it.
  S.painted = loadMap(true).then(() => {
    render();
    document.body.dataset.ready = "true";
  });
  await Promise.all([S.painted, check()]);
  loadRuns();
}
main();
