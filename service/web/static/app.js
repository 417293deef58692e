// The DTF placement page: a map job with progress and cancel, the colour map, a cell's joint
// speeds, the optimum. Plain JavaScript; it calls only this service's API.
"use strict";

const $ = (id) => document.getElementById(id);
const REASON_COLOURS = {
  unreachable: "#e0e0e0", joint_limits: "#f4a6c0", singular: "#555555", discontinuous: "#ffb74d",
};
const state = {
  robots: [], path: null, source: null, map: null, grid: null, job: null, cursor: null,
};

// ---- inputs -------------------------------------------------------------------------------
function numbers(text) {
  return text.split(",").map((v) => v.trim()).filter((v) => v !== "").map(Number);
}

function robotBody() {
  const own = $("robot-json").value.trim();
  if (own) return JSON.parse(own);
  const robot = { model: $("robot-model").value };
  const info = state.robots.find((r) => r.name === robot.model);
  const limits = [...$("limits").querySelectorAll("input")].map((i) => Number(i.value));
  if (info && limits.some((v, k) => v !== info.qdot_max[k])) robot.joint_velocity_limits = limits;
  return robot;
}

function gridBody() {
  const axis = (name) => ({
    min: Number($(`${name}-min`).value), max: Number($(`${name}-max`).value),
    step: Number($(`${name}-step`).value),
  });
  return { x: axis("x"), y: axis("y"), z: Number($("z").value),
    yaw: numbers($("yaws").value), spin: numbers($("spins").value) };
}

function mapBody() {
  return { robot: robotBody(), path: state.path, grid: gridBody() };
}

function showLimits() {
  const info = state.robots.find((r) => r.name === $("robot-model").value);
  const box = $("limits");
  box.textContent = "";
  if (!info) return;
  info.qdot_max.forEach((v, k) => {
    const input = document.createElement("input");
    input.type = "number"; input.step = "any"; input.value = v;
    input.id = `limit-${k}`;
    input.setAttribute("aria-label", `${info.joint_names[k]} speed limit (rad/s)`);
    box.appendChild(input);
  });
}

async function loadExample() {
  const name = $("path-example").value;
  const text = await (await fetch(`/ui/examples/${name}`)).text();
  await setPath(name, text);
}

function setPath(name, text) {
  const lower = name.toLowerCase();
  state.source = { name, text };
  const units = $("path-units").value;
  if (lower.endsWith(".json")) {
    const value = JSON.parse(text);
    state.path = value.path ?? value;
  } else if (lower.endsWith(".csv")) {
    state.path = { csv: text, units: units || "mm" };
  } else {
    state.path = { cl_data: text };
    if (units === "mm" || units === "inch") state.path.units = units;
  }
  $("path-info").textContent = `${name} loaded`;
  return showImport();
}

// What the service read: units and how they were known, passes and operations, skipped records.
async function showImport() {
  clearErrors();
  const box = $("import");
  delete box.dataset.waypoints;
  for (const id of ["import-summary", "import-units"]) $(id).textContent = "";
  $("import-passes").tBodies[0].textContent = "";
  $("import-skipped").textContent = "";
  const read = await api("POST", "/v1/paths/import", { path: state.path }).catch(() => null);
  if (!read) return;
  const dropped = read.repeated_points + read.one_point_passes;
  $("import-summary").textContent = `${read.waypoints.length} waypoints in ${read.passes.length} passes`
    + (read.arcs ? `, ${read.arcs} arcs interpolated` : "")
    + (dropped ? `; dropped ${read.repeated_points} repeated points, ${read.one_point_passes} one-point passes` : "");
  $("import-units").textContent = `${read.units} (${read.units_source}: ${read.units_note})`;
  const rows = $("import-passes").tBodies[0];
  read.pass_details.forEach((p, k) => {
    const row = rows.insertRow();
    const feed = p.feed == null ? "-" : (p.feed * 60000).toFixed(1);
    for (const value of [k + 1, `${p.start}-${p.stop - 1}`, p.operation ?? "-", feed]) {
      row.insertCell().textContent = value;
    }
  });
  for (const s of read.skipped_records) {
    const item = document.createElement("li");
    item.textContent = `${s.word}: ${s.count} (first at line ${s.first_line})`
      + (s.recognised ? "" : " - not recognised: check that it moves nothing");
    $("import-skipped").appendChild(item);
  }
  box.dataset.waypoints = String(read.waypoints.length);
}

