// The optimum: the search within the grid's x and y bounds and the optimiser's yaw range, its
// figures, its controller frames (format.js) and its marker on the nearest panel.
"use strict";

function drawMarker(canvas, p) {
  const { xs, ys } = state.scale;
  const dx = xs.length > 1 ? xs[1] - xs[0] : 1, dy = ys.length > 1 ? ys[1] - ys[0] : 1;
  const px = ((p.x - xs[0]) / dx + 0.5) * state.scale.size, py = (ys.length - 0.5 - (p.y - ys[0]) / dy) * state.scale.size;
  const g = canvas.getContext("2d");
  g.strokeStyle = "#d50000"; g.lineWidth = 3; g.beginPath();
  g.moveTo(px - 7, py - 7); g.lineTo(px + 7, py + 7); g.moveTo(px + 7, py - 7); g.lineTo(px - 7, py + 7);
  g.stroke();
}

// The optimiser's yaw range: any yaw, the two fields, or (a field empty) the yaws' range.
function yawRange(grid) {
  if ($("opt-any-yaw").checked) return [-Math.PI, Math.PI];
  const low = value("opt-yaw-min"), high = value("opt-yaw-max");
  const yaws = grid.yaw.length ? grid.yaw : [undefined];
  return [low ?? Math.min(...yaws), high ?? Math.max(...yaws)];
}

// The height searched: the grid's z (fixed: the request's z), or a range (bounds.z, and the
// request without z), an empty end being the grid's z.
function heightOf(grid) {
  const low = value("opt-z-min"), high = value("opt-z-max");
  if (low === undefined && high === undefined) return { z: grid.z };
  return { range: [low ?? grid.z, high ?? grid.z] };
}

// The constant tool spin searched (bounds.spin): left out when both ends are empty (0).
function spinRange() {
  const low = value("opt-spin-min"), high = value("opt-spin-max");
  return low === undefined && high === undefined ? undefined : [low ?? 0, high ?? 0];
}

// The start placement (the part now), or undefined (the API's default: the bounds' centre).
// A field left empty beside filled ones is sent as null: the API says so beside them. Its z and
// spin are the middles of their ranges where they are searched (the grid's z, no spin else).
function startOf(height, spins) {
  const ids = ["opt-start-x", "opt-start-y", "opt-start-yaw"];
  if (ids.every((id) => $(id).value.trim() === "")) return undefined;
  const [x, y, yaw] = ids.map((id) => value(id) ?? null);
  const z = height.range ? (height.range[0] + height.range[1]) / 2 : height.z;
  const start = { x, y, z, yaw };
  if (spins) start.spin = (spins[0] + spins[1]) / 2;
  return start;
}

function showYawRange() {
  const any = $("opt-any-yaw").checked;
  const yaws = numbers($("yaws").value).filter(Number.isFinite);
  for (const [id, pick] of [["opt-yaw-min", Math.min], ["opt-yaw-max", Math.max]]) {
    $(id).disabled = any;
    $(id).placeholder = yaws.length ? String(pick(...yaws)) : "";
  }
}

// The optimiser's bounds are the grid's fields (and the yaw range's): its errors go there.
const BOUND_FIELDS = {
  "bounds.x.0": "grid.x.min", "bounds.x.1": "grid.x.max", "bounds.y.0": "grid.y.min",
  "bounds.y.1": "grid.y.max", "bounds.x": "grid.x.min", "bounds.y": "grid.y.min", z: "grid.z",
};

// A search the service refuses as more work than a request may take: its 422 says that
// POST /v1/jobs runs it (the routes' size limits' own words, DTF_MAX_MAP_POSES and the like).
function needsJob(error) {
  return error.status === 422 && Array.isArray(error.detail)
    && error.detail.some((d) => String(d.msg).includes("POST /v1/jobs"));
}

