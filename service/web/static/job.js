// The map job: submitted once, watched to its end (its polls retried), its cells read in pages
// when there are many, dropped when the path or the robot changes, cancelled from the page.
// Loaded before app.js, whose functions (api, mapBody, drawMap, ...) it calls.
"use strict";

// One map at a time: from the first submit until its job ends, Run is disabled and a second
// submit (a double click, Enter in a field) is none, so Cancel reaches the only job. The run
// under way is state.run ({id}: its job's, once submitted); a run no longer in state.run was
// dropped (dropRun) and whatever its requests answer later is not shown.
async function runMap(event) {
  event.preventDefault();
  if (state.run) return;
  clearErrors();
  // A new map is asked with the inputs as they are now: an optimum found for earlier ones (the
  // cell edited since, say) is not marked on it, and one under way is cancelled.
  clearResults();
  dropOptimization("a map was run; optimise again for its inputs");
  if (!havePath()) return;
  if (unreadNumbers((id) => id.startsWith("opt-") || id === "feed")) {
    $("job-status").textContent = "no map: see the errors above";
    return;
  }
  let body;
  try { body = mapBody(); } catch (error) { showErrors([{ loc: ["robot"], msg: error.message }]); return; }
  const run = { id: null };
  state.run = run; $("run").disabled = true;
  $("resume").hidden = true; disableEarlier();
  $("job-status").textContent = "submitting the map…";
  const job = await api("POST", "/v1/jobs", { kind: "map", request: body }).catch(() => null);
  if (state.run !== run) { if (job) cancelJob(job.id); return; }  // dropped while submitted
  if (!job) { endRun(); $("job-status").textContent = "no map: see the errors above"; return; }
  run.id = job.id; state.grid = body.grid; state.mapBody = body;
  rememberJob(job.id);
  $("resume").hidden = true;
  $("cancel").disabled = false;
  await watch(run);
}

// The last map job submitted from this browser (localStorage): a page reloaded while it ran, or
// after, shows it again on request, watched to its end if it still runs, its cells evaluated
// with its own request (GET /v1/jobs/{id}/request), whatever the form holds.
const LAST_JOB_KEY = "dtf-placement.last-map-job";
// The statuses of a map job shown again: drawn once done, watched until then.
const DRAWABLE = ["queued", "running", "done"];

function rememberJob(id) {
  try { localStorage.setItem(LAST_JOB_KEY, id); } catch { /* storage refused: nothing kept */ }
}

// The job this browser remembers under ``key`` (localStorage), if it can still be shown:
// queued, running or done. A job the service no longer holds (deleted or expired) is forgotten.
async function rememberedJob(key) {
  let id = null;
  try { id = localStorage.getItem(key); } catch { return null; }
  if (!id) return null;
  let job;
  try { job = await getJson(`/v1/jobs/${id}`); } catch (error) {
    if (error.status === 404) localStorage.removeItem(key);
    return null;
  }
  return DRAWABLE.includes(job.status) ? job : null;
}

async function offerLastJob() {
  const job = await rememberedJob(LAST_JOB_KEY);
  if (!job) return;  // nothing of it to draw
  const id = job.id;
  if (state.run || state.map) return;  // a map run or drawn meanwhile: it is the one shown
  const when = new Date(job.created * 1000).toLocaleString();
  $("resume-text").textContent = `Your last map, job ${id} (submitted ${when}): `
    + `${job.status}, ${job.progress.done} of ${job.progress.total} placements.`;
  $("resume").hidden = false;
  $("resume-show").onclick = () => resumeMap(id);
}

// The service's map jobs, newest first (this browser's and other clients': GET /v1/jobs holds
// them until DTF_JOB_TTL), each shown again on request with its own request, as the last one.
const EARLIER_MAPS = 10;

async function listEarlierMaps() {
  let listed;
  try { listed = await getJson("/v1/jobs?kind=map&limit=100"); } catch { return; }  // no store
  const maps = listed.jobs
    .filter((j) => DRAWABLE.includes(j.status))
    .slice(0, EARLIER_MAPS);
  const list = $("earlier-list");
  list.textContent = "";
  for (const job of maps) {
    const item = document.createElement("li");
    item.dataset.job = job.id;
    item.textContent = `${new Date(job.created * 1000).toLocaleString()}: job ${job.id}, `
      + `${job.status}, ${job.progress.total} placements `;
    const show = document.createElement("button");
    show.type = "button"; show.textContent = "Show";
    show.addEventListener("click", () => resumeMap(job.id));
    item.append(show);
    list.append(item);
  }
  $("earlier").hidden = maps.length === 0;
}

// While a map runs, no other is shown (listEarlierMaps enables them again as it ends).
function disableEarlier() {
  for (const button of $("earlier-list").querySelectorAll("button")) button.disabled = true;
}

async function resumeMap(id) {
  if (state.run) return;
  clearErrors();
  const asked = await api("GET", `/v1/jobs/${id}/request`).catch(() => null);
  if (!asked || state.run) return;
  clearResults();
  dropOptimization("an earlier map was shown; optimise again for its inputs");
  $("resume").hidden = true;
  // Another client's job (from Earlier maps), or one this browser submitted before its last:
  // its Cancel stops watching it, as a new robot or path does (dropRun), and leaves it to run.
  let own = false;
  try { own = localStorage.getItem(LAST_JOB_KEY) === id; } catch { /* storage refused */ }
  const run = { id, resumed: true, own };
  state.run = run; $("run").disabled = true; $("cancel").disabled = false;
  $("cancel").textContent = own ? "Cancel" : "Stop watching";
  disableEarlier();
  state.grid = asked.request.grid; state.mapBody = asked.request;
  await watch(run);
}

