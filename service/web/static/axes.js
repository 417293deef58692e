// The axes of a colour-map panel: x and y in metres with ticks at round values, the panel's yaw
// and spin above it. Drawn as SVG around the map's canvas (the canvas keeps one pixel block a
// cell), so the tick labels are text a reader, a screen reader and a test can find.
"use strict";

const SVG = "http://www.w3.org/2000/svg";
const MARGIN = { left: 56, right: 14, top: 22, bottom: 38 };

// The smallest round step (1, 2, 2.5 or 5 times a power of ten) at least `minimum` long.
function roundStep(minimum) {
  const power = 10 ** Math.floor(Math.log10(minimum));
  for (const m of [1, 2, 2.5, 5, 10]) if (m * power >= minimum * (1 - 1e-9)) return m * power;
  return 10 * power;
}

function decimalsOf(step) {
  let d = 0;
  while (d < 6 && Math.abs(Math.round(step * 10 ** d) - step * 10 ** d) > 1e-6) d++;
  return d;
}

// Tick values of an axis whose cells centre on values[0], values[0] + delta, ...: round
// values from the first cell's value to the last's, at least `spacing` pixels apart.
function ticksOf(values, delta, size, spacing) {
  const first = values[0], last = values[values.length - 1];
  if (values.length === 1) return { ticks: [first], digits: 3 };
  const step = roundStep((spacing * delta) / size);
  const digits = decimalsOf(step);
  const ticks = [];
  for (let v = Math.ceil(first / step - 1e-9) * step; v <= last + 1e-9 * step; v += step) {
    ticks.push(Number(v.toFixed(digits + 2)));
  }
  if (ticks.length >= 3 || size * (values.length - 1) < spacing) return { ticks, digits };
  // Few round values on a short axis: the first and last cells' values, and every stride-th.
  const stride = Math.ceil(spacing / size);
  const picked = values.filter((_, k) => k % stride === 0);
  return { ticks: picked, digits: Math.max(decimalsOf(delta), decimalsOf(values[0])) };
}

function svgElement(name, attributes, text) {
  const element = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) element.setAttribute(key, String(value));
  if (text !== undefined) element.textContent = text;
  return element;
}

// Wrap `canvas` (nx by ny cells of `size` pixels; x values xs, y values ys, increasing) in a
// box holding its axes and `title`; the box is returned, the canvas inside it unchanged.
function withAxes(canvas, xs, ys, size, title) {
  const width = xs.length * size, height = ys.length * size;
  const box = document.createElement("div");
  box.className = "axes";
  // Wide enough for the title too (about 7 px a character at 12 px), so panels never overlap.
  box.style.width = `${Math.max(MARGIN.left + width + MARGIN.right, MARGIN.left + 7 * title.length)}px`;
  box.style.height = `${MARGIN.top + height + MARGIN.bottom}px`;
  const svg = svgElement("svg", {
    width: MARGIN.left + width + MARGIN.right, height: MARGIN.top + height + MARGIN.bottom,
    class: "axes-svg", role: "img", "aria-label": `${title}: x from ${xs[0]} to ${xs[xs.length - 1]} m, y from ${ys[0]} to ${ys[ys.length - 1]} m`,
  });
  canvas.style.left = `${MARGIN.left}px`;
  canvas.style.top = `${MARGIN.top}px`;
  const dx = xs.length > 1 ? xs[1] - xs[0] : 1, dy = ys.length > 1 ? ys[1] - ys[0] : 1;
  const xAt = (v) => MARGIN.left + ((v - xs[0]) / dx + 0.5) * size;
  const yAt = (v) => MARGIN.top + (ys.length - 0.5 - (v - ys[0]) / dy) * size;
  const bottom = MARGIN.top + height;
  svg.appendChild(svgElement("rect", { x: MARGIN.left - 0.5, y: MARGIN.top - 0.5, width: width + 1, height: height + 1, class: "frame" }));
  const xt = ticksOf(xs, dx, size, 40);
  for (const v of xt.ticks) {
    const at = xAt(v);
    svg.appendChild(svgElement("line", { x1: at, x2: at, y1: bottom, y2: bottom + 5, class: "tick" }));
    svg.appendChild(svgElement("text", { x: at, y: bottom + 16, "text-anchor": "middle", class: "tick-x", "data-value": v }, fixed(v, xt.digits)));
  }
  const yt = ticksOf(ys, dy, size, 28);
  for (const v of yt.ticks) {
    const at = yAt(v);
    svg.appendChild(svgElement("line", { x1: MARGIN.left - 5, x2: MARGIN.left, y1: at, y2: at, class: "tick" }));
    svg.appendChild(svgElement("text", { x: MARGIN.left - 7, y: at, "text-anchor": "end", "dominant-baseline": "middle", class: "tick-y", "data-value": v }, fixed(v, yt.digits)));
  }
  svg.appendChild(svgElement("text", { x: MARGIN.left + width / 2, y: bottom + 32, "text-anchor": "middle", class: "axis-title" }, "x (m)"));
  svg.appendChild(svgElement("text", {
    x: 12, y: MARGIN.top + height / 2, "text-anchor": "middle", class: "axis-title",
    transform: `rotate(-90 12 ${MARGIN.top + height / 2})`,
  }, "y (m)"));
  svg.appendChild(svgElement("text", { x: MARGIN.left, y: 14, class: "panel-title" }, title));
  box.append(svg, canvas);
  return box;
}
