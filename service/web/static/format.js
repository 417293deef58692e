// Numbers as a process engineer reads them: rounded, with their units, never "-0.000" nor
// "-0.04999999999999999"; the controller frames of a placement as each controller writes them.
"use strict";

// A number to `digits` decimals, without a minus sign on a rounded zero.
function fixed(value, digits) {
  const text = Number(value).toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}

// Lengths in the API are metres: shown to 0.1 mm; angles in rad to 1e-4 rad.
function metres(value) { return `${fixed(value, 4)} m`; }
function radians(value) { return `${fixed(value, 4)} rad`; }

// The frames of an answer's placement (cam.md 8), one row a controller: its name, the frame as
// the controller's own syntax writes it (rounded to 1 um and 1e-4 deg or 1e-6 rad), the units,
// and the text the Copy button puts on the clipboard (the shown figures).
const CONTROLLER_FRAMES = [
  {
    key: "kuka", name: "KUKA (BASE_DATA / FRAME)", units: "mm, deg; R = Rz(A) Ry(B) Rx(C)",
    text: (f) => `{X ${fixed(f.X, 3)}, Y ${fixed(f.Y, 3)}, Z ${fixed(f.Z, 3)}, `
      + `A ${fixed(f.A, 4)}, B ${fixed(f.B, 4)}, C ${fixed(f.C, 4)}}`,
  },
  {
    key: "ur", name: "Universal Robots (pose)", units: "m, rotation vector in rad",
    text: (f) => `p[${f.map((v) => fixed(v, 6)).join(", ")}]`,
  },
  {
    key: "abb", name: "ABB (wobjdata uframe)", units: "mm; quaternion w-first [q1 = w, q2 = x, q3 = y, q4 = z]",
    text: (f) => `[[${f[0].map((v) => fixed(v, 3)).join(", ")}], [${f[1].map((v) => fixed(v, 6)).join(", ")}]]`,
  },
  {
    key: "fanuc", name: "FANUC (user frame)", units: "mm, deg; R = Rz(R) Ry(P) Rx(W)",
    text: (f) => `X ${fixed(f.X, 3)}  Y ${fixed(f.Y, 3)}  Z ${fixed(f.Z, 3)}  `
      + `W ${fixed(f.W, 4)}  P ${fixed(f.P, 4)}  R ${fixed(f.R, 4)}`,
  },
];
