// The page's text, from the viewer's state (state.js): the connection's status and the rates
// in the header, which panels the graph fills and the topics they show, the poses' table, the
// alerts, the processes' and components' health (/diagnostics), a volume calibration's coverage,
// its solve's progress and report, the turret's angles and every topic with its rate and
// bandwidth.
import { rollPitchYaw } from "./geometry.js";
import { graph, report, stampSeconds } from "./state.js";
import { TYPES } from "./topics.js";

const $ = (id) => document.getElementById(id);
const statusLine = $("status");
const degrees = (radians) => ((radians * 180) / Math.PI).toFixed(1);

export function connected(url) {
  statusLine.textContent = `connected to ${url}`;
  statusLine.className = "connected";
}

export function disconnected(url, wasConnected) {
  statusLine.textContent = `disconnected: no bridge at ${url}${wasConnected ? " (it went away)" : ""}; retrying every 2 s`;
  statusLine.className = "disconnected";
}

// Image topics in one line, as "/volume/<camera>/image_raw" when they differ in one name.
function pattern(topics) {
  const names = topics.map((t) => t.split("/"));
  if (names.some((n) => n.length !== names[0].length)) return topics.join(", ");
  return names[0].map((name, i) => (names.every((n) => n[i] === name) ? name : "<camera>")).join("/");
}

// Which panels this graph fills: a single camera's, or a volume's: its cameras side by side
// (none when they send centroids instead of images) and the volume from above.
export function layout(channels) {
  const cameras = [...graph.cameras.keys()];
  const advertised = [...channels.values()];
  const types = new Set(advertised.map((c) => c.schemaName));
  const volume = cameras.length > 1 || types.has(TYPES.markers);
  $("camera-topic").textContent = cameras.length === 1 ? cameras[0] : "";
  $("camera-note").textContent = cameras.length ? "" : `no ${TYPES.image} in this graph`;
  $("volume").hidden = !volume;
  $("view3d-section").hidden = !volume;
  if (volume) {
    $("volume-topics").textContent = cameras.length
      ? `${pattern(cameras)} with their fiducials`
      : "none: the cameras send no images";
  }
  // A calibration session: each camera's coverage as the board is waved; its solve's progress,
  // then its report.
  const covering = types.has(TYPES.coverage);
  const solving = types.has(TYPES.progress) || types.has(TYPES.result);
  const calibrating = covering || solving;
  $("coverage-section").hidden = !covering;
  $("solve-section").hidden = !solving;
  // A volume alone, or a calibration session: the single camera's panels (its image, its top
  // view, the floor) stay empty.
  $("camera-section").hidden = volume || (calibrating && !cameras.length);
  $("side-section").hidden = volume && !types.has(TYPES.robots) && !types.has(TYPES.footprints);
  const alertTopics = advertised.filter((c) => c.schemaName === TYPES.alert).map((c) => c.topic);
  $("alerts-topic").textContent = alertTopics.sort().join(", ");
}

export function poses() {
  const rows = [...graph.poses.values()].flatMap((message) => message.poses).map((pose) => {
    const p = pose.pose.pose.position;
    const [roll, pitch, yaw] = rollPitchYaw(pose.pose.pose.orientation).map(degrees);
    // Speed and turn rate from the track (zero with a large covariance when just found).
    const v = pose.velocity ? pose.velocity.linear : { x: 0, y: 0, z: 0 };
    const w = pose.velocity ? pose.velocity.angular : { x: 0, y: 0, z: 0 };
    const speed = Math.hypot(v.x, v.y, v.z).toFixed(2);
    const turn = ((Math.hypot(w.x, w.y, w.z) * 180) / Math.PI).toFixed(0);
    return `<tr><td>${pose.name}</td><td>${p.x.toFixed(3)}</td><td>${p.y.toFixed(3)}</td>
      <td>${p.z.toFixed(3)}</td><td>${roll}</td><td>${pitch}</td><td>${yaw}</td>
      <td>${speed}</td><td>${turn}</td>
      <td>${pose.points_used}</td><td>${pose.reprojection_rms_px.toFixed(2)}</td>
      <td>${pose.cameras_used || ""}</td></tr>`;
  });
  $("poses-topic").textContent = [...graph.poses.keys()].join(", ");
  const html = rows.join("") || `<tr><td colspan="12" class="note">no constellation identified</td></tr>`;
  $("poses").tBodies[0].innerHTML = html;
  report.poseReadout = $("poses").tBodies[0].textContent;
}

