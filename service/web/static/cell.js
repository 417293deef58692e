// The cell editor (spec/cell.md): a table top, boxes fixed in the base frame {B} or moving with
// the workpiece in {O}, the tool and the clearance; the `cell` of a request built from them, and
// the words for what an answer says of it (a collision, the least clearance). With no table, no
// box and no tool the page sends no cell, so the answers are those of a request without one.
"use strict";

const DEGREE = Math.PI / 180;
const cellEditor = { boxes: 0 };

// The unit quaternion [x, y, z, w] of R = Rz(yaw) Ry(pitch) Rx(roll), angles in rad.
function quaternionOf(roll, pitch, yaw) {
  const cr = Math.cos(roll / 2), sr = Math.sin(roll / 2);
  const cp = Math.cos(pitch / 2), sp = Math.sin(pitch / 2);
  const cy = Math.cos(yaw / 2), sy = Math.sin(yaw / 2);
  return [
    sr * cp * cy - cr * sp * sy,
    cr * sp * cy + sr * cp * sy,
    cr * cp * sy - sr * sp * cy,
    cr * cp * cy + sr * sp * sy,
  ];
}

// A number input's value as typed: empty or a word is NaN, which JSON sends as null, so that the
// API says beside the field what is wrong (nothing is read as 0 or dropped here).
function typed(input) {
  const text = input.value.trim();
  return text === "" ? NaN : Number(text);
}

// One labelled group of number inputs with its error line; `tail` is its place in an object's
// loc (`box.size`), completed with the object's group and index when a body is built.
function numberGroup(tail, label, names, values, owner) {
  const field = document.createElement("div");
  field.className = "field";
  field.dataset.tail = tail;
  const title = document.createElement("span");
  title.className = "label";
  title.textContent = label;
  field.appendChild(title);
  names.forEach((name, k) => {
    const input = document.createElement("input");
    input.type = "number"; input.step = "any"; input.className = "short";
    input.value = values[k];
    input.dataset.part = name;
    input.setAttribute("aria-label", `${owner} ${name}`);
    field.appendChild(input);
  });
  const error = document.createElement("span");
  error.className = "error"; error.setAttribute("role", "alert");
  field.appendChild(error);
  return field;
}

// A new object row: its frame (fixed or workpiece), name, shape's own fields (a box's sizes, a
// mesh's STL file and unit), position and angles.
function addObject(shape) {
  cellEditor.boxes += 1;
  const n = cellEditor.boxes;
  const owner = `${shape} ${n}`;
  const row = document.createElement("fieldset");
  row.className = "cell-box";
  row.dataset.box = String(n);
  row.dataset.shape = shape;
  const legend = document.createElement("legend");
  legend.textContent = `${shape === "box" ? "Box" : "STL mesh"} ${n}`;
  row.appendChild(legend);
  const head = document.createElement("div");
  head.className = "field";
  head.dataset.tail = "";
  head.innerHTML = `<label>Frame and name</label>
    <select class="box-frame" aria-label="${owner} frame">
      <option value="fixed">fixed: in the base frame {B}, stays put</option>
      <option value="workpiece">workpiece: in {O}, moves with the placement</option>
    </select>
    <input class="box-name" type="text" value="${owner}" aria-label="${owner} name">
    <span class="error" role="alert"></span>`;
  row.appendChild(head);
  if (shape === "box") {
    row.appendChild(numberGroup("box.size", "Size lx, ly, lz (m)", ["lx (m)", "ly (m)", "lz (m)"], [0.1, 0.1, 0.1], owner));
  } else {
    for (const field of meshFields(row, owner)) row.appendChild(field);
  }
  const position = shape === "box" ? "Centre x, y, z (m)" : "Position of the file's origin x, y, z (m)";
  row.appendChild(numberGroup(`${shape}.pose.position`, position, ["x (m)", "y (m)", "z (m)"], [0, 0, 0], owner));
  row.appendChild(numberGroup(`${shape}.pose.orientation`, "Roll, pitch, yaw (deg; R = Rz(yaw) Ry(pitch) Rx(roll))",
    ["roll (deg)", "pitch (deg)", "yaw (deg)"], [0, 0, 0], owner));
  const remove = document.createElement("button");
  remove.type = "button"; remove.className = "remove-box"; remove.textContent = "Remove";
  remove.setAttribute("aria-label", `Remove ${owner}`);
  remove.addEventListener("click", () => { row.remove(); showCellStatus(); });
  row.appendChild(remove);
  $("cell-boxes").appendChild(row);
  showCellStatus();
  return row;
}

