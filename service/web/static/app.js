// The DTF placement page: a map job with progress and cancel, the colour map (mu_path, or mu_acc
// with joint acceleration limits), a cell's joint speeds and accelerations, the cycle time, the
// optimum. Plain JavaScript; it calls only this service's API. Its other scripts, loaded before
// it: format.js (rounding, controller frames), axes.js (the panels' axes), plot.js (the clicked
// placement's plot), cell.js (the cell editor and its words), optimum.js (the optimiser), job.js
// (the map job: submit, watch, read its cells, cancel).
"use strict";

const $ = (id) => document.getElementById(id);
const REASON_COLOURS = {
  unreachable: "#e0e0e0", joint_limits: "#f4a6c0", singular: "#555555", discontinuous: "#ffb74d",
  collision: "#c62828",
};
const state = {
  robots: [], path: null, pathProblem: "no path loaded yet", source: null, map: null, grid: null,
  run: null, optimization: null, evaluation: null, cursor: null, tipAt: null,
  limits: null,  // GET /v1/limits: what a request may hold, said before it is sent
};

// ---- inputs -------------------------------------------------------------------------------
function numbers(text) {
  return text.split(",").map((v) => v.trim()).filter((v) => v !== "").map(Number);
}

// A number field's value; an empty field is left out of the body (undefined), never read as 0,
// so that the API says beside it that it is required.
function value(id) {
  const text = $(id).value.trim();
  return text === "" ? undefined : Number(text);
}

function spinMode() { return $("spin-mode").value || undefined; }

// A pasted robot object that is not JSON throws, saying so: its callers show it beside Robot.
function robotBody() {
  const own = $("robot-json").value.trim();
  if (own) {  // a pasted robot object carries its own limits
    try { return JSON.parse(own); } catch (error) {
      throw new Error(`the robot object is not JSON: ${error.message}`);
    }
  }
  // Empty: none. Otherwise every entry is sent as typed (a wrong count or a word is the API's
  // error beside the field, never dropped here): Number("x") is NaN, sent as null.
  const acc = $("acc-limits").value.trim();
  const accLimits = acc ? acc.split(",").map((v) => (v.trim() === "" ? null : Number(v))) : null;
  const tcp = tcpBody();
  if ($("urdf").value.trim()) {  // the URDF as written; a frame left empty is the API's error
    const robot = { urdf: $("urdf").value };
    const base = $("base-frame").value.trim(), tool = $("tool-frame").value.trim();
    if (base) robot.base_frame = base;
    if (tool) robot.tool_frame = tool;
    if (accLimits) robot.joint_acceleration_limits = accLimits;
    if (tcp) robot.tcp = tcp;
    return robot;
  }
  const robot = { model: $("robot-model").value };
  const info = state.robots.find((r) => r.name === robot.model);
  const limits = [...$("limits").querySelectorAll("input")].map((i) => Number(i.value));
  if (info && limits.some((v, k) => v !== info.qdot_max[k])) robot.joint_velocity_limits = limits;
  if (accLimits) robot.joint_acceleration_limits = accLimits;
  if (tcp) robot.tcp = tcp;
  return robot;
}

const TCP_FIELDS = ["tcp-x", "tcp-y", "tcp-z", "tcp-roll", "tcp-pitch", "tcp-yaw"];

// The robot's tool point in its flange frame (the API's robot.tcp), where any of its six
// fields is filled: an empty one is then 0, as the label says; a word is sent as null, which
// the API refuses beside the field. Angles in degrees: R = Rz(yaw) Ry(pitch) Rx(roll).
function tcpBody() {
  if (TCP_FIELDS.every((id) => $(id).value.trim() === "")) return undefined;
  const [x, y, z, roll, pitch, yaw] = TCP_FIELDS.map((id) => {
    const text = $(id).value.trim();
    return text === "" ? 0 : Number(text);
  });
  const turn = [roll, pitch, yaw].some((a) => !Number.isFinite(a)) ? [null, null, null, null]
    : quaternionOf(roll * DEGREE, pitch * DEGREE, yaw * DEGREE);
  return { position: [x, y, z], orientation: turn };
}

// The links of a URDF, for the frame fields' suggestions; the base and tool frames filled in
// (where the field is empty): the base frame REP 199's "base", the controller's frame, where
// fixed joints join it to the root (the controller frames of the optimum are then the
// controller's, as dtf-place's), else the chain's root when it is a single link; the tool
// frame the chain's tip when it is a single link. Links no joint names are neither.
function readUrdfLinks() {
  const list = $("urdf-links");
  list.textContent = "";
  const doc = new DOMParser().parseFromString($("urdf").value, "application/xml");
  if (doc.querySelector("parsererror")) return;  // the API names what is wrong with it
  const links = [...doc.querySelectorAll("robot > link")].map((l) => l.getAttribute("name"));
  const joints = [...doc.querySelectorAll("robot > joint")];
  const children = new Set(joints.map((j) => j.querySelector("child")?.getAttribute("link")));
  const parents = new Set(joints.map((j) => j.querySelector("parent")?.getAttribute("link")));
  // A link no joint names is left out by the API (robot_read): no root, no tip of the chain.
  const joined = (l) => !joints.length || children.has(l) || parents.has(l);
  const roots = links.filter((l) => joined(l) && !children.has(l));
  const tips = links.filter((l) => joined(l) && !parents.has(l));
  for (const name of [...roots, ...links.filter((l) => !roots.includes(l))]) {
    list.appendChild(Object.assign(document.createElement("option"), { value: name }));
  }
  const joinedBy = new Map(joints.map((j) => [j.querySelector("child")?.getAttribute("link"), j]));
  const fixedToRoot = (link) => {
    const seen = new Set();
    while (joinedBy.has(link) && !seen.has(link)) {
      seen.add(link);
      const joint = joinedBy.get(link);
      if (joint.getAttribute("type") !== "fixed") return false;
      link = joint.querySelector("parent")?.getAttribute("link");
    }
    return !seen.has(link);
  };
  const controller = links.includes("base") && fixedToRoot("base");
  const base = controller ? "base" : roots.length === 1 ? roots[0] : "";
  if (base && !$("base-frame").value.trim()) $("base-frame").value = base;
  state.baseHint = !base ? null : {
    frame: base,
    text: controller
      ? "base: REP 199's controller frame, fixed to the URDF's root; placements and the optimum's controller frames are in it"
      : `${base}: the URDF's root link (it has no REP 199 controller frame "base" fixed to its root)`,
  };
  if (tips.length === 1 && !$("tool-frame").value.trim()) $("tool-frame").value = tips[0];
  showBaseHint();
}