// ---- API calls and errors ------------------------------------------------------------------
function clearErrors() {
  document.querySelectorAll(".error").forEach((e) => { e.textContent = ""; });
}

function showErrors(details) {
  for (const d of details) {
    const loc = d.loc.filter((p) => p !== "body" && p !== "request");
    let field = null;
    for (let n = loc.length; n > 0 && !field; n--) {
      field = document.querySelector(`.field[data-loc="${loc.slice(0, n).join(".")}"]`);
    }
    const target = field ? field.querySelector(".error") : $("form-error");
    target.textContent = (target.textContent ? target.textContent + " " : "") + d.msg;
  }
}

async function api(method, url, body) {
  const response = await fetch(url, {
    method, headers: body ? { "Content-Type": "application/json" } : {},
    body: body ? JSON.stringify(body) : undefined,
  });
  if (response.status === 204) return null;
  const answer = await response.json();
  if (!response.ok) {
    const detail = Array.isArray(answer.detail) ? answer.detail
      : [{ loc: [], msg: String(answer.detail) }];
    showErrors(detail);
    throw new Error(`${response.status}`);
  }
  return answer;
}

// ---- the map job ---------------------------------------------------------------------------
async function runMap(event) {
  event.preventDefault();
  clearErrors();
  let body;
  try { body = mapBody(); } catch (error) { showErrors([{ loc: ["robot"], msg: String(error) }]); return; }
  const job = await api("POST", "/v1/jobs", { kind: "map", request: body }).catch(() => null);
  if (!job) return;
  state.job = job.id; state.grid = body.grid;
  $("cancel").disabled = false; $("run").disabled = true;
  await watch(job.id);
}

async function watch(id) {
  for (;;) {
    const job = await api("GET", `/v1/jobs/${id}`);
    $("bar").value = job.progress.fraction;
    const eta = job.progress.eta_seconds;
    $("eta").textContent = eta == null ? "" : `about ${eta.toFixed(1)} s left`;
    $("job-status").textContent = `${job.status}: ${job.progress.done} of ${job.progress.total} placements`;
    if (!["queued", "running"].includes(job.status)) {
      $("cancel").disabled = true; $("run").disabled = false; state.job = null;
      if (job.status === "done") drawMap(job.result);
      if (job.status === "failed") showErrors(job.error);
      return;
    }
    await new Promise((resolve) => setTimeout(resolve, 200));
  }
}

async function cancelMap() {
  if (state.job) await api("POST", `/v1/jobs/${state.job}/cancel`);  // DELETE would forget it
}

// ---- the colour map ------------------------------------------------------------------------
function colour(fraction) {  // dark blue -> green -> yellow
  const stops = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  const t = Math.min(Math.max(fraction, 0), 1) * (stops.length - 1);
  const k = Math.min(Math.floor(t), stops.length - 2);
  const mix = stops[k].map((c, i) => Math.round(c + (stops[k + 1][i] - c) * (t - k)));
  return `rgb(${mix.join(",")})`;
}

