// The volume in 3D, as a person used to Motive looks at it first: the floor's grid and the world
// axes, each camera as a frustum coloured by its health (/diagnostics), the marker cloud, the
// bodies with their axes, names and trails, the single-marker robots as named points. Drawn with
// gl_lines.js from the viewer's state (state.js), only when something changed (new data, the
// pointer, a status turning stale), at the page's next animation frame; names on a 2D canvas
// laid over the WebGL one, placed with the same matrices (orbit.js). A click on a body shows
// its figures, a double click (or the select) follows it.
import { createRenderer } from "./gl_lines.js";
import { rotate } from "./geometry.js";
import { Orbit } from "./orbit.js";
import { points } from "./point_cloud.js";
import { graph, posesFresh, report, worldTransform } from "./state.js";

const $ = (id) => document.getElementById(id);
const rgba = (hex, alpha = 1) => [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16) / 255).concat(alpha);

const BACKGROUND = rgba("#14181e");
const GRID_STEP_M = 0.5;
const GRID_MINOR = rgba("#3a434f", 0.55);
const GRID_MAJOR = rgba("#56616f", 0.9);  // every metre
const AXIS_HEX = ["#ff5252", "#5fd38d", "#6cb6ff"];  // x, y, z
const AXIS_COLOURS = AXIS_HEX.map((c) => rgba(c));
const WORLD_AXIS_M = 0.5;
// The same palette and order as the views from above (draw.js), so a body keeps its colour.
const BODY_COLOURS = ["#ffd54a", "#5fd38d", "#6cb6ff", "#ff8f6b", "#d59bff"];
const LOST_COLOUR = "#7d8794";
// A body whose pose has not come for this long is drawn grey: lost.
const LOST_MS = 1000;
const LABELED = rgba("#e8f4ff");
const UNLABELED = rgba("#ffa94d");
// The health panel's levels (panels.js) and their colours; a camera with no fresh status is
// STALE.
const LEVELS = ["OK", "WARN", "ERROR", "STALE"];
const LEVEL_COLOURS = ["#5fd38d", "#ffd54a", "#ff6b6b", "#7d8794"];
const HEALTH_STALE_MS = 3000;
// A camera without camera_info (one that sends centroids) is drawn with the volume's lens
// (config/cameras/synthetic_ir_1280x720.yaml): its direction is right, its cone a guide.
const NOMINAL_INFO = { width: 1280, height: 720, k: [914, 0, 639.5, 0, 914, 359.5, 0, 0, 1] };
const CAMERA_BODY_M = 0.22;  // the frustum drawn as the camera
const CONE_MAX_M = 7;  // the view's edges out to the floor, or this far
// Above this many bodies, they are drawn smaller, their names smaller.
const CROWDED_BODIES = 20;
const PICK_RADIUS_PX = 16;
const DRAWS_KEPT = 1000;
// The marker nearest a body within this distance counts as its, for the cameras that see it.
const OWN_MARKER_M = 0.5;

const section = $("view3d-section");
const stage = $("view3d-stage");
const canvas = $("view3d");
const overlay = $("view3d-labels");
const labels = overlay.getContext("2d");
const box = $("view3d-box");
const follow = $("view3d-follow");
const note = $("view3d-note");
const orbit = new Orbit();
orbit.aspect = canvas.width / canvas.height;
orbit.update();

let renderer = null;
try {
  renderer = createRenderer(canvas);
} catch (error) {
  console.warn(`3D view: ${error.message}`);
}
if (renderer) {
  // Which renderer draws (SwiftShader, software, in a headless chromium): the frame times say
  // little without it.
  const gl = renderer.gl;
  const info = gl.getExtension("WEBGL_debug_renderer_info");
  report.view3dRenderer = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  report.view3dBuffer = [gl.drawingBufferWidth, gl.drawingBufferHeight];
} else {
  report.view3d = "needs WebGL";
  note.textContent = "3D view needs WebGL, which this browser does not give: the volume from above and the poses' table show the same.";
  stage.classList.add("no-webgl");
}