// Why the base frame holds what the page filled in; gone once the field says another frame.
function showBaseHint() {
  const hint = state.baseHint;
  $("base-frame-hint").textContent = hint && $("base-frame").value.trim() === hint.frame ? hint.text : "";
}

// Empty fields and the auto branch are left out: the API's defaults.
function ikBody() {
  const ik = { blend_length: value("blend-length"), max_joint_step: value("max-joint-step") };
  const branch = $("ik-branch");
  if (!branch.disabled && branch.value !== "auto") ik.branch = JSON.parse(branch.value);
  return ik;
}

// The catalogue robot's branches (GET /v1/robots: levels and their choices), each combination
// an option; a pasted robot object or a URDF follows the auto branch (its branches are its own).
// A numeric arm's level, "solution", lists its indices as words: ik.branch takes the number.
function showBranches(info) {
  const select = $("ik-branch");
  const kept = select.value;
  select.replaceChildren(select.options[0]);
  let combinations = [{}];
  for (const { level, choices } of info ? info.branches : []) {
    const named = (choice) => (level === "solution" ? Number(choice) : choice);
    combinations = combinations.flatMap((c) => choices.map((choice) => ({ ...c, [level]: named(choice) })));
  }
  for (const branch of info && info.branches.length ? combinations : []) {
    const option = document.createElement("option");
    option.value = JSON.stringify(branch);
    option.textContent = Object.entries(branch).map(([level, choice]) => `${level} ${choice}`).join(", ");
    select.appendChild(option);
  }
  select.value = [...select.options].some((o) => o.value === kept) ? kept : "auto";
}

// A pasted robot object brings its own limits: the catalogue's fields are then greyed out.
function showOwnRobot() {
  const own = $("robot-json").value.trim() !== "";
  const urdf = !own && $("urdf").value.trim() !== "";
  for (const input of [...$("limits").querySelectorAll("input"), $("robot-model")]) {
    input.disabled = own || urdf;
  }
  $("acc-limits").disabled = own;
  $("ik-branch").disabled = own || urdf;
  for (const id of TCP_FIELDS) $(id).disabled = own;  // a pasted robot object gives its own
  $("own-robot-note").hidden = !own;
  $("urdf-note").hidden = !urdf;
}

// Number fields whose text the browser cannot read as a number ("1e400", "1.2.3"): their value
// is then "", which every reader here takes for an empty field, so a table height, a tool
// point or a blend length so typed was left out of the request without a word. Each is said
// beside its field (named, where the field has several inputs) and the caller sends nothing.
// ``skip(id)``: the inputs the action does not read. Disabled inputs are not sent: not read.
function unreadNumbers(skip) {
  numberCellFields();  // a box added since the last request gets its loc: its error beside it
  const details = [];
  for (const input of document.querySelectorAll("input[type=number]")) {
    if (input.disabled || !input.validity.badInput || skip(input.id)) continue;
    const field = input.closest(".field[data-loc]");
    const label = input.getAttribute("aria-label") || input.labels?.[0]?.textContent || input.id;
    const said = "not a number as typed (the browser reads it as empty); a decimal takes a point";
    // Named where its field has other inputs (the tool point's six, a box's sizes, the limits)
    details.push({
      loc: field ? field.dataset.loc.split(".") : [],
      msg: !field || field.querySelectorAll("input").length > 1 ? `${label}: ${said}` : said,
    });
  }
  showErrors(details);
  return details.length > 0;
}

// How a list field is read, said beside it as the user types: "1,57" is two values, 1 and 57
// rad, not 1.57 (the lists are comma-separated; a decimal takes a point). A value beyond a turn
// is named with the angle it is the same as and, where a digit and a comma come right before
// it, the decimal it may have meant: the API takes any angle within 1000 rad, so this is the
// one place a decimal comma shows before a map of the wrong yaws is run.
function showListReading(id, plural) {
  const raw = $(id).value.split(",");
  const pieces = raw.map((v) => v.trim()).filter((v) => v !== "");
  const turn = 2 * Math.PI;
  let text = pieces.length > 1 ? `read as ${pieces.length} ${plural}: ${pieces.join(", ")} rad` : "";
  const beyond = (v) => v.trim() !== "" && Number.isFinite(Number(v)) && Math.abs(Number(v)) > turn;
  const k = raw.findIndex(beyond);
  if (k >= 0) {
    const v = Number(raw[k]);
    const same = v - turn * Math.round(v / turn);  // the same angle, within half a turn
    text += `${text ? "; " : ""}${raw[k].trim()} rad is more than a turn (the same as ${radians(same)})`;
    if (k > 0 && /^\d+$/.test(raw[k]) && /-?\d+$/.test(raw[k - 1])) {
      const whole = raw[k - 1].match(/-?\d+$/)[0];
      text += `: a decimal takes a point (${whole}.${raw[k]}, not ${whole},${raw[k]})`;
    }
  }
  const note = $(`${id}-read`);
  note.textContent = text;
  note.classList.toggle("too-large", k >= 0);
}