function drawMap(answer) {
  state.map = answer;
  const cells = answer.cells;
  const xs = [...new Set(cells.map((c) => c.x))];
  const ys = [...new Set(cells.map((c) => c.y))];
  const feasible = cells.filter((c) => c.mu_path !== null).map((c) => c.mu_path);
  const low = Math.min(...feasible), high = Math.max(...feasible);
  const size = Math.min(24, Math.max(2, Math.floor(480 / Math.max(xs.length, ys.length))));
  state.scale = { low, high, xs, ys, size };
  $("summary").textContent = `${cells.length} cells, ${answer.feasible_cells} feasible`;
  $("summary").dataset.cells = String(cells.length);
  $("best-mu").textContent = answer.best ? answer.best.mu_path.toFixed(6) + " m/s" : "none feasible";
  $("best-where").textContent = answer.best
    ? `at x ${answer.best.placement.x.toFixed(3)} m, y ${answer.best.placement.y.toFixed(3)} m, yaw ${answer.best.placement.yaw.toFixed(3)} rad` : "";
  $("cb-min").textContent = feasible.length ? `${low.toFixed(3)} m/s` : "";
  $("cb-max").textContent = feasible.length ? `${high.toFixed(3)} m/s` : "";
  const bar = $("colourbar-canvas").getContext("2d");
  for (let i = 0; i < 300; i++) { bar.fillStyle = colour(i / 299); bar.fillRect(i, 0, 1, 14); }
  const panels = $("panels");
  panels.textContent = "";
  const perPanel = xs.length * ys.length;
  for (let start = 0; start < cells.length; start += perPanel) {
    const panelCells = cells.slice(start, start + perPanel);
    const figure = document.createElement("figure");
    figure.className = "panel";
    const canvas = document.createElement("canvas");
    canvas.width = xs.length * state.scale.size; canvas.height = ys.length * state.scale.size;
    canvas.tabIndex = 0;
    canvas.dataset.first = String(start);
    canvas.dataset.nx = String(xs.length); canvas.dataset.ny = String(ys.length);
    canvas.dataset.cell = String(state.scale.size);
    const head = panelCells[0];
    canvas.setAttribute("aria-label", `map at yaw ${head.yaw} rad, spin ${head.spin} rad`);
    const caption = document.createElement("figcaption");
    caption.textContent = `yaw ${head.yaw.toFixed(3)} rad, spin ${head.spin.toFixed(3)} rad`;
    figure.append(canvas, caption);
    panels.appendChild(figure);
    paintPanel(canvas);
    canvas.addEventListener("mousemove", (e) => hover(canvas, e));
    canvas.addEventListener("mouseleave", () => { $("tooltip").hidden = true; });
    canvas.addEventListener("click", (e) => { const c = cellAt(canvas, e); if (c) evaluateCell(c); });
    canvas.addEventListener("keydown", (e) => keys(canvas, e));
  }
}

function paintPanel(canvas) {
  const { low, high, xs, ys } = state.scale;
  const g = canvas.getContext("2d");
  const first = Number(canvas.dataset.first);
  for (let k = 0; k < xs.length * ys.length; k++) {
    const c = state.map.cells[first + k];
    const i = k % xs.length, j = Math.floor(k / xs.length);
    g.fillStyle = c.mu_path === null ? REASON_COLOURS[c.reason]
      : colour(high > low ? (c.mu_path - low) / (high - low) : 1);
    g.fillRect(i * state.scale.size, (ys.length - 1 - j) * state.scale.size, state.scale.size, state.scale.size);
  }
  if (state.cursor && state.cursor.canvas === canvas) {
    g.strokeStyle = "#fff"; g.lineWidth = 2;
    g.strokeRect(state.cursor.i * state.scale.size + 1, (ys.length - 1 - state.cursor.j) * state.scale.size + 1,
      state.scale.size - 2, state.scale.size - 2);
  }
  if (state.optimum && state.optimum.canvas === canvas) drawMarker(canvas, state.optimum.placement);
}

function cellAt(canvas, event) {
  const box = canvas.getBoundingClientRect();
  const { xs, ys } = state.scale;
  const i = Math.floor((event.clientX - box.left) / state.scale.size);
  const j = ys.length - 1 - Math.floor((event.clientY - box.top) / state.scale.size);
  if (i < 0 || i >= xs.length || j < 0 || j >= ys.length) return null;
  return state.map.cells[Number(canvas.dataset.first) + j * xs.length + i];
}

function describe(c) {
  const lines = [`x ${c.x.toFixed(4)} m, y ${c.y.toFixed(4)} m, yaw ${c.yaw.toFixed(4)} rad`];
  if (c.mu_path === null) {
    lines.push(`infeasible: ${c.reason} at waypoint ${c.failed_waypoint}`);
  } else {
    lines.push(`mu_path ${c.mu_path.toFixed(6)} m/s`);
    lines.push(`bottleneck: joint ${c.bottleneck_joint + 1}, waypoint ${c.bottleneck_waypoint}`);
    lines.push(`branch ${Object.values(c.branch || {}).join("/")}`);
  }
  return lines.join("\n");
}

function hover(canvas, event) {
  const c = cellAt(canvas, event);
  const tip = $("tooltip");
  if (!c) { tip.hidden = true; return; }
  tip.textContent = describe(c);
  tip.style.left = `${event.clientX + 12}px`; tip.style.top = `${event.clientY + 12}px`;
  tip.hidden = false;
}