function endRun() {
  state.run = null;
  $("cancel").disabled = true; $("run").disabled = false;
  $("cancel").textContent = "Cancel";
  listEarlierMaps();
}

// A new path or robot while a map is submitted or runs: its job is cancelled on the service and
// its answer never drawn under the new inputs (whose map it is not).
function dropRun(why) {
  const run = state.run;
  if (!run) return;
  endRun();
  $("bar").value = 0; $("eta").textContent = "";
  if (run.resumed) {  // an earlier job shown again: not this form's, so left to run, and offered
    $("job-status").textContent = `no longer watched (job ${run.id} runs on): ${why}`;
    offerLastJob();
    return;
  }
  if (run.id) cancelJob(run.id);
  $("job-status").textContent = `cancelled: ${why}`;
}

// Asked, not awaited, and quiet: a job that ended meanwhile is left as it is (api.md).
function cancelJob(id) {
  fetch(`/v1/jobs/${id}/cancel`, { method: "POST" }).catch(() => null);
}

// A request about the job that gets no answer (the network, the service restarting: jobs
// survive a restart) or an error (a 5xx: the job store unusable, the service stopping) is asked
// again after these waits (ms), about two and a half minutes in all; then the page gives up. A
// first start after an upgrade compiles the kernels (two minutes on two cores): 7.5 s of
// waits gave up on a job the restarted service then ran (audit 26, O2).
const POLL_RETRIES_MS = [500, 1000, 2000, 4000, 8000, ...Array(9).fill(15000)];

// GET url: its JSON, or an error that carries the HTTP status (none: no answer) and, in
// error.answered, the status and what the service said of it (its detail's messages).
async function getJson(url) {
  const response = await fetch(url);
  if (!response.ok) {
    let said = "";
    try {
      const detail = (await response.json()).detail;
      said = Array.isArray(detail) ? detail.map((d) => d.msg).join("; ") : String(detail ?? "");
    } catch { /* no JSON (a proxy's page): the status alone */ }
    const why = [response.statusText, said].filter(Boolean).join(": ");
    const error = new Error(`HTTP ${response.status}${why ? ` ${why}` : ""}`);
    error.status = response.status;
    error.answered = `${response.status}${why ? ` (${why})` : ""}`;
    throw error;
  }
  return response.json();
}

// GET url for the run, asked again after POLL_RETRIES_MS when it fails. Null when the run was
// dropped meanwhile, or when the page gives up (the job gone: 404; else 5 failures): then Run
// is back and the status says why.
async function ask(run, url) {
  for (let failed = 0; ; failed++) {
    let error;
    try {
      const answer = await getJson(url);
      return state.run === run ? answer : null;
    } catch (caught) { error = caught; }
    if (state.run !== run) return null;
    if (error.status === 404 || failed === POLL_RETRIES_MS.length) {
      endRun();
      $("bar").value = 0; $("eta").textContent = "";
      $("job-status").textContent = error.status === 404
        ? `no map: job ${run.id} is gone (404: deleted by another client, or expired)`
        : `no map: ${failed + 1} requests about job ${run.id} failed (${error.message})`
          + (run.reading ? "" : "; it may still run on the service");
      return null;
    }
    $("eta").textContent = (error.status ? `the service answered ${error.answered}`
      : `no answer from the service (${error.message})`) + ": asking again";
    await new Promise((resolve) => setTimeout(resolve, POLL_RETRIES_MS[failed]));
  }
}

async function watch(run) {
  for (;;) {
    const job = await ask(run, `/v1/jobs/${run.id}`);
    if (!job) return;  // dropped (a new path or robot), or given up (said)
    $("bar").value = job.progress.fraction;
    const eta = job.progress.eta_seconds;
    $("eta").textContent = eta == null ? "" : `about ${eta.toFixed(1)} s left`;
    // A job shown again is drawn with its own inputs, which the form does not take: said, so
    // that the form's fields are not read as the map's.
    const status = `${job.status}: ${job.progress.done} of ${job.progress.total} placements`
      + (run.resumed ? ` (job ${run.id}'s own inputs; the form keeps yours)` : "");
    $("job-status").textContent = status;
    if (job.status === "done") {
      const cells = await readCells(run, job);
      if (!cells) return;
      endRun();
      $("job-status").textContent = status; $("bar").value = 1;
      drawMap({ ...job.result, cells });
      state.mapJob = run.id;  // its picture is the job's (savePng)
      return;
    }
    if (!["queued", "running"].includes(job.status)) {
      endRun();
      if (job.status === "failed") { showErrors(job.error); $("job-status").textContent += " (see the errors above)"; }
      return;
    }
    await new Promise((resolve) => setTimeout(resolve, 200));
  }
}

// A map of over DTF_JOB_PAGE_CELLS cells comes without them (result_cells.in_result false):
// they are read a page at a time from result_cells.first_page on, the count said as they come.
async function readCells(run, job) {
  const where = job.result_cells;
  if (!where || where.in_result) return job.result.cells;
  run.reading = true;
  $("eta").textContent = "";
  const cells = [];
  for (let next = where.first_page; next;) {
    $("job-status").textContent = `done: reading the map's cells, ${cells.length} of ${where.total}`;
    $("bar").value = cells.length / where.total;
    const page = await ask(run, next);
    if (!page) return null;
    for (const c of page.cells) cells.push(c);
    next = page.next;
  }
  return cells;
}

async function cancelMap() {  // POST .../cancel: DELETE would forget the job
  const run = state.run;
  if (!run || !run.id) return;
  if (run.reading) { dropRun("the map's cells were not all read"); return; }  // the job is done
  if (run.resumed && !run.own) { dropRun("stopped watching; not this browser's job"); return; }
  await api("POST", `/v1/jobs/${run.id}/cancel`).catch(() => null);
}