function gridBody() {
  const axis = (name) => ({
    min: value(`${name}-min`), max: value(`${name}-max`), step: value(`${name}-step`),
  });
  return { x: axis("x"), y: axis("y"), z: value("z"),
    yaw: numbers($("yaws").value), spin: numbers($("spins").value) };
}

function mapBody() {
  return {
    robot: robotBody(), path: state.path, grid: gridBody(), ik: ikBody(), spin_mode: spinMode(),
    cell: cellBody(),
  };
}

function showLimits() {
  const info = state.robots.find((r) => r.name === $("robot-model").value);
  const box = $("limits");
  box.textContent = "";
  showBranches(info);
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

// A new path: every result of the old one goes, and nothing runs until the new one is read.
// A file that cannot be read (JSON that is not JSON, a CSV without units) says so beside the
// field and leaves no path at all, never the previous one.
function setPath(name, text) {
  const lower = name.toLowerCase();
  state.source = { name, text };
  state.path = null;
  inputsChanged(`a new path, ${name}, was loaded`);
  clearImport();
  clearErrors();
  const units = $("path-units").value;
  let problem = null, loc = ["path"];
  if (lower.endsWith(".json")) {
    let parsed;
    try { parsed = JSON.parse(text); } catch (error) { problem = `${name} is not JSON: ${error.message}`; }
    if (!problem && (parsed === null || typeof parsed !== "object")) problem = `${name} holds no path object`;
    if (!problem) state.path = parsed.path ?? parsed;
  } else if (lower.endsWith(".csv")) {
    if (units) state.path = { csv: text, units };
    else { problem = `${name}: a CSV file states no units; choose mm, inch or m here`; loc = ["path", "units"]; }
  } else {
    state.path = { cl_data: text };
    if (units) state.path.units = units;  // "m" too: the API says that CL data takes mm or inch
  }
  if (problem) {
    state.pathProblem = problem;
    $("path-info").textContent = `${name}: not read, no path`;
    showErrors([{ loc, msg: problem }]);
    return Promise.resolve();
  }
  $("path-info").textContent = `${name} loaded`;
  return showImport(name);
}

function clearImport() {
  const box = $("import");
  delete box.dataset.waypoints;
  for (const id of ["import-summary", "import-units", "import-end"]) $(id).textContent = "";
  $("import-passes").tBodies[0].textContent = "";
  $("import-skipped").textContent = "";
}

// The length of a read path (m): the sum of its segments within each pass.
function pathLength(read) {
  let length = 0;
  for (const [start, stop] of read.passes) {
    for (let k = start + 1; k < stop; k++) {
      const a = read.waypoints[k - 1].position, b = read.waypoints[k].position;
      length += Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    }
  }
  return length;
}

// What the service read: units and how they were known, passes and operations, skipped records.
async function showImport(name) {
  const path = state.path;
  let read = null;
  try { read = await api("POST", "/v1/paths/import", { path }); } catch (error) {
    if (state.path === path) {  // refused: no path until one is read
      state.path = null;
      state.pathProblem = `${name} was not read: ${error.message}`;
      $("path-info").textContent = `${name}: not read, no path`;
    }
    return;
  }
  if (state.path !== path) return;  // another path came meanwhile
  const box = $("import");
  const dropped = read.repeated_points + read.one_point_passes;
  const passes = read.passes.length;
  $("import-summary").textContent = `${read.waypoints.length} waypoints in ${passes} ${passes === 1 ? "pass" : "passes"}`
    + `, ${fixed(1000 * pathLength(read), 1)} mm of path`
    + `; tool spin ${read.spin_mode} by default`
    + (read.arcs ? `, ${read.arcs} arcs interpolated` : "")
    + (dropped ? `; dropped ${read.repeated_points} repeated points, ${read.one_point_passes} one-point passes` : "");
  $("import-units").textContent = `${read.units} (${read.units_source}: ${read.units_note})`;
  // A program with no end record after its last move may be cut short: said in red.
  $("import-end").textContent = read.end_note;
  $("import-end").classList.toggle("cut-short", read.ended === false);
  const rows = $("import-passes").tBodies[0];
  // Passes from 0, as the waypoints, the API's failed_pass and its messages (shown on this
  // page) and the command line count them: this table counted from 1.
  read.pass_details.forEach((p, k) => {
    const row = rows.insertRow();
    const feed = p.feed == null ? "-" : (p.feed * 60000).toFixed(1);
    for (const value of [k, `${p.start}-${p.stop - 1}`, p.operation ?? "-", feed]) {
      row.insertCell().textContent = value;
    }
  });
  for (const s of read.skipped_records) {
    const item = document.createElement("li");
    item.textContent = `${s.word}: ${s.count} (first at line ${s.first_line})`
      + (s.recognised ? "" : " - not recognised: check that it moves nothing");
    $("import-skipped").appendChild(item);
  }
  if (!read.skipped_records.length) {  // said, not left as an empty list
    const item = document.createElement("li");
    item.textContent = "none";
    $("import-skipped").appendChild(item);
  }
  box.dataset.waypoints = String(read.waypoints.length);
}

// ---- API calls and errors ------------------------------------------------------------------
function clearErrors() {
  document.querySelectorAll(".error").forEach((e) => { e.textContent = ""; });
}

// Each error beside the field its loc names (the longest prefix that is a field on the page,
// after `aliases` renames a loc's head: the optimiser's bounds are the grid's fields); one the
// page has no field for goes under the buttons, prefixed with its loc.
function showErrors(details, aliases = {}) {
  for (const d of details) {
    let loc = d.loc.filter((p) => p !== "body" && p !== "request").map(String);
    for (const [from, to] of Object.entries(aliases)) {
      const head = from.split(".");
      if (head.every((p, k) => loc[k] === p)) { loc = [...to.split("."), ...loc.slice(head.length)]; break; }
    }
    let field = null;
    for (let n = loc.length; n > 0 && !field; n--) {
      field = document.querySelector(`.field[data-loc="${loc.slice(0, n).join(".")}"]`);
    }
    const target = field ? field.querySelector(".error") : $("form-error");
    const folded = target.closest("details");
    if (folded) folded.open = true;  // an error inside a folded section is seen
    // The part of the loc the field does not name (a waypoint, a joint, an item of a list)
    // leads the message: "waypoints[7].orientation: ...", "[2]: ..." beside the limits.
    const named = field ? field.dataset.loc.split(".").length : 0;
    const rest = locText(loc.slice(named));
    const msg = rest ? `${rest}: ${d.msg}` : d.msg;
    if (!target.textContent.split(" | ").includes(msg)) {
      target.textContent = (target.textContent ? target.textContent + " | " : "") + msg;
    }
  }
}

// A loc's parts as the API counts them: names joined by dots, indices in brackets.
function locText(parts) {
  return parts.map((p, k) => (/^\d+$/.test(p) ? `[${p}]` : (k ? "." : "") + p)).join("");
}

// An error detail in words: its loc (the body's own fields) before its message.
function detailText(d) {
  const loc = locText((d.loc || []).filter((p) => p !== "body" && p !== "request").map(String));
  return loc ? `${loc}: ${d.msg}` : d.msg;
}

// `signal` (an AbortSignal) aborts the request: it then throws before showing anything. Any
// other failure is shown under the buttons (or beside its field) before it throws: no answer
// (the network, the service stopped), an answer that is not JSON (a proxy's page, a 500 in
// text), an error status. With `show` false an error status is not shown: the error thrown
// carries it (`detail`, `status`) for the caller to act on.
async function api(method, url, body, aliases = {}, signal = undefined, show = true) {
  let response;
  try {
    response = await fetch(url, {
      method, headers: body ? { "Content-Type": "application/json" } : {},
      body: body ? JSON.stringify(body) : undefined, signal,
    });
  } catch (error) {
    if (error.name !== "AbortError") {
      showErrors([{ loc: [], msg: `no answer from the service to ${method} ${url}: ${error.message}` }]);
    }
    throw error;
  }
  if (response.status === 204) return null;
  let answer = null;
  try { answer = await response.json(); } catch { answer = null; }  // none, or not JSON
  if (!response.ok || answer === null) {
    const status = `HTTP ${response.status}${response.statusText ? ` ${response.statusText}` : ""}`;
    const detail = answer && Array.isArray(answer.detail) ? answer.detail
      : [{ loc: [], msg: answer && answer.detail != null ? `${status}: ${answer.detail}`
        : `${status} from ${method} ${url}${response.ok ? ": the answer is not JSON" : ""}` }];
    if (show) showErrors(detail, aliases);
    const error = new Error(detail.map(detailText).join("; "));
    error.detail = detail; error.status = response.status;
    throw error;
  }
  return answer;
}

// ---- stale results go ----------------------------------------------------------------------
function clearMap() {
  state.map = null; state.cursor = null; state.tipCell = null; state.mapJob = null;
  if (state.optimum) state.optimum.canvas = null;  // the optimum stays, to mark the next map
  $("panels").textContent = "";
  $("tooltip").hidden = true;
  for (const id of ["summary", "ik-line", "best-mu", "best-where", "cb-label", "cb-min", "cb-max"]) $(id).textContent = "";
  delete $("summary").dataset.cells;
  delete $("summary").dataset.key;
  const bar = $("colourbar-canvas");
  bar.getContext("2d").clearRect(0, 0, bar.width, bar.height);
  $("colourbar").hidden = true;
  $("png-line").hidden = true;
  $("best-line").hidden = true;
}

function clearCell() {
  state.evaluation = null;  // an evaluation under way shows nothing (evaluateCell)
  $("cell-summary").textContent = "Click (or press Enter on) a cell to see V_max along the path and each joint's use of its limit at the feed.";
  for (const id of ["bottleneck", "acceleration", "cycle-time", "cell-verdict"]) $(id).textContent = "";
  const canvas = $("plot");
  canvas.getContext("2d").clearRect(0, 0, canvas.width, canvas.height);
  delete canvas.dataset.drawn;
}

function clearOptimum() {
  for (const id of ["opt-mu", "opt-acc", "opt-acc-binds", "opt-improvement", "opt-where", "opt-clearance", "opt-why", "opt-marked", "opt-own"]) $(id).textContent = "";
  $("opt-marked").hidden = true;
  $("opt-own").hidden = true;
  $("opt-acc-line").hidden = true;
  $("opt-clearance").hidden = true;
  $("opt-why").hidden = true;
  $("opt-mu-line").hidden = true;
  $("frames").tBodies[0].textContent = "";
  $("frames").hidden = true;
  if (state.optimum) {
    state.optimum = null;
    document.querySelectorAll(".panel canvas").forEach((c) => { delete c.dataset.optimum; paintPanel(c); });
  }
}

// The map and its clicked cell go (clearResults adds the optimum: a new map, path or robot).
// An optimum found while a map job runs is marked on its map once drawn (markOptimum),
// whichever of the two answers comes last.
function clearMapResults() {
  clearMap(); clearCell();
  $("bar").value = 0; $("eta").textContent = "";
  $("job-status").textContent = "no map yet";
}

function clearResults() {
  clearOptimum(); clearMapResults();
}

// Another path or robot: the map drawn (whose cells a click would evaluate with the new
// inputs), the clicked cell and the optimum are the old inputs' and go, and so does a map job,
// an optimisation or a cell's evaluation under way; the map's status says why.
function inputsChanged(why) {
  const drawn = state.map !== null;
  clearResults();
  dropRun(why);
  dropOptimization(why);
  if (drawn) {
    $("job-status").textContent = `map cleared: ${why}`;
    offerLastJob();  // a done map's job: shown again on request, with its own request
  }
  offerLastOptimisation();  // and the last optimisation job's, as the map's
}

// Nothing runs without a path: the reason there is none goes beside the path field.
function havePath() {
  if (state.path) return true;
  showErrors([{ loc: ["path"], msg: `No path to run: ${state.pathProblem}` }]);
  return false;
}

// ---- the colour map ------------------------------------------------------------------------
// The least and the largest of many numbers: Math.min(...values) throws a RangeError in
// Chromium past about 100,000 of them, and a map has up to millions of cells.
function extent(values) {
  let low = Infinity, high = -Infinity;
  for (const v of values) { if (v < low) low = v; if (v > high) high = v; }
  return [low, high];
}

function colour(fraction) {  // dark blue -> green -> yellow
  const stops = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  const t = Math.min(Math.max(fraction, 0), 1) * (stops.length - 1);
  const k = Math.min(Math.floor(t), stops.length - 2);
  const mix = stops[k].map((c, i) => Math.round(c + (stops[k + 1][i] - c) * (t - k)));
  return `rgb(${mix.join(",")})`;
}

// What the API changed in the URDF (robot_read: links no joint names left out, continuous
// joints read as revolute, joints off the chain locked), said after how its IK is solved.
function urdfRead(read) {
  if (!read) return "";
  const names = (list) => list.map((n) => `'${n}'`).join(", ");
  const more = read.left_out_count - read.left_out_links.length;
  return (read.left_out_links.length
    ? `; left out of the URDF, no joint names them: ${names(read.left_out_links)}` + (more ? ` and ${more} more` : "") : "")
    + (read.continuous_joints.length ? `; continuous joints read as revolute: ${names(read.continuous_joints)}` : "")
    + (read.unlimited_joints.length ? ` (no position limit: ${names(read.unlimited_joints)})` : "")
    + (read.locked_joints.length ? `; locked at 0, they move no tool: ${names(read.locked_joints)}` : "");
}

// A correction made in normalising the request's tool axes or quaternions (the answer's
// axis_correction), said above the rounding of a file's printed digits, 1e-6 (as dtf-place).
function normalisedText(correction) {
  return correction > 1e-6
    ? `; the request's tool axes or quaternions normalised, largest correction ${correction.toExponential(1)}` : "";
}

// The map's colour: mu_acc when the request gave acceleration limits (the API then fills it in
// every feasible cell and ranks best and worst by it), else mu_path.
function drawMap(answer) {
  state.map = answer;
  state.whereAcc = new Map();
  const cells = answer.cells;
  const key = cells.some((c) => c.mu_acc != null) ? "mu_acc" : "mu_path";
  const xs = [...new Set(cells.map((c) => c.x))];
  const ys = [...new Set(cells.map((c) => c.y))];
  const feasible = cells.filter((c) => c.mu_path !== null).map((c) => c[key]);
  const [low, high] = extent(feasible);
  const size = Math.min(48, Math.max(2, Math.floor(480 / Math.max(xs.length, ys.length))));
  state.scale = { low, high, xs, ys, size, key };
  const byAcc = cells.filter((c) => c.limited_by === "acceleration").length;
  const collisions = cells.filter((c) => c.reason === "collision").length;
  $("summary").textContent = `${cells.length} cells, ${answer.feasible_cells} feasible`
    + (key === "mu_acc" ? `; colour: mu_acc, limited by acceleration in ${byAcc} cells, by speed in ${answer.feasible_cells - byAcc}` : "")
    + (state.mapBody && state.mapBody.cell ? `; ${collisions} in collision with the cell` : "")
    + normalisedText(answer.axis_correction)
    + cellModel(answer);
  // How a URDF's IK was solved: the closed form where its chain was recognised (the API's
  // sentence: the arm, its frames, its parameters), else numeric IK, said as plainly.
  const urdf = state.mapBody && state.mapBody.robot && state.mapBody.robot.urdf;
  $("ik-line").textContent = !urdf ? ""
    : (answer.recognised ? `IK in closed form: ${answer.recognised}`
      : "IK numeric (damped least squares from seeds covering every joint's range): the URDF "
        + "chain from this base frame to this tool frame is no OPW or UR arm's")
      + urdfRead(answer.robot_read);
  $("summary").dataset.collisions = String(collisions);
  $("summary").dataset.cells = String(cells.length);
  $("summary").dataset.key = key;
  $("cb-label").textContent = `${key} (m/s)`;
  $("best-mu").textContent = !answer.best ? "none feasible"
    : key === "mu_acc" ? `mu_acc ${answer.best.mu_acc.toFixed(6)} m/s (mu_path ${answer.best.mu_path.toFixed(6)} m/s)`
    : answer.best.mu_path.toFixed(6) + " m/s";
  // The spin too where the map has spins other than 0 (or the spin is free: its start).
  const spun = cells.some((c) => c.spin !== 0) || answer.spin_mode === "free";
  $("best-where").textContent = answer.best
    ? `at x ${metres(answer.best.placement.x)}, y ${metres(answer.best.placement.y)}, yaw ${radians(answer.best.placement.yaw)}`
      + (spun ? `, spin ${radians(answer.best.placement.spin)}${answer.spin_mode === "free" ? " + free rate" : ""}` : "")
    : "";
  $("colourbar").hidden = false;
  $("best-line").hidden = false;
  $("png-line").hidden = false;
  $("png-status").textContent = "";
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
    const spin = `spin ${radians(head.spin)}${answer.spin_mode === "free" ? " + free rate" : ""}`;
    const title = `yaw ${radians(head.yaw)} (${fixed((head.yaw * 180) / Math.PI, 2)} deg), ${spin}`;
    canvas.setAttribute("aria-label", `map at ${title}`);
    figure.dataset.title = title;
    figure.append(withAxes(canvas, xs, ys, state.scale.size, title));
    panels.appendChild(figure);
    paintPanel(canvas);
    canvas.addEventListener("mousemove", (e) => hover(canvas, e));
    canvas.addEventListener("mouseleave", () => { $("tooltip").hidden = true; state.tipCell = null; });
    canvas.addEventListener("blur", () => { $("tooltip").hidden = true; state.tipCell = null; });
    canvas.addEventListener("click", (e) => { const c = cellAt(canvas, e); if (c) evaluateCell(c); });
    canvas.addEventListener("keydown", (e) => keys(canvas, e));
  }
  markOptimum();
}