let pending = true;  // the pointer moved the view, or a status or body turned stale
let userMoved = false;  // the view is the user's: not fitted to the cameras again
let fittedTo = "";  // the cameras the view was fitted to
let selected = "";
let following = "";
let levelsKey = "";
let followNames = "";
let cloudOwners = new Map();  // marker -> the name of its nearest body (ownMarkers)
// The last frame's bodies and cameras on screen (drawing-buffer pixels), for picking.
let onScreen = [];

// Scratch points: gl_lines.js copies what it is given.
const A = [0, 0, 0];
const B = [0, 0, 0];
const set = (out, p) => {
  out[0] = p.x;
  out[1] = p.y;
  out[2] = p.z;
  return out;
};

// Trail colours by age, a few steps of alpha per body colour: made once, not per segment.
const FADE_STEPS = 12;
const fades = new Map();
function fade(hex, step) {
  if (!fades.has(hex)) fades.set(hex, Array.from({ length: FADE_STEPS + 1 }, (_, i) => rgba(hex, 0.85 * (i / FADE_STEPS) ** 1.5)));
  return fades.get(hex)[step];
}

// A camera's level, from the statuses of its name: its process's and its components' (the
// health panel's rows "cam_0", "cam_0/cam_0", "cam_0/cam_0_fiducials"), the worst fresh one.
function cameraLevel(name, now) {
  let worst = -1;
  for (const [statusName, { status, receivedAt }] of graph.health) {
    if (statusName !== name && !statusName.startsWith(`${name}/`) && !statusName.endsWith(`/${name}`)) continue;
    if (now - receivedAt > HEALTH_STALE_MS) continue;
    worst = Math.max(worst, Math.min(status.level, 2));
  }
  return worst < 0 ? 3 : worst;
}

// The volume's cameras: those sending images (with camera_info where it came) and those /tf
// alone places (centroid cameras), each once, by its optical frame.
function cameras() {
  const found = new Map();
  for (const c of graph.cameras.values()) {
    const frame = c.image?.header.frame_id;
    const pose = frame && worldTransform(frame);
    if (pose) found.set(frame, { name: c.name, frame, pose, info: graph.infos.get(frame) });
  }
  for (const frame of graph.tf.keys()) {
    if (found.has(frame) || !frame.endsWith("_optical")) continue;
    const pose = worldTransform(frame);
    if (pose) found.set(frame, { name: frame.replace(/_optical$/, ""), frame, pose, info: graph.infos.get(frame) });
  }
  return [...found.values()];
}

// The bodies to draw: estimated poses while they come, else the frames /tf moves under the world
// (a ROS 2 graph's), each {name, x, y, z, orientation, track, lost, colour}.
function bodies(now) {
  const fresh = posesFresh() || graph.tfBodies.size === 0;
  report.view3dBodiesFrom = fresh ? (graph.bodies.size ? "/mocap/poses" : "") : "/tf";
  const out = [];
  let k = 0;
  if (fresh) {
    for (const [name, body] of graph.bodies) {
      const colour = BODY_COLOURS[k++ % BODY_COLOURS.length];
      const lost = now - body.receivedAt > LOST_MS;
      out.push({ name, body, colour: lost ? LOST_COLOUR : colour, lost });
    }
  } else {
    for (const [name, body] of graph.tfBodies) {
      if (body.updates < 2) continue;
      out.push({ name, body, colour: BODY_COLOURS[k++ % BODY_COLOURS.length], lost: false });
    }
  }
  return out;
}

function grid(min, max) {
  const x0 = Math.floor(min[0] / GRID_STEP_M) * GRID_STEP_M;
  const x1 = Math.ceil(max[0] / GRID_STEP_M) * GRID_STEP_M;
  const y0 = Math.floor(min[1] / GRID_STEP_M) * GRID_STEP_M;
  const y1 = Math.ceil(max[1] / GRID_STEP_M) * GRID_STEP_M;
  const major = (v) => Math.abs(v - Math.round(v)) < 1e-6;
  for (let x = x0; x <= x1 + 1e-6; x += GRID_STEP_M) {
    renderer.line([x, y0, 0], [x, y1, 0], major(x) ? GRID_MAJOR : GRID_MINOR);
  }
  for (let y = y0; y <= y1 + 1e-6; y += GRID_STEP_M) {
    renderer.line([x0, y, 0], [x1, y, 0], major(y) ? GRID_MAJOR : GRID_MINOR);
  }
  AXIS_COLOURS.forEach((colour, i) => {
    const end = [0, 0, 0];
    end[i] = WORLD_AXIS_M;
    renderer.line([0, 0, 0.002], end, colour, colour, 3);
  });
}