function addBox() { return addObject("box"); }

// A binary STL: 80 header bytes, a triangle count, 50 bytes a triangle, exactly (its header
// may begin with "solid" as an ASCII file does: SolidWorks writes them so).
function binaryStl(bytes) {
  if (bytes.length < 84) return false;
  const count = new DataView(bytes.buffer, bytes.byteOffset, bytes.length).getUint32(80, true);
  return bytes.length === 84 + 50 * count;
}

// What a mesh file would meet, said at its choice (GET /v1/limits): a body over the service's
// limit is refused whole (413) and an STL of more triangles than it takes too. The body holds
// the file as sent (base64: 4 bytes for 3; ASCII: its text, each line end escaped).
function meshTooLarge(row, bytes, binary, sent) {
  const limits = state.limits;
  if (!limits) return "";
  const said = [];
  const triangles = binary
    ? (binaryStl(bytes) ? new DataView(bytes.buffer, bytes.byteOffset).getUint32(80, true) : null)
    : (sent.match(/\bfacet\b/g) || []).length;
  if (triangles !== null && triangles > limits.max_mesh_triangles) {
    said.push(`${triangles} triangles; the service takes at most ${limits.max_mesh_triangles} a mesh (DTF_MAX_MESH_TRIANGLES)`);
  }
  const size = JSON.stringify(sent).length;
  const most = `the service takes requests of at most ${limits.max_body_bytes} bytes (DTF_MAX_BODY_BYTES)`;
  if (size > limits.max_body_bytes) {
    said.push(`sent as ${size} bytes${binary ? " (base64)" : ""}; ${most}`
      + `${binary ? "" : ": a binary STL is about a fifth of the size"}`);
  } else {  // this mesh's size, and the other rows' meshes as they are sent
    const meshes = [...document.querySelectorAll(".cell-box")].filter((other) => other !== row)
      .reduce((sum, other) => sum + (other.dataset.stl ? JSON.stringify(other.dataset.stl).length : 0), size);
    if (meshes > limits.max_body_bytes) said.push(`with the cell's other meshes, sent as ${meshes} bytes; ${most}`);
  }
  return said.length ? ` — too large to send: ${said.join("; ")}` : "";
}