function paintPanel(canvas) {
  const { low, high, xs, ys, key } = state.scale;
  const g = canvas.getContext("2d");
  const first = Number(canvas.dataset.first);
  for (let k = 0; k < xs.length * ys.length; k++) {
    const c = state.map.cells[first + k];
    const i = k % xs.length, j = Math.floor(k / xs.length);
    g.fillStyle = c.mu_path === null ? REASON_COLOURS[c.reason]
      : colour(high > low ? (c[key] - low) / (high - low) : 1);
    g.fillRect(i * state.scale.size, (ys.length - 1 - j) * state.scale.size, state.scale.size, state.scale.size);
  }
  if (state.cursor && state.cursor.canvas === canvas) {
    g.strokeStyle = "#fff"; g.lineWidth = 2;
    g.strokeRect(state.cursor.i * state.scale.size + 1, (ys.length - 1 - state.cursor.j) * state.scale.size + 1,
      state.scale.size - 2, state.scale.size - 2);
  }
  if (state.optimum && state.optimum.canvas === canvas) drawMarker(canvas, state.optimum.placement);
}

// The cell under the pointer, from the canvas's drawing area (inside any border it has).
function cellAt(canvas, event) {
  const box = canvas.getBoundingClientRect();
  const { xs, ys } = state.scale;
  const left = box.left + canvas.clientLeft, top = box.top + canvas.clientTop;
  const i = Math.floor((event.clientX - left) / state.scale.size);
  const j = ys.length - 1 - Math.floor((event.clientY - top) / state.scale.size);
  if (i < 0 || i >= xs.length || j < 0 || j >= ys.length) return null;
  return state.map.cells[Number(canvas.dataset.first) + j * xs.length + i];
}