// A camera as Motive draws one: a small frustum in its level's colour with its image's face
// filled and a notch on the image's top edge, and the view's edges out to the floor.
function camera(c, colour) {
  const info = c.info ?? NOMINAL_INFO;
  const [fx, , cx, , fy, cy] = info.k;
  const { translation: t, rotation: q } = c.pose;
  const apex = [t.x, t.y, t.z];
  const world = (v) => {
    const r = rotate(q, v);
    return [t.x + r.x, t.y + r.y, t.z + r.z];
  };
  const rays = [[0, 0], [info.width, 0], [info.width, info.height], [0, info.height]].map(([u, v]) => ({
    x: (u - cx) / fx,
    y: (v - cy) / fy,
    z: 1,
  }));
  const solid = rgba(colour);
  const face = rgba(colour, 0.28);
  const cone = rgba(colour, 0.16);
  const near = rays.map((r) => world({ x: r.x * CAMERA_BODY_M, y: r.y * CAMERA_BODY_M, z: CAMERA_BODY_M }));
  for (let i = 0; i < 4; i++) {
    renderer.line(apex, near[i], solid, solid, 2);
    renderer.line(near[i], near[(i + 1) % 4], solid, solid, 2);
  }
  renderer.triangle(near[0], near[1], near[2], face);
  renderer.triangle(near[0], near[2], near[3], face);
  // The image's top (v = 0) marked by a small triangle above it.
  const top = world({ x: 0, y: (rays[0].y - 0.25 * (rays[3].y - rays[0].y)) * CAMERA_BODY_M, z: CAMERA_BODY_M });
  const mid0 = world({ x: rays[0].x * 0.3 * CAMERA_BODY_M, y: rays[0].y * CAMERA_BODY_M, z: CAMERA_BODY_M });
  const mid1 = world({ x: rays[1].x * 0.3 * CAMERA_BODY_M, y: rays[1].y * CAMERA_BODY_M, z: CAMERA_BODY_M });
  renderer.triangle(mid0, mid1, top, solid);
  // The view's edges until they meet the floor: where they do, their ends outline what the camera
  // sees of it.
  const far = rays.map((r) => {
    const d = rotate(q, r);
    const length = Math.hypot(d.x, d.y, d.z);
    const s = d.z < -1e-6 ? Math.min(-t.z / d.z, CONE_MAX_M / length) : CONE_MAX_M / length;
    return [t.x + d.x * s, t.y + d.y * s, t.z + d.z * s];
  });
  for (let i = 0; i < 4; i++) {
    renderer.line(near[i], far[i], cone);
    renderer.line(far[i], far[(i + 1) % 4], cone);
  }
  renderer.point(apex, solid, 7);
}

function body(b, crowded) {
  const { body: pose, colour } = b;
  const solid = rgba(colour);
  // The trail: older is fainter.
  const track = pose.track;
  const n = track.length;
  for (let i = 1; i < n; i++) {
    const ca = fade(colour, Math.round(((i - 1) / (n - 1)) * FADE_STEPS));
    const cb = fade(colour, Math.round((i / (n - 1)) * FADE_STEPS));
    renderer.line(set(A, track[i - 1]), set(B, track[i]), ca, cb, crowded ? 1.5 : 2.5);
  }
  report.view3dTrailSegments += Math.max(0, n - 1);
  const origin = [pose.x, pose.y, pose.z];
  if (pose.orientation) {
    const length = crowded ? 0.1 : 0.18;
    [{ x: length, y: 0, z: 0 }, { x: 0, y: length, z: 0 }, { x: 0, y: 0, z: length }].forEach((v, i) => {
      const r = rotate(pose.orientation, v);
      const colour = b.lost ? solid : AXIS_COLOURS[i];
      renderer.line(origin, [origin[0] + r.x, origin[1] + r.y, origin[2] + r.z], colour, colour, crowded ? 2 : 3);
    });
    renderer.point(origin, solid, crowded ? 7 : 10);
    report.view3dBodiesDrawn++;
  } else {
    renderer.point(origin, solid, crowded ? 9 : 12);
    report.view3dRobotsDrawn++;
  }
}