export function alerts() {
  const level = (l) => (l >= 2 ? "error" : "warning");
  $("alerts").innerHTML = graph.alerts
    .map((a) => `<li class="${level(a.level)}">${new Date(stampSeconds(a.header) * 1000).toLocaleTimeString()} ${a.source}: ${a.text}</li>`)
    .join("");
}

// A status not renewed for this long is shown STALE: its process stopped publishing.
const HEALTH_STALE_MS = 3000;
const LEVELS = ["OK", "WARN", "ERROR", "STALE"];
const escape = (text) => text.replace(/[&<>"]/g, (c) => `&#${c.charCodeAt(0)};`);

// One row per status, the worst first, with the stage's latency where the component gives one
// (its last "capture -> ..." median) and its host.
export function health() {
  const now = Date.now();
  const rows = [...graph.health.entries()].map(([name, { status, receivedAt }]) => {
    const stale = now - receivedAt > HEALTH_STALE_MS;
    const level = stale ? 3 : Math.min(status.level, 3);
    const message = stale ? `no status for ${((now - receivedAt) / 1000).toFixed(0)} s: is its process running?` : status.message;
    // The stage's last figure: a fusion gives its inputs' arrival, then its poses sent.
    const latency = status.values.filter((v) => v.key.startsWith("capture -> ") && v.key.endsWith("median (ms)")).pop();
    return { name, level, message, host: status.hardware_id, latency };
  });
  rows.sort((a, b) => b.level - a.level || a.name.localeCompare(b.name));
  report.healthRows = Object.fromEntries(rows.map((r) => [r.name, LEVELS[r.level]]));
  $("health").tBodies[0].innerHTML = rows.length
    ? rows.map((r) => `<tr class="level-${LEVELS[r.level].toLowerCase()}"><td>${escape(r.name)}</td><td>${LEVELS[r.level]}</td>
      <td>${escape(r.message)}</td><td>${r.latency ? `${escape(r.latency.key.slice(11, -12))}: ${escape(r.latency.value)} ms` : ""}</td>
      <td>${escape(r.host)}</td></tr>`).join("")
    : `<tr><td colspan="5" class="note">no /diagnostics in this graph</td></tr>`;
}

// Each camera of the calibration session: its image's nine regions filled in as the board is
// seen there (the count in each, full at what a region needs), a progress bar, the shots it
// shares with another camera and what is still missing.
export function coverage() {
  const message = graph.coverage;
  if (!message) return;
  report.coverageCameras = message.cameras.length;
  report.coverageProgress = message.progress;
  report.coverageViews = message.cameras.reduce((sum, c) => sum + c.views.reduce((a, b) => a + b, 0), 0);
  report.coverageMissing = Object.fromEntries(message.cameras.map((c) => [c.name, c.missing]));
  $("coverage").innerHTML = message.cameras.map((camera) => {
    const percent = Math.floor(100 * camera.progress);
    const cells = Array.from(camera.views, (views) => {
      const filled = Math.min(1, views / Math.max(1, camera.views_needed));
      return `<div class="${filled >= 1 ? "full" : ""}" style="--filled: ${filled.toFixed(2)}">${views}</div>`;
    }).join("");
    const missing = camera.missing.length ? `missing: ${camera.missing.map(escape).join(", ")}` : "complete";
    return `<figure class="${percent >= 100 ? "complete" : ""}">
      <figcaption><b>${escape(camera.name)}</b> ${percent} %</figcaption>
      <div class="regions" style="aspect-ratio: ${camera.image_width} / ${camera.image_height}">${cells}</div>
      <div class="bar"><div style="width: ${percent}%"></div></div>
      <p>${camera.shared_shots} shots with another camera (${camera.shared_shots_needed} needed); ${missing}</p>
    </figure>`;
  }).join("");
  $("coverage-note").textContent = `the session: ${Math.floor(100 * message.progress)} % (its least covered camera)`;
}

// The calibration's solve: a bar of its share done, its stage and what it says; a failure in the
// page's error colour with why, its bar full so that it is seen at a glance.
export function solve() {
  const message = graph.solve;
  if (!message) return;
  report.solveStage = message.stage;
  report.solveProgress = message.progress;
  report.solveDetail = message.detail;
  const failed = message.stage === "failed";
  const percent = failed ? 100 : Math.floor(100 * message.progress);
  $("solve-bar").className = `bar ${message.stage}`;  // coloured by its stage: viewer.css
  $("solve-bar").firstElementChild.style.width = `${percent}%`;
  $("solve-stage").className = failed ? "failed" : "";
  $("solve-stage").textContent = failed
    ? `failed: ${message.detail}`
    : `${message.stage} ${percent} %${message.detail ? `: ${message.detail}` : ""}`;
}

// Figures as the report of mocap_volume_calibrate prints them, empty where it has none.
const fixed = (value, digits) => (value === null ? "" : value.toFixed(digits));

// The calibration's report: the solve in one line, each camera (its RMS, where it is, how far
// from its camera file's pose) and each placement of the board on the floor. The figures go to
// window.viewerState as the message has them, in metres turned into the millimetres shown.
export function result() {
  const message = graph.result;
  $("result").hidden = !message;
  if (!message) {
    report.resultSummary = null;
    report.resultCameras = [];
    report.resultFloor = [];
    return;
  }
  const { frames_used, rms_px, points, iterations } = message;
  report.resultSummary = { frames_used, rms_px, points, iterations };
  report.resultCameras = message.cameras.map((c) => ({
    name: c.name,
    rms_px: c.rms_px,
    shots: c.shots,
    ...c.pose.position,
    moved_mm: c.has_previous_pose ? c.moved_m * 1e3 : null,
    turned_deg: c.has_previous_pose ? c.turned_deg : null,
  }));
  report.resultFloor = message.floor.map((f) => ({
    mark_x: f.mark_x,
    mark_y: f.mark_y,
    cameras: f.cameras,
    rms_px: f.rms_px,
    off_mark_mm: f.off_mark_m >= 0 ? f.off_mark_m * 1e3 : null,  // -1: a single mark
  }));
  $("result-summary").textContent =
    `${frames_used} capture times, RMS ${rms_px.toFixed(3)} px over ${points} points, ${iterations} iterations`;
  $("result-cameras").tBodies[0].innerHTML = report.resultCameras.map((c) =>
    `<tr><td>${escape(c.name)}</td><td>${c.rms_px.toFixed(3)}</td><td>${c.shots}</td><td>${c.x.toFixed(4)}</td>
      <td>${c.y.toFixed(4)}</td><td>${c.z.toFixed(4)}</td><td>${fixed(c.moved_mm, 2)}</td>
      <td>${fixed(c.turned_deg, 4)}</td></tr>`).join("");
  // The marks as the tool names them: "(1, 0)", "(0.5, -1)".
  $("result-floor").tBodies[0].innerHTML = report.resultFloor.map((f) =>
    `<tr><td>(${f.mark_x}, ${f.mark_y})</td><td>${f.cameras}</td><td>${f.rms_px.toFixed(3)}</td>
      <td>${fixed(f.off_mark_mm, 3)}</td></tr>`).join("");
}

export function turret() {
  if (graph.turret) $("turret").textContent = `turret: pan ${degrees(graph.turret.pan)}°, tilt ${degrees(graph.turret.tilt)}°`;
}

export function topics() {
  const rows = [...graph.topics.entries()].sort().map(([name, t]) =>
    `<tr><td>${name}</td><td>${t.type}</td><td>${t.rate === null ? "—" : t.rate.toFixed(1)}</td>
      <td>${t.bandwidth === null ? "—" : (t.bandwidth / 1000).toFixed(1)}</td></tr>`);
  $("topics").tBodies[0].innerHTML = rows.join("");
}

// The cameras' and the estimated poses' rates and the poses' latency, in the header.
export function rates() {
  const rate = (topic) => graph.topics.get(topic)?.rate ?? 0;
  const cameras = [...graph.cameras.keys()].map(rate);
  const shown = cameras.length > 1
    ? `${cameras.length} cameras ${Math.min(...cameras)}–${Math.max(...cameras)} Hz shown`
    : cameras.length === 1 ? `camera ${cameras[0]} Hz shown` : "no camera images";
  const poses = [...graph.poses.keys()].reduce((sum, topic) => sum + rate(topic), 0);
  $("rates").textContent = report.connected
    ? `${shown} · poses ${poses} Hz · latency to bridge ${report.latencyMs === null ? "—" : report.latencyMs.toFixed(1) + " ms"}`
    : "";
}