function describe(c) {
  const lines = [`x ${c.x.toFixed(4)} m, y ${c.y.toFixed(4)} m, yaw ${c.yaw.toFixed(4)} rad`];
  if (c.mu_path === null) {
    lines.push(`infeasible: ${c.reason} at waypoint ${c.failed_waypoint}`);
    if (c.reason === "collision") {  // the map's cell says where, the evaluation what hits what
      const contact = state.whereAcc.get(cellKey(c));
      lines.push(contact ? collisionText(contact, state.mapBody.cell) : "what hits what: asking the API…");
    }
  } else {
    lines.push(`mu_path ${c.mu_path.toFixed(6)} m/s`);
    lines.push(`bottleneck: joint ${c.bottleneck_joint + 1}, waypoint ${c.bottleneck_waypoint}`);
    if (c.mu_acc != null) {
      lines.push(`mu_acc ${c.mu_acc.toFixed(6)} m/s, limited by ${c.limited_by}`);
      if (c.limited_by === "speed") {
        lines.push(`where: the speed bottleneck (joint ${c.bottleneck_joint + 1}, waypoint ${c.bottleneck_waypoint})`);
      } else {
        const where = state.whereAcc.get(cellKey(c));
        lines.push(where ? `where: joint ${where.joint + 1} (${where.joint_name}), waypoint ${where.waypoint}`
          : "where: asking the API…");
      }
    }
    lines.push(`branch ${Object.values(c.branch || {}).join("/")}`);
  }
  return lines.join("\n");
}