function markers() {
  if (!graph.markers) return [];
  try {
    return points(graph.markers, ["x", "y", "z", "body", "cameras"]);
  } catch (error) {
    console.warn(`marker cloud: ${error.message}`);
    return [];
  }
}

// The eye at its first look, near enough that the cameras (else the box [min, max]) fill the view
// but for a margin.
function fit(list, min, max) {
  orbit.fit(min, max);
  const targets = list.length ? list.map((c) => [c.pose.translation.x, c.pose.translation.y, c.pose.translation.z]) : [min, max];
  const inside = () => targets.every((p) => {
    const q = orbit.project(p, canvas.width, canvas.height);
    return q && q.x > 0.06 * canvas.width && q.x < 0.94 * canvas.width && q.y > 0.1 * canvas.height && q.y < 0.94 * canvas.height;
  });
  let near = 0.5;
  let far = orbit.distance * 3;
  for (let i = 0; i < 24; i++) {
    orbit.distance = (near + far) / 2;
    orbit.update();
    if (inside()) far = orbit.distance;
    else near = orbit.distance;
  }
  orbit.distance = far;
  orbit.update();
}

// The box the view is fitted to: the cameras and what they look at on the floor.
function bounds(list, drawnBodies) {
  const min = [Infinity, Infinity, 0];
  const max = [-Infinity, -Infinity, 0];
  const add = (x, y, z) => {
    min[0] = Math.min(min[0], x);
    min[1] = Math.min(min[1], y);
    min[2] = Math.min(min[2], z);
    max[0] = Math.max(max[0], x);
    max[1] = Math.max(max[1], y);
    max[2] = Math.max(max[2], z);
  };
  for (const c of list) add(c.pose.translation.x, c.pose.translation.y, c.pose.translation.z);
  if (!list.length) for (const b of drawnBodies) add(b.body.x, b.body.y, b.body.z);
  if (min[0] === Infinity) return [[-2, -2, 0], [2, 2, 2]];
  return [min.map((v, i) => (i < 2 ? Math.min(v, -1) : v)), max.map((v, i) => (i < 2 ? Math.max(v, 1) : v))];
}

function text(string, x, y, colour, size, align = "left") {
  labels.font = `${size}px system-ui, sans-serif`;
  labels.textAlign = align;
  labels.lineWidth = 3;
  labels.strokeStyle = "rgba(10, 12, 16, 0.85)";
  labels.strokeText(string, x, y);
  labels.fillStyle = colour;
  labels.fillText(string, x, y);
  report.view3dLabelsDrawn++;
}

// Names that would cover one another: each goes to the first free place of `at` ([x, y]: left,
// baseline), the first placed winning (the caller puts the selected body, the cameras and the
// nearer bodies first); one with no free place is drawn at its first all the same when `always`,
// else left out until the view turns (a crowd's). Returns whether it was drawn.
function placeLabel(placed, string, at, colour, size, always = true) {
  labels.font = `${size}px system-ui, sans-serif`;
  const width = labels.measureText(string).width;
  const boxes = at.map(([x, y]) => ({ x, y, x0: x - 1, x1: x + width + 1, y0: y - size, y1: y + 3 }));
  const free = boxes.find((b) => !placed.some((p) => b.x0 < p.x1 && p.x0 < b.x1 && b.y0 < p.y1 && p.y0 < b.y1));
  const box = free ?? (always ? boxes[0] : null);
  if (!box) return false;
  placed.push(box);
  text(string, box.x, box.y, colour, size);
  return true;
}

// Beside a point: right and up first, then the other corners.
const around = (x, y, size, width = 0) => [[x + 7, y - 6], [x - 7 - width, y - 6], [x + 7, y + size + 2], [x - 7 - width, y + size + 2]];

