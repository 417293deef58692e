// The clicked placement's plot: V_max along the path, each joint's use of its speed limit at
// the feed and, with acceleration limits, of its acceleration limit; the bottleneck marked.
"use strict";

// Each joint's use of its acceleration limit at the constant feed F: |D_i| F^2 / a_j, from the
// answer's qdd_at_mu_acc = D_i mu_acc^2 (motion.md section 2; null near the pass ends).
function accelerationUse(answer, body) {
  const acc = answer.acceleration;
  const limits = body.robot.joint_acceleration_limits;
  if (!acc || !(acc.mu_acc > 0) || !(body.feed > 0) || !Array.isArray(limits)) return null;
  const scale = (body.feed / acc.mu_acc) ** 2;
  return answer.waypoints.map((p) => (p.qdd_at_mu_acc
    ? p.qdd_at_mu_acc.map((v, j) => (Math.abs(v) * scale) / limits[j]) : null));
}

function plot(answer, body) {
  const canvas = $("plot");
  const accUse = answer.feasible ? accelerationUse(answer, body) : null;
  canvas.height = accUse ? 480 : 320;
  const g = canvas.getContext("2d");
  g.clearRect(0, 0, canvas.width, canvas.height);
  delete canvas.dataset.accelerationUse;
  canvas.dataset.panels = accUse ? "3" : "2";
  const points = answer.waypoints;
  if (!answer.feasible || !points.length) return;
  const panels = accUse ? 3 : 2;
  const left = 50, width = canvas.width - 70, top = 10, height = (canvas.height - 30 * panels) / panels;
  const xOf = (k) => left + (width * k) / Math.max(points.length - 1, 1);
  const axes = (y0, label, max) => {
    g.strokeStyle = "#444"; g.strokeRect(left, y0, width, height);
    g.fillStyle = "#222"; g.font = "12px sans-serif";
    g.fillText(label, left + 4, y0 + 14); g.fillText(max.toFixed(2), 4, y0 + 10); g.fillText("0", 30, y0 + height);
  };
  const vmax = extent(points.map((p) => p.v_max ?? 0))[1];
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
  let bottom = useTop + height;
  if (accUse) {  // the third panel: the joints' use of their acceleration limits at the feed
    const accTop = useTop + height + 30;
    bottom = accTop + height;
    const peak = Math.max(extent(accUse.flatMap((row) => (row ? row.filter(Number.isFinite) : [])))[1], 0);
    const ceiling = Math.max(1, Math.min(peak, 2));
    axes(accTop, "joint use of its acceleration limit at the feed (none within the blend of a pass end)", ceiling);
    g.strokeStyle = "#b00020"; g.setLineDash([2, 2]); g.beginPath();
    g.moveTo(left, accTop + height * (1 - 1 / ceiling)); g.lineTo(left + width, accTop + height * (1 - 1 / ceiling)); g.stroke(); g.setLineDash([]);
    for (let j = 0; j < joints; j++) {
      g.strokeStyle = colours[j % colours.length]; g.beginPath();
      let open = false;
      accUse.forEach((row, k) => {
        if (!row) { open = false; return; }
        const y = accTop + height * (1 - Math.min(row[j], ceiling) / ceiling);
        if (open) g.lineTo(xOf(k), y); else g.moveTo(xOf(k), y);
        open = true;
      });
      g.stroke();
    }
    const acc = answer.acceleration;
    if (acc.limited_by === "acceleration") {
      const x = xOf(acc.waypoint);
      g.strokeStyle = "#000"; g.setLineDash([4, 3]); g.beginPath();
      g.moveTo(x, accTop); g.lineTo(x, bottom); g.stroke(); g.setLineDash([]);
      g.fillStyle = "#000"; g.fillText(`mu_acc binds (joint ${acc.joint + 1})`, Math.min(x + 4, left + width - 130), accTop - 6);
    }
    canvas.dataset.accelerationUse = peak.toFixed(6);
  }
  if (answer.bottleneck) {
    const x = xOf(answer.bottleneck.waypoint);
    g.strokeStyle = "#b00020"; g.setLineDash([4, 3]); g.beginPath();
    g.moveTo(x, top); g.lineTo(x, useTop + height); g.stroke(); g.setLineDash([]);
    g.fillStyle = "#b00020"; g.fillText(`bottleneck (joint ${answer.bottleneck.joint + 1})`, Math.min(x + 4, left + width - 130), top + height + 20);
  }
  g.fillStyle = "#222"; g.textAlign = "center";  // the horizontal axis: the waypoints
  g.fillText("0", left, bottom + 14); g.fillText(String(points.length - 1), left + width, bottom + 14);
  g.fillText("waypoint along the path", left + width / 2, bottom + 14);
  g.textAlign = "start";
  canvas.dataset.drawn = "1";
}