// The same search as a job (api.md "Jobs", kind "optimize"): its progress shown on the
// optimum's line until it ends; its answer is the route's. Null when it failed (said), was
// cancelled, or the run was dropped meanwhile (its job then cancelled).
async function optimizeAsJob(body, run) {
  $("opt-mu").textContent = "more work than a request may take: submitting it as a job…";
  const job = await api("POST", "/v1/jobs", { kind: "optimize", request: body }, BOUND_FIELDS)
    .catch(() => null);
  if (!job) return null;
  run.jobId = job.id;
  if (state.optimization !== run) { cancelJob(job.id); return null; }
  rememberOptimisation(job.id);
  return watchOptimisation(job.id, run);
}

// An optimisation job watched to its end: its answer, or null (failed: said; cancelled; the
// run dropped meanwhile; its status unreadable: said).
async function watchOptimisation(id, run) {
  for (let failed = 0; ;) {
    let status = null;
    try { status = await getJson(`/v1/jobs/${id}`); failed = 0; } catch (error) {
      if (++failed > POLL_RETRIES_MS.length) {
        if (state.optimization === run) $("opt-mu").textContent = `no optimum: the job's status could not be read (${error.message})`;
        return null;
      }
    }
    if (state.optimization !== run) return null;
    if (status && status.status === "done") return status.result;
    if (status && status.status === "failed") { showErrors(status.error, BOUND_FIELDS); return null; }
    if (status && status.status === "cancelled") return null;
    if (status) {
      const eta = status.progress.eta_seconds;
      $("opt-mu").textContent = `optimising as job ${id}: ${(100 * status.progress.fraction).toFixed(0)} %`
        + (eta == null ? "" : `, about ${eta.toFixed(0)} s left`);
    }
    await new Promise((resolve) => setTimeout(resolve, failed ? POLL_RETRIES_MS[failed - 1] : 500));
  }
}

// The last optimisation job submitted from this browser (localStorage), as the last map job
// (job.js): a page reloaded while it ran, or after, shows it again on request, watched to its
// end if it still runs, with its own request (GET /v1/jobs/{id}/request), whatever the form
// holds. Its optimum is not marked on the map, which may be another request's.
const LAST_OPTIMISATION_KEY = "dtf-placement.last-optimisation-job";

function rememberOptimisation(id) {
  try { localStorage.setItem(LAST_OPTIMISATION_KEY, id); } catch { /* storage refused */ }
}

async function offerLastOptimisation() {
  $("opt-resume").hidden = true;
  const job = await rememberedJob(LAST_OPTIMISATION_KEY);
  if (!job) return;  // failed or cancelled: nothing to show
  if (state.optimization || state.optimum) return;  // one run or shown meanwhile
  const id = job.id;
  const when = new Date(job.created * 1000).toLocaleString();
  const done = job.status === "done" ? "done" : `${job.status}, ${(100 * job.progress.fraction).toFixed(0)} %`;
  $("opt-resume-text").textContent = `Your last optimisation, job ${id} (submitted ${when}): ${done}.`;
  $("opt-resume").hidden = false;
  $("opt-resume-show").onclick = () => resumeOptimisation(id);
}

async function resumeOptimisation(id) {
  clearErrors();
  const asked = await api("GET", `/v1/jobs/${id}/request`).catch(() => null);
  if (!asked) return;
  clearOptimum();
  dropOptimization("an earlier optimisation was shown");
  $("opt-resume").hidden = true;
  const run = { abort: new AbortController(), jobId: id, resumed: true };
  state.optimization = run;
  $("opt-cancel").disabled = false;
  $("opt-mu").textContent = `optimising as job ${id}…`;
  $("opt-mu-line").hidden = false;
  const answer = await watchOptimisation(id, run);
  if (state.optimization !== run) return;
  state.optimization = null;
  $("opt-cancel").disabled = true;
  showOptimum(answer, asked.request);
  if (!answer) return;
  if (state.optimum) state.optimum.resumed = true;
  $("opt-own").textContent = `Job ${id}'s optimum, with the job's own inputs (the form keeps yours)`
    + (state.optimum ? ": not marked on the map, which may be of other inputs." : ".");
  $("opt-own").hidden = false;
}