// The follow select lists the bodies; rebuilt when they change.
function updateFollow(drawnBodies) {
  const names = drawnBodies.map((b) => b.name).sort((a, b) => a.localeCompare(b, undefined, { numeric: true }));
  const key = names.join("\n");
  if (key === followNames) return;
  followNames = key;
  follow.replaceChildren(new Option("nothing", ""), ...names.map((name) => new Option(name, name)));
  follow.value = following;
}

function figures(b, cloud) {
  const { body } = b;
  const rows = [[b.name, b.lost ? "lost" : ""]];
  rows.push(["position", `${body.x.toFixed(3)}, ${body.y.toFixed(3)}, ${body.z.toFixed(3)} m`]);
  if (body.pose) {
    rows.push(["rate", body.rate === null ? "—" : `${body.rate} Hz here`]);
    rows.push(["latency", `${body.latencyMs.toFixed(1)} ms to the bridge`]);
    rows.push(["error", `${body.pose.reprojection_rms_px.toFixed(2)} px rms, ${body.pose.points_used} points`]);
    // Which cameras: its markers' camera bits, in the fusion's camera order.
    let bits = 0;
    for (const m of cloud) {
      if (!(m.body >= 0) || m.cameras === undefined) continue;
      const d = Math.hypot(m.x - body.x, m.y - body.y, m.z - body.z);
      if (d > OWN_MARKER_M) continue;
      const nearer = cloudOwners.get(m);
      if (nearer === b.name) bits |= m.cameras;
    }
    const names = graph.cameraOrder.map((frame, i) => ((bits >>> i) & 1 ? frame.replace(/_optical$/, "") : null)).filter(Boolean);
    rows.push(["cameras", `${body.pose.cameras_used}${names.length ? `: ${names.join(", ")}` : ""}`]);
  } else {
    rows.push(["from", "/tf: no figures"]);
  }
  return rows;
}

// Each labeled marker's nearest body, for the selected body's cameras: computed when one is
// selected, not otherwise.
function ownMarkers(cloud, drawnBodies) {
  cloudOwners = new Map();
  for (const m of cloud) {
    if (!(m.body >= 0)) continue;
    let best = OWN_MARKER_M;
    let owner = "";
    for (const b of drawnBodies) {
      const d = Math.hypot(m.x - b.body.x, m.y - b.body.y, m.z - b.body.z);
      if (d < best) {
        best = d;
        owner = b.name;
      }
    }
    cloudOwners.set(m, owner);
  }
}

function showBox(drawnBodies, cloud) {
  const b = drawnBodies.find((x) => x.name === selected);
  if (!b) {
    box.hidden = true;
    return;
  }
  ownMarkers(cloud, drawnBodies);
  const rows = figures(b, cloud);
  const html = `<h3 style="color:${b.colour}">${escape(rows[0][0])} <small>${rows[0][1]}</small></h3><table>` +
    rows.slice(1).map(([k, v]) => `<tr><th>${k}</th><td>${escape(v)}</td></tr>`).join("") + "</table>";
  if (box.innerHTML !== html) box.innerHTML = html;
  box.hidden = false;
}

