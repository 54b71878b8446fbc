// navseq studio: a fleet's robots on the map, live (a fleet run started here) and in
// replay (a fleet run folder). Loaded after studio.js, whose helpers it uses ($, api, say,
// map, ll, lastAt, replayStatuses). Every robot keeps the colour fleet.png gives it; the
// panel beside the map says, as text, each robot's waypoint, state and counts.
"use strict";

const FLEET = {
  mode: null,        // null, "live" or "replay"
  data: null,        // the live snapshot, or the replay's answer
  events: null,      // the live run's EventSource
  timer: null,       // the replay's animation frame
  layer: null,       // the robots, trails, plans and waypoints
  mapLayer: null,    // the fleet's map, when it is not the opened mission's
  drawn: { t: null, robots: [] },
  updates: 0,        // live snapshots drawn (benchmarks, tests)
};
map.createPane("fleetmap").style.zIndex = 452;  // over the mission's canvas (450)
map.createPane("fleet").style.zIndex = 455;     // under the single run's robot (460)
const FLEET_ENDED = ["completed", "failed", "stopped", "error"];

// ---- the fleet files and the live run ----------------------------------------------------
async function loadFleets() {
  const answer = await api("GET", "/api/fleets");
  if (!answer.ok) return false;
  const select = $("fleet-file");
  const chosen = select.value || answer.data.chosen || "";
  select.length = 1;
  for (const path of answer.data.fleets) {
    const o = document.createElement("option");
    o.value = path; o.textContent = path;
    select.appendChild(o);
  }
  select.value = answer.data.fleets.includes(chosen) ? chosen : "";
  fleetButtons();
  return answer.data.running;
}
function fleetButtons() {
  const live = FLEET.mode === "live" && FLEET.data && !FLEET_ENDED.includes(FLEET.data.status);
  $("fleet-run").disabled = live || !$("fleet-file").value;
  $("fleet-stop").disabled = !live;
}
$("fleet-file").onchange = fleetButtons;
$("fleet-run").onclick = async () => {
  const speed = $("speed").value;
  $("fleet-run").disabled = true;
  fleetSay("planning the split and checking every robot…");
  const answer = await api("POST", "/api/fleet/run", { fleet: $("fleet-file").value, realtime: speed ? Number(speed) : null });
  if (!answer.ok) {
    const problems = (answer.data.problems || []).map((p) => p.text);
    fleetSay([answer.data.error, ...problems].join(" · "), true);
    fleetButtons();
    return;
  }
  fleetSay("");
  say(`fleet running; outputs in ${answer.data.folder}`);
  openFleet("live", null);
  watchFleet();
};
$("fleet-stop").onclick = () => api("POST", "/api/fleet/run/stop");
function watchFleet() {
  if (FLEET.events) FLEET.events.close();
  FLEET.events = new EventSource("/api/fleet/run/events");
  FLEET.events.onmessage = (e) => {
    const run = JSON.parse(e.data);
    if (FLEET.mode !== "live") return;
    FLEET.data = run;
    FLEET.updates += 1;
    drawFleetLive(run);
    if (FLEET_ENDED.includes(run.status)) {
      FLEET.events.close(); FLEET.events = null;
      say(`fleet ${run.status}; outputs in ${run.folder}`, run.status === "error");
      loadRuns();
    }
    fleetButtons();
  };
  FLEET.events.onerror = () => { if (FLEET.events && FLEET.data && FLEET_ENDED.includes(FLEET.data.status)) FLEET.events.close(); };
}
function drawFleetLive(run) {
  const robots = run.robots.map((r) => ({
    name: r.name, colour: r.colour, state: r.state,
    current: r.current, label: r.current !== null ? r.waypoint_labels[r.current] || "" : "", statuses: r.waypoint_states,
    points: r.waypoint_points, reached: r.reached, skipped: r.skipped, failed: r.failed, of: r.waypoints,
    trail: r.trail, head: null, pose: r.pose ? [r.pose.x_m, r.pose.y_m, r.pose.yaw_deg] : null,
    footprint: r.footprint_m, plan: r.plan,
  }));
  drawFleet(robots, run.clock_s);
  const eta = run.eta_s != null ? ` · done in ~${Math.round(run.eta_s)} s` : "";
  const overlaps = run.robot_overlaps ? ` · ${run.robot_overlaps} footprint overlaps` : "";
  const head = `fleet ${run.status} · t = ${run.clock_s.toFixed(1)} s`;
  const tail = `${run.reached} reached, ${run.skipped} skipped, ${run.failed} failed of ${run.waypoints} · makespan so far ${run.makespan_s.toFixed(1)} s (planned ${run.planned_makespan_s.toFixed(0)} s)${eta}${overlaps}`;
  fleetTotals(`${head} · ${tail}${run.error ? ` · ${run.error}` : ""}`, `fleet ${run.status} · ${run.reached} reached, ${run.skipped} skipped, ${run.failed} failed of ${run.waypoints}`, robots);
}