// The optimisation under way is state.optimization ({abort}: its request's AbortController;
// {jobId} once it runs as a job); one no longer there was dropped (dropOptimization, or a
// newer click) and shows nothing.
async function optimize() {
  clearErrors();
  clearOptimum();
  dropOptimization("a newer optimisation");  // a newer click: the older goes (its job too)
  $("opt-resume").hidden = true;
  if (!havePath()) return;
  if (unreadNumbers((id) => id === "feed" || id === "x-step" || id === "y-step")) {
    $("opt-mu").textContent = "no optimum: see the errors above";
    return;
  }
  const grid = gridBody();
  const height = heightOf(grid);
  if (height.range ? height.range.includes(undefined) : grid.z === undefined) {
    showErrors([{ loc: ["grid", "z"], msg: "Field required: the optimiser searches at this height"
      + (height.range ? " (the height range's empty end)" : "") }]);
    return;
  }
  let robot;
  try { robot = robotBody(); } catch (error) { showErrors([{ loc: ["robot"], msg: error.message }]); return; }
  const ik = ikBody();
  delete ik.branch;  // the optimiser takes the fastest branch (ik.branch "auto" only)
  const spins = spinRange();
  const body = {
    robot, path: state.path, method: $("method").value, z: height.z, ik,
    bounds: {
      x: [grid.x.min, grid.x.max], y: [grid.y.min, grid.y.max], yaw: yawRange(grid),
      z: height.range, spin: spins,
    },
    start: startOf(height, spins), spin_mode: spinMode(), cell: cellBody(),
  };
  const run = { abort: new AbortController(), jobId: null };
  state.optimization = run;
  $("opt-cancel").disabled = false;
  $("opt-mu").textContent = "optimising…";
  $("opt-mu-line").hidden = false;
  let answer = await api("POST", "/v1/optimize", body, BOUND_FIELDS, run.abort.signal, false)
    .catch((error) => error);
  if (answer instanceof Error) {
    if (state.optimization === run && needsJob(answer)) answer = await optimizeAsJob(body, run);
    else {
      if (state.optimization === run && answer.detail) showErrors(answer.detail, BOUND_FIELDS);
      answer = null;
    }
  }
  if (state.optimization !== run) return;  // dropped meanwhile: its answer is not the inputs'
  state.optimization = null;
  $("opt-cancel").disabled = true;
  showOptimum(answer, body);
  if (state.optimum) markOptimum();
}