function base64Of(bytes) {
  let text = "";
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

// A mesh row's file and unit fields. The file is sent as the API takes it: an ASCII STL as its
// text, a binary one in base64. An STL states no unit, so the unit is chosen (none chosen: the
// API's error beside it, never a unit guessed); no file: the API's error beside the file.
function meshFields(row, owner) {
  const file = document.createElement("div");
  file.className = "field";
  file.dataset.tail = "mesh.stl";
  file.innerHTML = `<label>STL file (ASCII or binary; each separate part taken as its convex hull)</label>
    <input class="mesh-file" type="file" accept=".stl" aria-label="${owner} STL file">
    <span class="mesh-read note"></span>
    <span class="error" role="alert"></span>`;
  row.dataset.stl = "";
  file.querySelector(".mesh-file").addEventListener("change", async (event) => {
    const chosen = event.target.files[0];
    if (!chosen) return;
    const bytes = new Uint8Array(await chosen.arrayBuffer());
    // Text only where every byte is ASCII: anything else (a binary STL cut short, not an STL)
    // goes as its bytes, whose errors the API's reader names, not as mangled text.
    const binary = binaryStl(bytes) || bytes.some((b) => b > 127);
    row.dataset.stl = binary ? base64Of(bytes) : new TextDecoder().decode(bytes);
    const tooLarge = meshTooLarge(row, bytes, binary, row.dataset.stl);
    const read = file.querySelector(".mesh-read");
    read.textContent = `${chosen.name}: ${binary ? "binary" : "ASCII"}, ${bytes.length} bytes` + tooLarge;
    read.classList.toggle("too-large", tooLarge !== "");  // in the errors' colour
    showCellStatus();
  });
  const units = document.createElement("div");
  units.className = "field";
  units.dataset.tail = "mesh.units";
  units.innerHTML = `<label>The file's unit (an STL states none)</label>
    <select class="mesh-units" aria-label="${owner} unit">
      <option value="">choose</option><option value="mm">mm</option><option value="cm">cm</option>
      <option value="m">m</option><option value="in">inch</option>
    </select>
    <span class="error" role="alert"></span>`;
  return [file, units];
}

function parts(row, tail) {
  return [...row.querySelector(`.field[data-tail="${tail}"]`).querySelectorAll("input")].map(typed);
}

// The object of a row as the API takes it: a box, or a mesh (an unchosen unit sent as "", which
// the API refuses beside its field).
function boxObject(row) {
  const shape = row.dataset.shape || "box";
  const [roll, pitch, yaw] = parts(row, `${shape}.pose.orientation`).map((a) => a * DEGREE);
  const name = row.querySelector(".box-name").value.trim();
  const pose = {
    position: parts(row, `${shape}.pose.position`), orientation: quaternionOf(roll, pitch, yaw),
  };
  const object = shape === "box" ? { shape, size: parts(row, "box.size"), pose }
    : { shape, stl: row.dataset.stl, units: row.querySelector(".mesh-units").value, pose };
  if (name) object.name = name;
  return object;
}

// The tool, when any of its fields is filled: each as typed (an empty radius or length is the
// API's "Field required" beside it); an empty cutting length is the API's default.
function toolBody() {
  const ids = ["tool-radius", "tool-length", "tool-cutting-length"];
  if (ids.every((id) => $(id).value.trim() === "")) return undefined;
  const tool = { radius: value("tool-radius"), length: value("tool-length") };
  if ($("tool-cutting-length").value.trim() !== "") tool.cutting_length = value("tool-cutting-length");
  return tool;
}

// Each cell field's loc, numbered as cellBody numbers the objects (the table, when given, the
// first fixed one; each box in its frame's list): the API's errors, and the page's own before
// a request, go beside their fields.
function numberCellFields() {
  const table = $("table-height");
  const tabled = table.value.trim() !== "";
  table.closest(".field").dataset.loc = tabled ? "cell.fixed.0" : "cell.table";
  const count = { fixed: tabled ? 1 : 0, workpiece: 0 };
  for (const row of $("cell-boxes").querySelectorAll(".cell-box")) {
    const group = row.querySelector(".box-frame").value === "workpiece" ? "workpiece" : "fixed";
    const place = `cell.${group}.${count[group]++}`;
    for (const field of row.querySelectorAll(".field")) {
      field.dataset.loc = field.dataset.tail ? `${place}.${field.dataset.tail}` : place;
    }
  }
}

// The request's `cell`, or undefined (left out of the body) when there is nothing in it. Every
// field's loc is numbered as the body is, so that the API's errors go beside their fields.
function cellBody() {
  const fixed = [], workpiece = [];
  numberCellFields();
  if ($("table-height").value.trim() !== "") {
    fixed.push({ shape: "halfspace", name: "table", normal: [0, 0, 1], offset: value("table-height") });
  }
  for (const row of $("cell-boxes").querySelectorAll(".cell-box")) {
    (row.querySelector(".box-frame").value === "workpiece" ? workpiece : fixed).push(boxObject(row));
  }
  const tool = toolBody();
  if (!fixed.length && !workpiece.length && !tool && !selfChecked()) return undefined;
  const cell = { fixed, workpiece };
  if (tool) cell.tool = tool;
  if ($("clearance").value.trim() !== "") cell.clearance = value("clearance");
  if ($("link-radii").value.trim() !== "") cell.link_radii = numbers($("link-radii").value);
  return cell;
}

// Whether the robot is to be checked against itself with no object: asked, or a clearance or
// link radii given (which mean nothing without a cell: they were dropped without a word).
function selfChecked() {
  return $("self-check").checked || $("clearance").value.trim() !== ""
    || $("link-radii").value.trim() !== "";
}

// The editor's own number fields by a short name, for the line under it (a box's sizes and
// pose have theirs in their aria-label: "box 1 ly (m)").
const UNREAD_NAMES = {
  "table-height": "table height", "tool-radius": "tool radius", "tool-length": "tool length",
  "tool-cutting-length": "cutting length", clearance: "clearance",
};

// Whether a field of the editor holds something: a value, or a text the browser cannot read as
// a number (its value is then "", and the line said the table was not there while Run refused
// its height: unreadNumbers).
function filledIn(id) { return $(id).value.trim() !== "" || $(id).validity.badInput; }

// What the editor holds, in a line under it; the number fields it cannot read are named after it.
function showCellStatus() {
  const rows = [...$("cell-boxes").querySelectorAll(".cell-box")];
  const boxes = rows.filter((row) => row.dataset.shape !== "mesh").length;
  const meshes = rows.length - boxes;
  const table = filledIn("table-height");
  const tool = ["tool-radius", "tool-length", "tool-cutting-length"].some(filledIn);
  const things = [table ? "a table top" : "", boxes ? `${boxes} box${boxes === 1 ? "" : "es"}` : "",
    meshes ? `${meshes} mesh${meshes === 1 ? "" : "es"}` : "", tool ? "the tool" : ""]
    .filter(Boolean);
  const unread = [...$("cell-details").querySelectorAll("input[type=number]")]
    .filter((input) => input.validity.badInput)
    .map((input) => UNREAD_NAMES[input.id] || input.getAttribute("aria-label") || input.id);
  $("cell-status").textContent = (things.length
    ? `Checked along the path against ${things.join(", ")}, and the robot against itself.`
    : selfChecked() ? "Checked along the path: the robot against itself (no object)."
      : "Empty: nothing is checked (no cell is sent).")
    + (unread.length ? ` Not a number as typed: ${unread.join(", ")} (nothing is sent until it is).` : "");
}

function millimetres(metresValue) { return `${fixed(1000 * metresValue, 1)} mm`; }

// An obstacle of a contact by its name and its place in the request's lists (fixed first, then
// workpiece, as the API counts them); null is another part of the robot.
function obstacleOf(contact, cell) {
  if (contact.obstacle === null) return `${contact.obstacle_name} (the robot itself)`;
  const fixedCount = cell ? cell.fixed.length : 0;
  const place = contact.obstacle < fixedCount ? `fixed[${contact.obstacle}]`
    : `workpiece[${contact.obstacle - fixedCount}]`;
  return contact.obstacle_name === place ? place : `${contact.obstacle_name} (${place})`;
}

function clearanceOf(cell) { return cell && cell.clearance !== undefined ? cell.clearance : 0.005; }

// A collision as a sentence: robot part, obstacle, waypoint, distance against the clearance.
function collisionText(contact, cell) {
  const overlap = contact.distance < 0 ? ", overlapping" : "";
  return `${contact.robot_part} hits ${obstacleOf(contact, cell)} at waypoint ${contact.waypoint}: `
    + `distance ${millimetres(contact.distance)}${overlap} (clearance ${millimetres(clearanceOf(cell))})`;
}

// The least clearance of a feasible path as a sentence.
function clearanceText(contact, cell) {
  return `min clearance ${millimetres(contact.distance)}: ${contact.robot_part} to ${obstacleOf(contact, cell)}`
    + ` at waypoint ${contact.waypoint} (clearance asked ${millimetres(clearanceOf(cell))})`;
}

// What an evaluation says of the cell: the collision, or the least clearance, then its model
// (cellModel); empty without a cell.
function cellVerdict(answer, cell) {
  if (!cell) return "";
  const text = answer.collision ? `collision: ${collisionText(answer.collision, cell)}`
    : answer.min_clearance ? clearanceText(answer.min_clearance, cell) : "";
  return text + cellModel(answer);
}

// What an evaluation or a map says of the cell's model: the links given capsules for want of
// collision geometry, and the parts not checked against a fixed object because no joint moves
// them relative to it; each after "; ", empty where the answer has none.
function cellModel(answer) {
  const approximated = answer.cell_approximated && answer.cell_approximated.length
    ? `; links approximated by capsules: ${answer.cell_approximated.join(", ")}` : "";
  const unchecked = answer.cell_unchecked && answer.cell_unchecked.length
    ? "; not checked, no joint moves them relative to each other: " + answer.cell_unchecked
      .map((pair) => `${pair.robot_part} and ${pair.obstacle_name} (${millimetres(pair.distance)})`)
      .join(", ")
    : "";
  return approximated + unchecked;
}

function startCellEditor() {
  $("add-box").addEventListener("click", addBox);
  $("add-mesh").addEventListener("click", () => addObject("mesh"));
  $("cell-details").addEventListener("input", showCellStatus);  // a box's fields too
  $("self-check").addEventListener("change", showCellStatus);
  showCellStatus();
}