// ---- a past fleet run --------------------------------------------------------------------
async function openFleetReplay(folder) {
  const answer = await api("GET", `/api/fleet/replay?folder=${encodeURIComponent(folder)}`);
  if (!answer.ok) { say(answer.data.error, true); return; }
  openFleet("replay", answer.data);
  const slider = $("fleet-time");
  slider.max = String(answer.data.duration_s);
  slider.value = "0";
  drawFleetReplay(0);
  say(`replaying the fleet run ${answer.data.folder}`);
}
$("fleet-time").oninput = (e) => drawFleetReplay(Number(e.target.value));
$("fleet-play").onclick = () => {
  if (FLEET.timer) { stopFleetPlay(); return; }
  const slider = $("fleet-time");
  if (Number(slider.value) >= Number(slider.max)) slider.value = "0";
  let last = performance.now();
  $("fleet-play").textContent = "❚❚";
  $("fleet-play").setAttribute("aria-label", "pause the fleet replay");
  // Ten times real time, as the single run's replay.
  const step = (now) => {
    const t = Math.min(Number(slider.value) + ((now - last) / 1000) * 10, Number(slider.max));
    last = now;
    slider.value = String(t);
    drawFleetReplay(t);
    if (t >= Number(slider.max)) stopFleetPlay(); else FLEET.timer = requestAnimationFrame(step);
  };
  FLEET.timer = requestAnimationFrame(step);
};
function stopFleetPlay() {
  if (FLEET.timer) cancelAnimationFrame(FLEET.timer);
  FLEET.timer = null;
  $("fleet-play").textContent = "▶";
  $("fleet-play").setAttribute("aria-label", "play the fleet replay");
}
// One robot of the replay at time t: its states, the journaled poses so far, and the
// robot drawn between the last one and the next (as the single run's replay draws it).
function replayedRobot(robot, t) {
  const R = robot.replay;
  const row = robot.report || {};
  const base = { name: robot.name, colour: robot.colour, trail: [], head: null, pose: null, plan: [], footprint: [] };
  if (!R) {
    const parked = robot.parked;  // no share: where the fleet file put it, all along
    return { ...base, state: "idle", current: null, label: "", statuses: [], points: [], reached: 0, skipped: 0, failed: 0, of: row.waypoints || 0,
      pose: parked ? parked.pose : null, footprint: parked ? parked.footprint_m : [] };
  }
  const wps = (R.mission || {}).waypoints || [];
  const si = lastAt(R.states, t, "t");
  const state = si === null ? { current: null, status: "waiting" } : R.states[si];
  const statuses = replayStatuses(R, si);
  const count = (what) => statuses.filter((s) => s === what).length;
  const current = state.current ?? null;
  let shown = current !== null ? statuses[current] || "pending" : state.status;
  if (shown === "finishing" || shown === "completed") shown = "done";
  const pi = lastAt(R.poses, t);
  let trail = [], head = null, pose = null;
  if (pi !== null) {
    trail = R.poses.slice(0, pi + 1).map(([, x, y]) => [x, y]);
    let [t0, x, y, deg] = R.poses[pi];
    const next = R.poses[pi + 1];
    if (next && next[0] > t0 && t > t0) {
      const f = Math.min((t - t0) / (next[0] - t0), 1);
      x += (next[1] - x) * f; y += (next[2] - y) * f;
      let turn = next[3] - deg; turn -= 360 * Math.round(turn / 360);
      deg += turn * f;
    }
    head = [x, y]; pose = [x, y, deg];
  }
  const plan = R.plans[lastAt(R.plans, t, "t")];
  const label = current !== null && wps[current] ? wps[current].name || "" : "";
  return {
    ...base, state: shown, current, label, statuses, points: wps.map((w) => [w.x, w.y]),
    reached: count("reached"), skipped: count("skipped"), failed: count("failed") + count("stopped"), of: wps.length || row.waypoints || 0,
    trail, head, pose, footprint: R.footprint_m,
    plan: plan && plan.index === current ? plan.points : [],
  };
}
function drawFleetReplay(t) {
  const D = FLEET.data;
  if (FLEET.mode !== "replay" || !D) return;
  const robots = D.robots.map((robot) => replayedRobot(robot, t));
  drawFleet(robots, t);
  const sum = (key) => robots.reduce((n, r) => n + r[key], 0);
  const totals = `${sum("reached")} reached, ${sum("skipped")} skipped, ${sum("failed")} failed of ${sum("of")}`;
  $("fleet-clock").textContent = `${t.toFixed(1)} / ${D.duration_s.toFixed(1)} s`;
  const end = t >= D.duration_s && D.report ? ` · makespan ${D.report.makespan_s} s` : "";
  fleetTotals(`replay ${D.folder} · t = ${t.toFixed(1)} s · ${totals}${end}`, `fleet replay · ${totals}`, robots);
}