// An optimisation's answer (null: none, the errors said) for its request ``body``: its
// figures, its placement and its frames (state.optimum, not yet marked).
function showOptimum(answer, body) {
  if (!answer) { $("opt-mu").textContent = "no optimum: see the errors above"; return; }
  if (!answer.found) {
    $("opt-mu").textContent = body.cell ? "no feasible placement free of collisions" : "no feasible placement";
    if (answer.failure) {  // why: the start's failure and what the search tried, by reason
      $("opt-why").textContent = `Why: ${answer.failure.message}.`;
      $("opt-why").hidden = false;
    }
    return;
  }
  if (body.cell && answer.evaluation) {
    $("opt-clearance").textContent = cellVerdict(answer.evaluation, body.cell);
    $("opt-clearance").hidden = false;
  }
  const p = answer.placement;
  $("opt-mu").textContent = `${answer.mu_path.toFixed(6)} m/s`;
  const start = answer.start.mu_path === null ? "infeasible" : answer.start.mu_path.toFixed(6) + " m/s";
  // improvement_percent is of mu_acc with acceleration limits (what the search maximised), so
  // it goes on the mu_acc line then; the start's mu_path is all the answer gives of the start.
  const gain = answer.improvement_percent === null ? "" : `+${answer.improvement_percent.toFixed(2)} %`;
  $("opt-improvement").textContent = answer.mu_acc == null
    ? `(${gain}${gain ? " " : ""}over the start, ${start})` : `(the start's mu_path: ${start})`;
  if (answer.mu_acc != null) {
    const acc = answer.evaluation && answer.evaluation.acceleration;
    $("opt-acc").textContent = `${answer.mu_acc.toFixed(6)} m/s`;
    $("opt-acc-binds").textContent = (gain ? `(${gain} over the start's mu_acc) ` : "")
      + (!acc ? "" : acc.limited_by === "speed" ? "a speed limit binds"
        : `the acceleration of joint ${acc.joint + 1} (${acc.joint_name}) binds at waypoint ${acc.waypoint}`);
    $("opt-acc-line").hidden = false;
  }
  $("opt-where").textContent = `x ${metres(p.x)}, y ${metres(p.y)}, z ${metres(p.z)}, yaw ${radians(p.yaw)} (${fixed((p.yaw * 180) / Math.PI, 2)} deg)`
    + (answer.evaluation && answer.evaluation.spin_mode === "free" ? ", spin free" : `, spin ${radians(p.spin)}`);
  const rows = $("frames").tBodies[0];
  for (const frame of CONTROLLER_FRAMES) {
    const row = rows.insertRow();
    row.dataset.controller = frame.key;
    const text = frame.text(p.frames[frame.key]);
    row.insertCell().textContent = frame.name;
    const code = document.createElement("code");
    code.textContent = text;
    row.insertCell().appendChild(code);
    row.insertCell().textContent = frame.units;
    const copy = document.createElement("button");
    copy.type = "button"; copy.textContent = "Copy";
    copy.setAttribute("aria-label", `Copy the ${frame.name} frame`);
    copy.addEventListener("click", () => navigator.clipboard && navigator.clipboard.writeText(text));
    row.insertCell().appendChild(copy);
  }
  $("frames").hidden = false;
  state.optimum = { canvas: null, placement: p };
}

// The optimum shown (state.optimum), marked on the map drawn, if any, on the panel whose yaw
// is nearest the optimum's: called by both answers, the optimiser's and the map's.
function markOptimum() {
  const canvases = [...document.querySelectorAll(".panel canvas")];
  if (!state.optimum || state.optimum.resumed || !state.map || !canvases.length) return;
  const p = state.optimum.placement;
  const yaws = canvases.map((c) => state.map.cells[Number(c.dataset.first)].yaw);
  const k = yaws.reduce((best, y, i) => (Math.abs(y - p.yaw) < Math.abs(yaws[best] - p.yaw) ? i : best), 0);
  state.optimum.canvas = canvases[k];
  canvases.forEach(paintPanel);
  canvases[k].dataset.optimum = "1";
  // Marked on the nearest panel's yaw: said where that is not the optimum's own.
  const note = $("opt-marked");
  note.hidden = Math.abs(yaws[k] - p.yaw) <= 1e-9;
  note.textContent = note.hidden ? ""
    : `Marked at its x and y on the map's panel at yaw ${radians(yaws[k])}, the nearest of the map's yaws to the optimum's ${radians(p.yaw)} (${fixed((p.yaw * 180) / Math.PI, 2)} deg).`;
}

// A new path or robot while an optimisation runs: its request is aborted (the service stops the
// search when its client goes) and its answer, of the old inputs, never shown; the status says so.
// An earlier job shown again (resumeOptimisation) is not this form's: it is left to run (unless
// ``stop``: "Stop optimising" was clicked) and offered again.
function dropOptimization(why, stop = false) {
  const run = state.optimization;
  if (!run) return;
  state.optimization = null;
  $("opt-cancel").disabled = true;
  run.abort.abort();
  clearOptimum();
  $("opt-mu-line").hidden = false;
  if (run.resumed && !stop) {
    $("opt-mu").textContent = `no longer watched (job ${run.jobId} runs on): ${why}`;
    offerLastOptimisation();
    return;
  }
  if (run.jobId) cancelJob(run.jobId);
  $("opt-mu").textContent = `cancelled: ${why}`;
}

function stopOptimization() {
  dropOptimization("stopped from the page", true);
}