function cellKey(c) { return `${c.x} ${c.y} ${c.yaw} ${c.spin}`; }

// A map cell says whether acceleration binds, not where, and that it collides, not with what:
// the summary evaluation of the cell hovered (or under the keyboard cursor) gives them, asked
// once per cell and kept.
function askWhere(c) {
  const collides = c.reason === "collision";
  if (!collides && (c.mu_acc == null || c.limited_by !== "acceleration")) return;
  if (state.whereAcc.has(cellKey(c))) return;
  state.whereAcc.set(cellKey(c), null);
  const body = { ...state.mapBody, placement: placementOf(c), detail: "summary" };
  delete body.grid;
  api("POST", "/v1/evaluate", body).then((answer) => {
    state.whereAcc.set(cellKey(c), collides ? answer.collision : answer.acceleration);
    if (state.tipCell === c) {
      $("tooltip").textContent = describe(c);
      $("tooltip").dataset.where = "1";
      placeTip();  // longer now: kept inside the window
    }
  }).catch(() => state.whereAcc.delete(cellKey(c)));
}

function placementOf(c) {
  return { x: c.x, y: c.y, z: state.grid.z, yaw: c.yaw, spin: c.spin };
}

function showTip(c) {
  const tip = $("tooltip");
  state.tipCell = c;
  delete tip.dataset.where;
  tip.textContent = describe(c);
  // Asked once the pointer rests on the cell: a sweep over a large map sends no request a cell.
  clearTimeout(state.whereTimer);
  state.whereTimer = setTimeout(() => { if (state.tipCell === c) askWhere(c); }, 150);
}