function keys(canvas, event) {
  const { xs, ys } = state.scale;
  const cur = state.cursor && state.cursor.canvas === canvas ? state.cursor : { canvas, i: 0, j: 0 };
  const moves = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
  const cell = () => state.map.cells[Number(canvas.dataset.first) + cur.j * xs.length + cur.i];
  if (moves[event.key]) {
    event.preventDefault();
    cur.i = Math.min(Math.max(cur.i + moves[event.key][0], 0), xs.length - 1);
    cur.j = Math.min(Math.max(cur.j + moves[event.key][1], 0), ys.length - 1);
    state.cursor = cur;
    document.querySelectorAll(".panel canvas").forEach(paintPanel);
    $("tooltip").textContent = describe(cell());
  } else if (event.key === "Enter") {
    event.preventDefault();
    state.cursor = cur;
    evaluateCell(cell());
  }
}

// ---- one placement: V_max and joint use along the path ---------------------------------------
async function evaluateCell(c) {
  clearErrors();
  const body = {
    robot: robotBody(), path: state.path,
    placement: { x: c.x, y: c.y, z: state.grid.z, yaw: c.yaw, spin: c.spin },
    feed: Number($("feed").value),
  };
  const answer = await api("POST", "/v1/evaluate", body).catch(() => null);
  if (!answer) return;
  $("cell-summary").textContent = answer.feasible
    ? `x ${c.x} m, y ${c.y} m, yaw ${c.yaw} rad: mu_path ${answer.mu_path.toFixed(6)} m/s; at ${body.feed} m/s the largest joint use is ${(100 * answer.feed_check.feed / answer.mu_path).toFixed(1)} %`
    : `x ${c.x} m, y ${c.y} m, yaw ${c.yaw} rad: infeasible (${answer.reason} at waypoint ${answer.failed_waypoint})`;
  const b = answer.bottleneck;
  $("bottleneck").textContent = b ? `bottleneck: waypoint ${b.waypoint}, joint ${b.joint + 1} (${b.joint_name})` : "";
  $("bottleneck").dataset.waypoint = b ? String(b.waypoint) : "";
  $("bottleneck").dataset.joint = b ? String(b.joint) : "";
  plot(answer);
}

function plot(answer) {
  const canvas = $("plot");
  const g = canvas.getContext("2d");
  g.clearRect(0, 0, canvas.width, canvas.height);
  const points = answer.waypoints;
  if (!answer.feasible || !points.length) return;
  const left = 50, width = canvas.width - 70, top = 10, height = (canvas.height - 60) / 2;
  const xOf = (k) => left + (width * k) / Math.max(points.length - 1, 1);
  const axes = (y0, label, max) => {
    g.strokeStyle = "#444"; g.strokeRect(left, y0, width, height);
    g.fillStyle = "#222"; g.font = "12px sans-serif";
    g.fillText(label, left + 4, y0 + 14); g.fillText(max.toFixed(2), 4, y0 + 10); g.fillText("0", 30, y0 + height);
  };
  const vmax = Math.max(...points.map((p) => p.v_max ?? 0));
  axes(top, "V_max (m/s) along the path", vmax);
  g.strokeStyle = "#1565c0"; g.beginPath();
  points.forEach((p, k) => { const y = top + height * (1 - (p.v_max ?? 0) / vmax); k ? g.lineTo(xOf(k), y) : g.moveTo(xOf(k), y); });
  g.stroke();
  const useTop = top + height + 30;
  axes(useTop, "joint use of its limit at the feed (1 = on the limit)", 1);
  const colours = ["#e53935", "#8e24aa", "#3949ab", "#00897b", "#7cb342", "#fb8c00", "#6d4c41"];
  const joints = points[0].use ? points[0].use.length : 0;
  for (let j = 0; j < joints; j++) {
    g.strokeStyle = colours[j % colours.length]; g.beginPath();
    points.forEach((p, k) => { const u = Math.min(p.use[j] ?? 0, 1.2); const y = useTop + height * (1 - u); k ? g.lineTo(xOf(k), y) : g.moveTo(xOf(k), y); });
    g.stroke();
    g.fillStyle = colours[j % colours.length]; g.fillText(`joint ${j + 1}`, left + width - 60, useTop + 14 + 13 * j);
  }
  if (answer.bottleneck) {
    const x = xOf(answer.bottleneck.waypoint);
    g.strokeStyle = "#b00020"; g.setLineDash([4, 3]); g.beginPath();
    g.moveTo(x, top); g.lineTo(x, useTop + height); g.stroke(); g.setLineDash([]);
    g.fillStyle = "#b00020"; g.fillText(`bottleneck (joint ${answer.bottleneck.joint + 1})`, Math.min(x + 4, left + width - 130), top + height + 20);
  }
  canvas.dataset.drawn = "1";
}