const escape = (s) => String(s).replace(/[&<>"]/g, (c) => `&#${c.charCodeAt(0)};`);

// Draws the view now.
export function draw() {
  if (!renderer || section.hidden) return;
  const started = performance.now();
  const now = Date.now();
  pending = false;
  for (const key of ["view3dBodiesDrawn", "view3dRobotsDrawn", "view3dTrailSegments", "view3dLabelsDrawn", "view3dLabeledMarkers"]) report[key] = 0;
  const list = cameras();
  const drawnBodies = bodies(now);
  const [min, max] = bounds(list, drawnBodies);
  const camerasKey = list.map((c) => c.frame).join(",");
  if (!userMoved && camerasKey !== fittedTo) {
    fit(list, min, max);
    fittedTo = camerasKey;
  }
  const followed = drawnBodies.find((b) => b.name === following);
  if (followed) {
    orbit.target = [followed.body.x, followed.body.y, followed.body.z];
    orbit.update();
  }
  renderer.clear();
  grid([min[0] - 0.5, min[1] - 0.5], [max[0] + 0.5, max[1] + 0.5]);
  const byLevel = {};
  const levels = list.map((c) => cameraLevel(c.name, now));
  list.forEach((c, i) => {
    camera(c, LEVEL_COLOURS[levels[i]]);
    byLevel[LEVELS[levels[i]]] = (byLevel[LEVELS[levels[i]]] ?? 0) + 1;
  });
  levelsKey = levels.join();
  const cloud = markers();
  for (const m of cloud) {
    const labeled = m.body >= 0;
    A[0] = m.x;
    A[1] = m.y;
    A[2] = m.z;
    renderer.point(A, labeled ? LABELED : UNLABELED, 6);
    if (labeled) report.view3dLabeledMarkers++;
  }
  const crowded = drawnBodies.length > CROWDED_BODIES;
  for (const b of drawnBodies) body(b, crowded);
  renderer.draw(orbit.viewProjection, canvas.width, canvas.height, BACKGROUND);

  // The names, over the drawing.
  const width = overlay.width;
  const height = overlay.height;
  labels.clearRect(0, 0, width, height);
  const scale = canvas.clientWidth ? canvas.clientWidth / canvas.width : 1;
  const screen = { cameras: {}, bodies: {} };
  onScreen = [];
  const placed = [];
  for (const b of drawnBodies) {
    const p = orbit.project([b.body.x, b.body.y, b.body.z], width, height);
    if (!p) continue;
    screen.bodies[b.name] = [p.x * scale, p.y * scale];
    onScreen.push({ name: b.name, x: p.x, y: p.y, depth: p.depth, b });
  }
  const chosen = onScreen.find((o) => o.name === selected || o.name === following);
  if (chosen) {
    labels.strokeStyle = "#ffffff";
    labels.lineWidth = 2;
    labels.beginPath();
    labels.arc(chosen.x, chosen.y, 13, 0, 2 * Math.PI);
    labels.stroke();
    placeLabel(placed, chosen.name, [[chosen.x + 15, chosen.y - 8]], chosen.b.colour, 15);
  }
  list.forEach((c, i) => {
    const t = c.pose.translation;
    const p = orbit.project([t.x, t.y, t.z], width, height);
    if (!p) return;
    screen.cameras[c.name] = [p.x * scale, p.y * scale];
    labels.font = "15px system-ui, sans-serif";
    const w = labels.measureText(c.name).width;
    placeLabel(placed, c.name, [[p.x - w / 2, p.y - 16], [p.x - w / 2, p.y + 28]], LEVEL_COLOURS[levels[i]], 15);
  });
  let hidden = 0;
  const size = crowded ? 12 : 14;
  for (const o of [...onScreen].sort((a, b) => a.depth - b.depth)) {
    if (o === chosen) continue;
    labels.font = `${size}px system-ui, sans-serif`;
    const w = labels.measureText(o.name).width;
    if (!placeLabel(placed, o.name, around(o.x, o.y, size, w), o.b.colour, size, !crowded)) hidden++;
  }
  report.view3dLabelsHidden = hidden;
  // The world's axes last: a body's name matters more.
  ["x", "y", "z"].forEach((axis, i) => {
    const end = [0, 0, 0];
    end[i] = WORLD_AXIS_M * 1.2;
    const p = orbit.project(end, width, height);
    if (p) placeLabel(placed, axis, [[p.x - 4, p.y + 5], [p.x + 4, p.y - 4]], AXIS_HEX[i], 15, false);
  });
  if (followed) text(`following ${following}`, 12, 24, followed.colour, 15);
  updateFollow(drawnBodies);
  showBox(drawnBodies, cloud);
  renderer.finish();

  report.view3d = "drawn";
  report.view3dFrames++;
  report.view3dCamerasDrawn = list.length;
  report.view3dCamerasByLevel = byLevel;
  report.view3dMarkersDrawn = cloud.length;
  report.view3dEye = orbit.state();
  report.view3dSelected = box.hidden ? "" : selected;
  report.view3dFollowing = followed ? following : "";
  report.view3dScreen = screen;
  report.view3dCanvas = [canvas.clientWidth, canvas.clientHeight];
  report.view3dDrawMs.push(performance.now() - started);
  if (report.view3dDrawMs.length > DRAWS_KEPT) report.view3dDrawMs.shift();
}

// Whether the view has news of its own to draw (the pointer moved it).
export const wanted = () => pending;

// Once a second: a camera whose statuses stopped coming turns grey, a body whose poses did, lost.
export function tick() {
  const now = Date.now();
  const key = cameras().map((c) => cameraLevel(c.name, now)).join();
  const lost = [...graph.bodies.values()].some((b) => now - b.receivedAt > LOST_MS && now - b.receivedAt < LOST_MS + 1500);
  if (key !== levelsKey || lost) pending = true;
}

// The body under (x, y) (drawing-buffer pixels): the nearest to the eye among those within reach.
function pick(x, y) {
  let best = null;
  for (const b of onScreen) {
    const d = Math.hypot(b.x - x, b.y - y);
    if (d > PICK_RADIUS_PX) continue;
    if (!best || d < best.d - 4 || (Math.abs(d - best.d) <= 4 && b.depth < best.depth)) best = { ...b, d };
  }
  return best?.name ?? "";
}

function bufferPoint(event) {
  const rect = canvas.getBoundingClientRect();
  return [((event.clientX - rect.left) * canvas.width) / rect.width, ((event.clientY - rect.top) * canvas.height) / rect.height];
}

function setFollowing(name) {
  following = name;
  follow.value = name;
  pending = true;
}

if (renderer) {
  let drag = null;
  stage.addEventListener("contextmenu", (event) => event.preventDefault());
  stage.addEventListener("pointerdown", (event) => {
    if (box.contains(event.target)) return;
    drag = { x: event.clientX, y: event.clientY, moved: 0, pan: event.button === 2 || event.shiftKey };
    stage.setPointerCapture(event.pointerId);
  });
  stage.addEventListener("pointermove", (event) => {
    if (!drag) return;
    const dx = event.clientX - drag.x;
    const dy = event.clientY - drag.y;
    drag.x = event.clientX;
    drag.y = event.clientY;
    drag.moved += Math.abs(dx) + Math.abs(dy);
    if (drag.moved < 3) return;
    userMoved = true;
    if (drag.pan) {
      if (following) setFollowing("");
      orbit.pan(dx, dy, canvas.getBoundingClientRect().height);
    } else {
      orbit.orbit(dx, dy);
    }
    pending = true;
  });
  stage.addEventListener("pointerup", (event) => {
    if (!drag) return;
    const click = drag.moved < 3 && !drag.pan;
    drag = null;
    if (!click) return;
    selected = pick(...bufferPoint(event));
    pending = true;
  });
  stage.addEventListener("dblclick", (event) => {
    const name = pick(...bufferPoint(event));
    setFollowing(name === following ? "" : name);
  });
  stage.addEventListener("wheel", (event) => {
    event.preventDefault();
    userMoved = true;
    orbit.zoom(event.deltaY * (event.deltaMode === 1 ? 33 : 1));
    pending = true;
  }, { passive: false });
  follow.addEventListener("change", () => setFollowing(follow.value));
  $("view3d-home").addEventListener("click", () => {
    userMoved = false;
    fittedTo = "";
    setFollowing("");
    orbit.azimuth = new Orbit().azimuth;
    orbit.elevation = new Orbit().elevation;
  });
}

// For the browser test: draws a frame now and counts, in the drawing buffer before the page
// shows it, the pixels around `name`'s camera or body (within `radius` CSS pixels) that are not
// the background, and in the whole frame.
window.view3dProbe = {
  drawnAround(name, radius) {
    if (!renderer) return null;
    draw();
    const at = report.view3dScreen.cameras[name] ?? report.view3dScreen.bodies[name];
    if (!at) return null;
    const scale = canvas.width / (canvas.clientWidth || canvas.width);
    const around = renderer.countDrawn(at[0] * scale, at[1] * scale, Math.round(radius * scale), BACKGROUND);
    const whole = renderer.countDrawn(canvas.width / 2, canvas.height / 2, canvas.width / 2, BACKGROUND);
    return { ...around, frameDrawn: whole.drawn, frameTotal: whole.total };
  },
};