function hover(canvas, event) {
  const c = cellAt(canvas, event);
  const tip = $("tooltip");
  if (!c) { tip.hidden = true; state.tipCell = null; return; }
  if (state.tipCell !== c) showTip(c);
  state.tipAt = { x: event.clientX, y: event.clientY };
  tip.hidden = false;
  placeTip();
}

// The tooltip beside state.tipAt (a window point), inside the window: to the right of and
// below the point where it fits, else to its left or above it, else against the window's edge.
function placeTip() {
  const tip = $("tooltip"), at = state.tipAt;
  if (!at || tip.hidden) return;
  const width = tip.offsetWidth, height = tip.offsetHeight, gap = 12, edge = 4;
  const room = (size, space) => Math.max(edge, space - size - edge);
  let left = at.x + gap, top = at.y + gap;
  if (left + width > window.innerWidth - edge) left = at.x - gap - width;
  if (top + height > window.innerHeight - edge) top = at.y - gap - height;
  left = Math.min(Math.max(left, edge), room(width, window.innerWidth));
  top = Math.min(Math.max(top, edge), room(height, window.innerHeight));
  tip.style.left = `${left}px`; tip.style.top = `${top}px`;
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
    showTip(cell());
    // Shown beside the cell under the cursor (a role="status" region: read out as it changes).
    const box = canvas.getBoundingClientRect(), size = state.scale.size;
    state.tipAt = {
      x: box.left + canvas.clientLeft + (cur.i + 1) * size,
      y: box.top + canvas.clientTop + (ys.length - cur.j) * size,
    };
    $("tooltip").hidden = false;
    placeTip();
  } else if (event.key === "Enter") {
    event.preventDefault();
    state.cursor = cur;
    evaluateCell(cell());
  }
}

// ---- one placement: V_max and joint use along the path ---------------------------------------
// The evaluation under way is state.evaluation, a token: one no longer there (clearCell: a new
// click, map, path or robot came meanwhile) shows nothing of its answers.
// A cell is evaluated with its map's own request (the robot, its limits, the path, the IK
// options, the spin mode and the cell the map was computed with), as its hover text is: the
// form edited since the map (a joint limit, the cell's table) would otherwise give a cell
// another answer than its colour's. Only the feed to check is the form's.
async function evaluateCell(c) {
  clearErrors();
  clearCell();
  const map = state.mapBody;
  if (!map) return;
  if (unreadNumbers((id) => id !== "feed")) {  // the map's own inputs, and the feed typed
    $("cell-summary").textContent = "no evaluation: see the errors above";
    return;
  }
  const evaluation = {};
  state.evaluation = evaluation;
  const body = { ...map, placement: placementOf(c), feed: value("feed") };
  delete body.grid;
  $("cell-summary").textContent = "evaluating…";
  const answer = await api("POST", "/v1/evaluate", body).catch(() => null);
  if (state.evaluation !== evaluation) return;
  if (!answer) { $("cell-summary").textContent = "no evaluation: see the errors above"; return; }
  const where = `x ${metres(c.x)}, y ${metres(c.y)}, yaw ${radians(c.yaw)}`;
  // The feed checked: the field's, else the program's (CL data), else none (the field empty).
  body.feed = answer.feed_check ? answer.feed_check.feed : undefined;
  const use = body.feed === undefined ? "; no feed to check"
    : `; at ${fixed(body.feed, 6)} m/s the largest joint use is ${(100 * body.feed / answer.mu_path).toFixed(1)} %`;
  $("cell-summary").textContent = (answer.feasible
    ? `${where}: mu_path ${answer.mu_path.toFixed(6)} m/s${use}`
    : `${where}: infeasible (${answer.reason} at waypoint ${answer.failed_waypoint})`)
    + normalisedText(answer.axis_correction)
    + (formChanged(map) ? " (with the map's inputs: the form has changed since; run the map again for its own)" : "");
  $("cell-verdict").textContent = cellVerdict(answer, body.cell);
  if (answer.feasible && answer.spin_mode === "free") await compareFixedSpin(body, answer);
  if (state.evaluation !== evaluation) return;
  const b = answer.bottleneck;
  $("bottleneck").textContent = b ? `bottleneck: waypoint ${b.waypoint}, joint ${b.joint + 1} (${b.joint_name})` : "";
  $("bottleneck").dataset.waypoint = b ? String(b.waypoint) : "";
  $("bottleneck").dataset.joint = b ? String(b.joint) : "";
  showAcceleration(answer, body);
  plot(answer, body);
}

// The map drawn as the API draws it (panels, colour bar, reasons' colours, best and worst
// marked), saved as a file: the map's job's picture (GET /v1/jobs/{id}/png, drawn from its
// stored cells, any size), or where the job is gone (deleted, expired) POST /v1/map/png with the
// map's own request, which computes it again within a request's limits.
async function savePng() {
  const body = state.mapBody;
  if (!body) return;
  $("png-status").textContent = "drawing…";
  $("png").disabled = true;  // one picture at a time
  try { await downloadPng(body, state.mapJob); } finally { $("png").disabled = false; }
}