// ---- the optimum ---------------------------------------------------------------------------
function drawMarker(canvas, p) {
  const { xs, ys } = state.scale;
  const dx = xs.length > 1 ? xs[1] - xs[0] : 1, dy = ys.length > 1 ? ys[1] - ys[0] : 1;
  const px = ((p.x - xs[0]) / dx + 0.5) * state.scale.size, py = (ys.length - 0.5 - (p.y - ys[0]) / dy) * state.scale.size;
  const g = canvas.getContext("2d");
  g.strokeStyle = "#d50000"; g.lineWidth = 3; g.beginPath();
  g.moveTo(px - 7, py - 7); g.lineTo(px + 7, py + 7); g.moveTo(px + 7, py - 7); g.lineTo(px - 7, py + 7);
  g.stroke();
}

async function optimize() {
  clearErrors();
  const grid = gridBody();
  const body = {
    robot: robotBody(), path: state.path, method: $("method").value, z: grid.z,
    bounds: { x: [grid.x.min, grid.x.max], y: [grid.y.min, grid.y.max],
      yaw: [Math.min(...grid.yaw), Math.max(...grid.yaw)] },
  };
  $("opt-mu").textContent = "optimising…";
  const answer = await api("POST", "/v1/optimize", body).catch(() => null);
  if (!answer) { $("opt-mu").textContent = ""; return; }
  if (!answer.found) { $("opt-mu").textContent = "no feasible placement"; return; }
  const p = answer.placement;
  $("opt-mu").textContent = `${answer.mu_path.toFixed(6)} m/s`;
  $("opt-improvement").textContent = `(+${answer.improvement_percent.toFixed(2)} % over the start, ${answer.start.mu_path === null ? "infeasible" : answer.start.mu_path.toFixed(6) + " m/s"})`;
  $("opt-where").textContent = `x ${p.x.toFixed(4)} m, y ${p.y.toFixed(4)} m, z ${p.z} m, yaw ${p.yaw.toFixed(4)} rad`;
  const frames = $("frames");
  frames.textContent = "";
  for (const [name, value] of Object.entries(p.frames)) {
    if (name === "matrix") continue;
    const row = document.createElement("p");
    const code = document.createElement("code");
    code.textContent = `${name}: ${JSON.stringify(value)}`;
    const copy = document.createElement("button");
    copy.type = "button"; copy.textContent = `Copy ${name}`;
    copy.addEventListener("click", () => navigator.clipboard && navigator.clipboard.writeText(JSON.stringify(value)));
    row.append(code, copy);
    frames.appendChild(row);
  }
  const canvases = [...document.querySelectorAll(".panel canvas")];
  if (state.map && canvases.length) {  // the panel whose yaw is nearest the optimum's
    const yaws = canvases.map((c) => state.map.cells[Number(c.dataset.first)].yaw);
    const k = yaws.reduce((best, y, i) => (Math.abs(y - p.yaw) < Math.abs(yaws[best] - p.yaw) ? i : best), 0);
    state.optimum = { canvas: canvases[k], placement: p };
    canvases.forEach(paintPanel);
    canvases[k].dataset.optimum = "1";
  }
}

// ---- start ---------------------------------------------------------------------------------
async function start() {
  const answer = await api("GET", "/v1/robots");
  state.robots = answer.robots;
  const select = $("robot-model");
  for (const robot of state.robots) {
    const option = document.createElement("option");
    option.value = robot.name; option.textContent = `${robot.name} (${robot.dof} joints, ${robot.family})`;
    select.appendChild(option);
  }
  if (state.robots.some((r) => r.name === "ur5")) select.value = "ur5";
  showLimits();
  select.addEventListener("change", showLimits);
  $("path-example").addEventListener("change", loadExample);
  $("path-file").addEventListener("change", async () => {
    const file = $("path-file").files[0];
    if (file) await setPath(file.name, await file.text());
  });
  $("path-units").addEventListener("change", () => {
    if (state.source) setPath(state.source.name, state.source.text);
  });
  $("inputs").addEventListener("submit", runMap);
  $("cancel").addEventListener("click", cancelMap);
  $("optimize").addEventListener("click", optimize);
  await loadExample();
  document.body.dataset.ready = "1";
}

start();