// ---- both: the map and the panel ---------------------------------------------------------
function openFleet(mode, data) {
  if (typeof closeReplay === "function" && S.replay) { $("runs").value = ""; closeReplay(); }
  stopFleetPlay();
  if (FLEET.events && mode !== "live") { FLEET.events.close(); FLEET.events = null; }
  FLEET.mode = mode;
  FLEET.data = data;
  $("fleet-replay").hidden = mode !== "replay";
  $("fleet-close").hidden = false;
  $("fleet-robots").hidden = false;
  $("map").classList.add("fleet-view");
  fleetMap(mode === "replay" && data ? data.map : null);
}
function closeFleet() {
  stopFleetPlay();
  if (FLEET.events && FLEET.data && !FLEET_ENDED.includes(FLEET.data.status)) {
    fleetSay("the fleet is running: Stop it first", true);
    return;
  }
  if (FLEET.events) { FLEET.events.close(); FLEET.events = null; }
  FLEET.mode = null; FLEET.data = null;
  FLEET.drawn = { t: null, robots: [] };
  $("fleet-replay").hidden = true;
  $("fleet-close").hidden = true;
  $("fleet-robots").hidden = true;
  $("fleet-totals").textContent = "";
  $("map").classList.remove("fleet-view");
  if (FLEET.layer) { FLEET.layer.remove(); FLEET.layer = null; }
  fleetMap(null);
  fleetButtons();
}
$("fleet-close").onclick = () => {
  closeFleet();
  if ($("runs").selectedOptions[0] && $("runs").selectedOptions[0].dataset.fleet) $("runs").value = "";
};
// The fleet's own map under its robots, when the opened mission is on another one.
async function fleetMap(mapText) {
  if (FLEET.mapLayer) { FLEET.mapLayer.remove(); FLEET.mapLayer = null; }
  if (!mapText || mapText === ((S.doc || {}).map || "")) return;
  const query = `?map=${encodeURIComponent(mapText)}`;
  const info = await api("GET", `/api/map${query}`);
  if (!info.ok || FLEET.mode === null) return;
  const b = info.data.bounds_m;
  FLEET.mapLayer = L.imageOverlay(`/api/map/image${query}&layer=map`, L.latLngBounds(ll(b.xmin, b.ymin), ll(b.xmax, b.ymax)), { pane: "fleetmap" }).addTo(map);
}
function fleetSay(text, error) {
  const el = $("fleet-note");
  el.textContent = text;
  el.className = error ? "note error" : "note";
}
// Each robot in its colour: its waypoints (filled where reached, hollow while pending,
// dashed where skipped, failed or stopped), the path driven, its current plan, its body.
function drawFleet(robots, t) {
  if (!FLEET.layer) FLEET.layer = L.layerGroup().addTo(map);
  FLEET.layer.clearLayers();
  const opts = { interactive: false, pane: "fleet" };
  for (const r of robots) {
    const line = r.head ? [...r.trail, r.head] : r.trail;
    if (line.length > 1) L.polyline(line.map(([x, y]) => ll(x, y)), { ...opts, color: r.colour, weight: 3 }).addTo(FLEET.layer);
    if (r.plan && r.plan.length > 1) L.polyline(r.plan.map(([x, y]) => ll(x, y)), { ...opts, color: r.colour, weight: 2, dashArray: "4 4", opacity: 0.8 }).addTo(FLEET.layer);
    r.points.forEach(([x, y], i) => {
      const s = r.statuses[i] || "pending";
      const reached = s === "reached", missed = ["failed", "skipped", "stopped"].includes(s);
      L.circleMarker(ll(x, y), { ...opts, radius: s === "driving" || s === "dwelling" ? 8 : 6, color: s === "driving" ? "#111827" : r.colour,
        weight: 2, fillColor: r.colour, fillOpacity: reached ? 0.9 : s === "driving" ? 0.5 : 0, dashArray: missed ? "2 3" : null }).addTo(FLEET.layer);
    });
    if (r.pose && r.footprint.length) {
      const [x, y, deg] = r.pose, yaw = (deg * Math.PI) / 180, c = Math.cos(yaw), s = Math.sin(yaw);
      const outline = r.footprint.map(([fx, fy]) => ll(x + c * fx - s * fy, y + s * fx + c * fy));
      const body = L.polygon(outline, { ...opts, color: "#111827", weight: 2, fillColor: r.colour, fillOpacity: 0.95 }).addTo(FLEET.layer);
      body.getElement().dataset.testid = "fleet-robot";
      body.getElement().dataset.robot = r.name;
      L.polyline([ll(x, y), ll(x + 0.25 * c, y + 0.25 * s)], { ...opts, color: "#111827", weight: 2 }).addTo(FLEET.layer);
    }
  }
  FLEET.drawn = { t, robots: robots.map((r) => ({ name: r.name, colour: r.colour, state: r.state, current: r.current,
    statuses: r.statuses.slice(), trail: r.trail, head: r.head, pose: r.pose })) };
}
// The panel: a row per robot (its name a button that shows it on the map), the fleet's
// totals; the live region says what changed (states and waypoints), not the clock.
function fleetTotals(text, spoken, robots) {
  $("fleet-totals").textContent = text;
  const tbody = $("fleet-robots").querySelector("tbody");
  while (tbody.children.length > robots.length) tbody.lastChild.remove();
  robots.forEach((r, k) => {
    let tr = tbody.children[k];
    if (!tr || tr.dataset.robot !== r.name) {
      tr = fleetRow(r);
      if (tbody.children[k]) tbody.replaceChild(tr, tbody.children[k]); else tbody.appendChild(tr);
    }
    const at = r.current !== null && r.current !== undefined ? `${r.current + 1}${r.label ? ` ${r.label}` : ""}` : "—";
    const cells = [at, r.state, r.reached, r.skipped, r.failed, r.of];
    cells.forEach((value, i) => {
      const td = tr.children[i + 1];
      if (td.textContent !== String(value)) td.textContent = String(value);
    });
  });
  const words = [spoken, ...robots.map((r) => `${r.name} ${r.state}${r.current !== null && r.current !== undefined ? ` at waypoint ${r.current + 1}` : ""}`)].join("; ");
  const live = $("fleet-live");
  if (live.textContent !== words) live.textContent = words;
}
function fleetRow(r) {
  const tr = document.createElement("tr");
  tr.dataset.robot = r.name;
  tr.dataset.testid = "fleet-robot-row";
  const th = document.createElement("th");
  th.scope = "row";
  const button = document.createElement("button");
  button.type = "button";
  button.className = "robot-name";
  button.title = `show ${r.name} on the map`;
  const swatch = document.createElement("span");
  swatch.className = "swatch";
  swatch.style.background = r.colour;
  swatch.setAttribute("aria-hidden", "true");
  button.append(swatch, document.createTextNode(r.name));
  button.onclick = () => {
    const robot = FLEET.drawn.robots.find((d) => d.name === r.name);
    if (robot && robot.pose) map.panTo(ll(robot.pose[0], robot.pose[1]));
  };
  th.appendChild(button);
  tr.appendChild(th);
  for (let i = 0; i < 6; i++) {
    const td = document.createElement("td");
    if (i >= 2) td.className = "n";
    tr.appendChild(td);
  }
  return tr;
}
// What the fleet view drew last, for tests: per robot its trail (journaled or reported
// poses), the robot's head and pose, its waypoints' states.
function fleetDrawn() { return FLEET.drawn; }
// A fleet run going on when the page is (re)loaded is watched again.
async function startFleet() {
  if (await loadFleets()) { openFleet("live", null); watchFleet(); }
}
startFleet();