async function downloadPng(body, job) {
  let response;
  try {
    if (job) response = await fetch(`/v1/jobs/${job}/png`);
    if (!response || response.status === 404) {
      response = await fetch("/v1/map/png", {
        method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
      });
    }
  } catch (error) { $("png-status").textContent = `no picture: no answer (${error.message})`; return; }
  if (state.mapBody !== body) return;  // another map meanwhile
  if (!response.ok) {
    let said = `HTTP ${response.status}`;
    try { said = (await response.json()).detail.map(detailText).join("; "); } catch { /* not JSON */ }
    $("png-status").textContent = `no picture: ${said}`;
    return;
  }
  const link = document.createElement("a");
  link.href = URL.createObjectURL(await response.blob());
  link.download = "dtf-map.png";
  link.click();
  setTimeout(() => URL.revokeObjectURL(link.href), 10_000);
  $("png-status").textContent = "saved as dtf-map.png";
}

// Whether the form now asks another map than ``map`` (its grid aside): a robot, limit, path,
// IK option, spin mode or cell edited since.
function formChanged(map) {
  try {
    const now = mapBody(), then = { ...map };
    delete now.grid; delete then.grid;
    return JSON.stringify(now) !== JSON.stringify(then);
  } catch { return true; }  // a robot object that is no longer JSON
}

// With the spin free, what it is worth: mu_path with the spin fixed at the same placement.
async function compareFixedSpin(body, answer) {
  const summary = { ...body, spin_mode: "fixed", detail: "summary" };
  delete summary.feed;
  const evaluation = state.evaluation;
  const fixedSpin = await api("POST", "/v1/evaluate", summary).catch(() => null);
  if (!fixedSpin || state.evaluation !== evaluation) return;
  const gain = fixedSpin.feasible ? 100 * (answer.mu_path / fixedSpin.mu_path - 1) : 0;
  $("cell-summary").textContent += fixedSpin.feasible
    ? `; spin free: ${gain >= 0 ? "+" : ""}${fixed(gain, 0)} % over the spin fixed (${fixedSpin.mu_path.toFixed(6)} m/s)`
    : `; with the spin fixed the path is infeasible here (${fixedSpin.reason})`;
}

// mu_acc, what binds it and where; the cycle time at mu_acc, with the ramps, time-optimal.
function showAcceleration(answer, body) {
  const acc = answer.acceleration, t = answer.cycle_time;
  const line = $("acceleration");
  line.textContent = "";
  if (acc) {
    const where = acc.limited_by === "speed" ? "a speed limit binds (the bottleneck above)"
      : `the acceleration limit of joint ${acc.joint + 1} (${acc.joint_name}) binds at waypoint ${acc.waypoint}`;
    const use = accelerationUse(answer, body);
    const peak = use ? Math.max(extent(use.flatMap((row) => (row ? row : [])))[1], 0) : null;
    line.textContent = `mu_acc ${acc.mu_acc.toFixed(6)} m/s (blend ${(1000 * acc.blend_length).toFixed(3)} mm): ${where}`
      + (peak === null ? "" : `; at ${fixed(body.feed, 6)} m/s the largest acceleration use is ${(100 * peak).toFixed(1)} %`)
      + (answer.feed_check ? (answer.feed_check.feasible ? " (the feed runs)" : " (the feed does NOT run)") : "");
  }
  $("cycle-time").textContent = t
    ? `cycle time: ${t.constant_feed_time.toFixed(3)} s at the constant feed mu_acc, ${t.ramp.toFixed(3)} s with the ramps at the pass ends, ${t.time_optimal.toFixed(3)} s time-optimal (feed free along the path)`
    : (acc ? "cycle time: none (mu_acc is 0)" : "");
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
  $("robot-json").addEventListener("input", showOwnRobot);
  $("urdf").addEventListener("input", showOwnRobot);
  // Another robot (the catalogue's, a URDF and its frames, a robot object): the map, the cell
  // and the optimum, shown or being computed, are not its own. Its speed and acceleration
  // limits, edited, leave them be, as edited grid fields do.
  for (const [id, event] of [["robot-model", "change"], ["robot-json", "input"], ["urdf", "input"],
    ["urdf-file", "change"], ["base-frame", "input"], ["tool-frame", "input"]]) {
    $(id).addEventListener(event, () => inputsChanged("the robot changed"));
  }
  $("urdf").addEventListener("change", readUrdfLinks);
  $("base-frame").addEventListener("input", showBaseHint);
  $("urdf-file").addEventListener("change", async () => {
    const file = $("urdf-file").files[0];
    if (!file) return;
    $("urdf").value = await file.text();
    readUrdfLinks();
    showOwnRobot();
  });
  $("yaws").addEventListener("input", showYawRange);
  for (const [id, plural] of [["yaws", "yaws"], ["spins", "spins"]]) {
    $(id).addEventListener("input", () => showListReading(id, plural));
    showListReading(id, plural);
  }
  $("opt-any-yaw").addEventListener("change", showYawRange);
  showYawRange();
  clearResults();
  $("path-example").addEventListener("change", loadExample);
  $("path-file").addEventListener("change", async () => {
    const file = $("path-file").files[0];
    if (file) await setPath(file.name, await file.text());
  });
  $("path-file").addEventListener("click", () => { $("path-file").value = ""; });  // the same file again
  $("path-units").addEventListener("change", () => {
    if (state.source) setPath(state.source.name, state.source.text);
  });
  $("inputs").addEventListener("submit", runMap);
  $("cancel").addEventListener("click", cancelMap);
  $("optimize").addEventListener("click", optimize);
  $("opt-cancel").addEventListener("click", stopOptimization);
  $("png").addEventListener("click", savePng);
  startCellEditor();
  state.limits = await fetch("/v1/limits").then((r) => (r.ok ? r.json() : null)).catch(() => null);
  await loadExample();
  await offerLastJob();
  await listEarlierMaps();
  await offerLastOptimisation();
  document.body.dataset.ready = "1";
}

start();
