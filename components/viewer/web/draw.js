// The canvases, from the viewer's state (state.js): a single camera's image with the
// fiducials, constellations and poses' axes found in it; a volume's cameras side by side and
// seen from above with its bodies, robots and marker cloud; the boards seen from above in the
// camera frame; the floor; a volume calibration's report seen from above.
import { halfView, project, rotate, yaw } from "./geometry.js";
import { points } from "./point_cloud.js";
import { foundIn, graph, inWorld, report } from "./state.js";
import { subject } from "./topics.js";

const COLOURS = ["#ffd54a", "#5fd38d", "#6cb6ff", "#ff8f6b", "#d59bff"];
const AXIS_LENGTH_M = 0.1;
const AXIS_COLOURS = ["#ff5252", "#5fd38d", "#6cb6ff"];  // x, y, z
const LATENCIES_KEPT = 1000;
const WORLD = "world";
// Above this many bodies in the volume, they are drawn small and without names.
const CROWDED_BODIES = 20;

const $ = (id) => document.getElementById(id);
const camera = $("camera");
const cameraContext = camera.getContext("2d");

// An image's pixels, converted once for all the drawings over it.
function pixels() {
  const offscreen = document.createElement("canvas");
  return { offscreen, context: offscreen.getContext("2d"), imageData: null, image: null };
}
const mainView = pixels();
const volumeViews = new Map();  // image topic -> its figure, canvas, caption and pixels

// The camera of a graph with one (the follower's turret camera), or undefined.
const soleCamera = () => (graph.cameras.size === 1 ? graph.cameras.values().next().value : undefined);

// An image message into a view's offscreen canvas, resizing `fit` to it; false for encodings
// this viewer does not draw.
function toPixels(image, view, fit) {
  if (view.image === image) return true;
  const { width, height, encoding, step, data } = image;
  const channels = { mono8: 1, bgr8: 3, rgb8: 3, bgra8: 4, rgba8: 4 }[encoding];
  if (!channels || data.length < step * height) {
    $("camera-note").textContent = `cannot draw ${encoding} images`;
    return false;
  }
  if (!view.imageData || view.imageData.width !== width || view.imageData.height !== height) {
    view.imageData = new ImageData(width, height);
    view.offscreen.width = width;
    view.offscreen.height = height;
    if (fit) {
      fit.width = width;
      fit.height = height;
    }
  }
  const out = view.imageData.data;
  const swap = encoding.startsWith("bgr");
  for (let y = 0; y < height; y++) {
    let i = y * step;
    let o = y * width * 4;
    for (let x = 0; x < width; x++, o += 4, i += channels) {
      if (channels === 1) {
        out[o] = out[o + 1] = out[o + 2] = data[i];
      } else {
        out[o] = data[swap ? i + 2 : i];
        out[o + 1] = data[i + 1];
        out[o + 2] = data[swap ? i : i + 2];
      }
      out[o + 3] = 255;
    }
  }
  view.context.putImageData(view.imageData, 0, 0);
  view.image = image;
  return true;
}

export function drawCameras() {
  const sole = soleCamera();
  if (sole) drawCamera(sole);
  else drawVolumeCameras();
}

function drawCamera(c) {
  if (!c.dirty || !c.image) return;
  c.dirty = false;
  const fresh = mainView.image !== c.image;
  if (!toPixels(c.image, mainView, camera)) return;
  if (fresh) {
    report.images++;
    report.frameStamp = c.frameStamp;
    report.drawLatenciesMs.push(Date.now() - Number(c.frameStamp) * 1000);
    if (report.drawLatenciesMs.length > LATENCIES_KEPT) report.drawLatenciesMs.shift();
  }
  cameraContext.drawImage(mainView.offscreen, 0, 0);
  const header = c.image.header;
  const fiducials = foundIn("fiducials", header) ?? [];
  const constellations = foundIn("constellations", header) ?? [];
  const scale = camera.width / 1280;
  cameraContext.lineWidth = 2 * scale;
  cameraContext.strokeStyle = "#ffd54a";
  let circles = 0;
  for (const f of fiducials) {
    cameraContext.beginPath();
    cameraContext.arc(f.x, f.y, Math.max(6, Math.sqrt(f.size ?? 36)) * scale, 0, 2 * Math.PI);
    cameraContext.stroke();
    circles++;
  }
  cameraContext.font = `${16 * scale}px system-ui, sans-serif`;
  for (const constellation of constellations) {
    cameraContext.strokeStyle = "#5fd38d";
    cameraContext.fillStyle = "#5fd38d";
    let sx = 0;
    let sy = 0;
    let n = 0;
    for (const sub of constellation.sub_constellations) {
      // A marker not seen (hidden, out of the picture) is NaN: the line joins the seen ones.
      const points = sub.fiducial_array.fiducials.filter((p) => Number.isFinite(p.x) && Number.isFinite(p.y));
      if (points.length < 2) continue;
      cameraContext.beginPath();
      cameraContext.moveTo(points[0].x, points[0].y);
      for (const p of points.slice(1)) cameraContext.lineTo(p.x, p.y);
      cameraContext.stroke();
      for (const p of points) {
        sx += p.x;
        sy += p.y;
        n++;
      }
    }
    if (n) cameraContext.fillText(constellation.name, sx / n + 12 * scale, sy / n - 12 * scale);
  }
  report.fiducialsInFrame = fiducials.length;
  report.circlesDrawn = circles;
  const poses = foundIn("poses", header) ?? [];
  report.posesInFrame = poses.length;
  const info = graph.infos.get(header.frame_id);
  report.axesDrawn = info ? drawAxes(poses, scale, info) : 0;
}

// Each pose's axes, 10 cm long, reprojected into the image; returns how many poses were drawn.
function drawAxes(poses, scale, info) {
  let drawn = 0;
  cameraContext.lineWidth = 3 * scale;
  for (const pose of poses) {
    const { position: t, orientation: q } = pose.pose.pose;
    const at = (v) => {
      const r = rotate(q, v);
      return project(info, { x: t.x + r.x, y: t.y + r.y, z: t.z + r.z });
    };
    const origin = at({ x: 0, y: 0, z: 0 });
    if (!origin) continue;
    const ends = [
      at({ x: AXIS_LENGTH_M, y: 0, z: 0 }),
      at({ x: 0, y: AXIS_LENGTH_M, z: 0 }),
      at({ x: 0, y: 0, z: AXIS_LENGTH_M }),
    ];
    ends.forEach((end, i) => {
      if (!end) return;
      cameraContext.strokeStyle = AXIS_COLOURS[i];
      cameraContext.beginPath();
      cameraContext.moveTo(origin.u, origin.v);
      cameraContext.lineTo(end.u, end.v);
      cameraContext.stroke();
    });
    drawn++;
  }
  return drawn;
}

function volumeView(topic, name) {
  let view = volumeViews.get(topic);
  if (view) return view;
  const figure = document.createElement("figure");
  const canvas = document.createElement("canvas");
  canvas.width = 640;
  canvas.height = 360;
  const caption = document.createElement("figcaption");
  caption.textContent = name;
  figure.append(canvas, caption);
  const after = [...volumeViews.keys()].sort().find((other) => other > topic);
  $("volume-cameras").insertBefore(figure, after ? volumeViews.get(after).figure : null);
  view = { figure, canvas, caption, ...pixels() };
  volumeViews.set(topic, view);
  return view;
}

function drawVolumeCameras() {
  for (const [topic, view] of volumeViews) {
    if (graph.cameras.has(topic)) continue;
    view.figure.remove();
    volumeViews.delete(topic);
  }
  for (const [topic, c] of graph.cameras) {
    if (!c.dirty || !c.image) continue;
    c.dirty = false;
    const view = volumeView(topic, c.name);
    if (!toPixels(c.image, view)) continue;
    const context = view.canvas.getContext("2d");
    const scale = view.canvas.width / view.offscreen.width;
    context.drawImage(view.offscreen, 0, 0, view.canvas.width, view.canvas.height);
    const found = foundIn("fiducials", c.image.header);
    const fiducials = found ?? [];
    context.strokeStyle = "#ffd54a";
    context.lineWidth = 1.5;
    for (const f of fiducials) {
      context.beginPath();
      context.arc(f.x * scale, f.y * scale, 5, 0, 2 * Math.PI);
      context.stroke();
    }
    view.caption.textContent = found
      ? `${c.name}: ${fiducials.length} fiducials`
      : `${c.name}: its fiducials not yet here`;
    report.volumeImagesDrawn[c.name] = (report.volumeImagesDrawn[c.name] ?? 0) + 1;
    report.volumeCirclesDrawn[c.name] = fiducials.length;
  }
}

function grid(context, width, height, pixelsPerMetre, originX, originY) {
  context.fillStyle = "#000";
  context.fillRect(0, 0, width, height);
  context.strokeStyle = "#222a33";
  context.lineWidth = 1;
  const step = pixelsPerMetre / 2;
  for (let x = originX % step; x < width; x += step) {
    context.beginPath();
    context.moveTo(x, 0);
    context.lineTo(x, height);
    context.stroke();
  }
  for (let y = originY % step; y < height; y += step) {
    context.beginPath();
    context.moveTo(0, y);
    context.lineTo(width, y);
    context.stroke();
  }
}

export function drawVolumeTop() {
  const canvas = $("volume-top");
  const context = canvas.getContext("2d");
  const ppm = 80;
  const ox = canvas.width / 2;
  const oy = canvas.height / 2;
  grid(context, canvas.width, canvas.height, ppm, ox, oy);
  const at = (p) => [ox + p.x * ppm, oy - p.y * ppm];
  context.font = "12px system-ui, sans-serif";
  let cones = 0;
  const drawn = new Set();
  for (const c of graph.cameras.values()) {
    const frame = c.image?.header.frame_id;
    const info = graph.infos.get(frame);
    const pose = inWorld(frame);
    if (!info || !pose) continue;
    // The optical axis and the image's sides, seen from above, out to 3 m.
    const half = halfView(info);
    const axis = rotate(pose.rotation, { x: 0, y: 0, z: 1 });
    const heading = Math.atan2(axis.y, axis.x);
    const [px, py] = at(pose.translation);
    context.strokeStyle = "#7d8794";
    context.fillStyle = "rgba(125, 135, 148, 0.12)";
    context.beginPath();
    context.moveTo(px, py);
    context.lineTo(px + 3 * ppm * Math.cos(heading - half), py - 3 * ppm * Math.sin(heading - half));
    context.lineTo(px + 3 * ppm * Math.cos(heading + half), py - 3 * ppm * Math.sin(heading + half));
    context.closePath();
    context.fill();
    context.stroke();
    context.fillStyle = "#d8dee6";
    context.fillRect(px - 5, py - 5, 10, 10);
    context.fillText(c.name, px + 8, py + (py > oy ? 16 : -8));
    cones++;
    drawn.add(frame);
  }
  // Cameras that send no images (centroids, as motion-capture cameras do): where the fusion's
  // /tf puts their optical frames, with the direction they look.
  for (const [frame, t] of graph.tf) {
    if (drawn.has(frame) || !frame.endsWith("_optical") || t.header.frame_id !== WORLD) continue;
    const { translation, rotation } = t.transform;
    const axis = rotate(rotation, { x: 0, y: 0, z: 1 });
    const [px, py] = at(translation);
    context.strokeStyle = "#7d8794";
    context.beginPath();
    context.moveTo(px, py);
    context.lineTo(px + 40 * axis.x, py - 40 * axis.y);
    context.stroke();
    context.fillStyle = "#d8dee6";
    context.fillRect(px - 5, py - 5, 10, 10);
    context.fillText(frame.replace(/_optical$/, ""), px + 8, py + (py > oy ? 16 : -8));
    drawn.add(frame);
  }
  // The marker cloud: markers a body or robot claims in its colour's grey, the others dimmer.
  let markers = [];
  try {
    markers = graph.markers ? points(graph.markers, ["x", "y", "z", "body"]) : [];
  } catch (error) {
    console.warn(`marker cloud: ${error.message}`);
  }
  for (const m of markers) {
    const [px, py] = at(m);
    context.fillStyle = m.body >= 0 ? "#d8dee6" : "#7d8794";
    context.fillRect(px - 1.5, py - 1.5, 3, 3);
  }
  // A swarm's robots smaller and unnamed (the poses' table names them).
  const crowded = graph.bodies.size > CROWDED_BODIES;
  const radius = crowded ? 3 : 6;
  let k = 0;
  for (const [name, body] of graph.bodies) {
    const colour = COLOURS[k++ % COLOURS.length];
    context.strokeStyle = colour;
    context.globalAlpha = 0.5;
    context.beginPath();
    body.trail.forEach((p, i) => (i ? context.lineTo : context.moveTo).call(context, ...at(p)));
    context.stroke();
    context.globalAlpha = 1;
    const [px, py] = at(body);
    context.fillStyle = colour;
    context.beginPath();
    context.arc(px, py, radius, 0, 2 * Math.PI);
    context.fill();
    if (body.yaw !== null) {
      // No heading for a robot of one marker: it has no orientation.
      context.beginPath();
      context.moveTo(px, py);
      context.lineTo(px + (radius + 10) * Math.cos(body.yaw), py - (radius + 10) * Math.sin(body.yaw));
      context.stroke();
    }
    if (!crowded) context.fillText(name, px + 9, py - 9);
  }
  report.volumeConesDrawn = cones;
  report.volumeCamerasDrawn = drawn.size;
  report.volumeBodiesDrawn = graph.bodies.size;
  report.volumeMarkersDrawn = markers.length;
}

export function drawTop() {
  const canvas = $("top");
  const context = canvas.getContext("2d");
  const ppm = 100;  // pixels per metre
  const ox = canvas.width / 2;
  const oy = canvas.height - 20;
  grid(context, canvas.width, canvas.height, ppm, ox, oy);
  // The camera and its field of view (about 90 degrees).
  context.strokeStyle = "#7d8794";
  context.beginPath();
  context.moveTo(ox - 3 * ppm, oy - 3 * ppm);
  context.lineTo(ox, oy);
  context.lineTo(ox + 3 * ppm, oy - 3 * ppm);
  context.stroke();
  context.fillStyle = "#d8dee6";
  context.fillRect(ox - 6, oy - 4, 12, 8);
  let k = 0;
  report.boardsOnTop = graph.trails.size;
  for (const [name, trail] of graph.trails) {
    const colour = COLOURS[k++ % COLOURS.length];
    context.strokeStyle = colour;
    context.globalAlpha = 0.5;
    context.beginPath();
    trail.forEach((p, i) => (i ? context.lineTo : context.moveTo).call(context, ox + p.x * ppm, oy - p.z * ppm));
    context.stroke();
    context.globalAlpha = 1;
    const last = trail[trail.length - 1];
    context.fillStyle = colour;
    context.beginPath();
    context.arc(ox + last.x * ppm, oy - last.z * ppm, 5, 0, 2 * Math.PI);
    context.fill();
    context.fillText(name, ox + last.x * ppm + 8, oy - last.z * ppm - 8);
  }
}

export function drawFloor() {
  const canvas = $("floor");
  const context = canvas.getContext("2d");
  const ppm = 60;
  const ox = canvas.width / 2;
  const oy = canvas.height / 2;
  grid(context, canvas.width, canvas.height, ppm, ox, oy);
  const marker = (x, y, theta, colour, label) => {
    const px = ox + x * ppm;
    const py = oy - y * ppm;
    context.fillStyle = colour;
    context.strokeStyle = colour;
    context.beginPath();
    context.arc(px, py, 7, 0, 2 * Math.PI);
    context.fill();
    context.beginPath();
    context.moveTo(px, py);
    context.lineTo(px + 18 * Math.cos(theta), py - 18 * Math.sin(theta));
    context.stroke();
    context.fillText(label, px + 10, py - 10);
  };
  // Each ceiling camera's view of the robots' plane.
  const footprints = [...graph.footprints.values()].flat();
  context.strokeStyle = "#7d8794";
  context.fillStyle = "#7d8794";
  for (const f of footprints) {
    context.beginPath();
    f.corners.forEach((c, i) => (i ? context.lineTo : context.moveTo).call(context, ox + c.x * ppm, oy - c.y * ppm));
    context.closePath();
    context.stroke();
    context.fillText(f.name, ox + f.corners[0].x * ppm + 4, oy - f.corners[0].y * ppm + 12);
  }
  const info = graph.infos.get(soleCamera()?.image?.header.frame_id);
  for (const [topic, base] of graph.bases) {
    const heading = yaw(base.orientation);
    marker(base.position.x, base.position.y, heading, "#6cb6ff", subject(topic));
    if (!graph.turret) continue;
    // Where the turret's camera looks: the base's heading turned by the pan joint.
    const looking = heading + graph.turret.pan;
    const half = info ? halfView(info) : 0.6;
    const px = ox + base.position.x * ppm;
    const py = oy - base.position.y * ppm;
    context.strokeStyle = "#ffd54a";
    context.beginPath();
    context.moveTo(px, py);
    context.lineTo(px + 40 * Math.cos(looking - half), py - 40 * Math.sin(looking - half));
    context.moveTo(px, py);
    context.lineTo(px + 40 * Math.cos(looking + half), py - 40 * Math.sin(looking + half));
    context.stroke();
  }
  // Every topic's: an estimate and its ground truth are one robot drawn twice.
  const robots = [...graph.robots.values()].flat();
  for (const r of robots) marker(r.x, r.y, r.theta, "#ff8f6b", r.name);
  report.footprintsDrawn = footprints.length;
  report.robotsDrawn = new Set(robots.map((r) => r.name)).size;
  if (graph.bases.size === 0 && robots.length === 0) {
    context.fillStyle = "#7d8794";
    context.fillText("no mobile base or robots in this graph", 12, 20);
  }
}

// The calibration's picture: the volume from above, scaled to its cameras and floor marks with
// this much room around them (metres) and, in pixels, for the grid's figures and the names.
const PICTURE_MARGIN_M = 0.6;
const PICTURE_PAD = { left: 34, right: 14, top: 14, bottom: 26 };
const LOOK_PX = 48;  // a camera's arrow when it looks level; shorter as it looks down
const CALIBRATED = "#6cb6ff";
const PREVIOUS = "#7d8794";
const MARK = "#ffd54a";

// The world-frame rectangle holding `spots` ({x, y}), with the margin.
function extent(spots) {
  const xs = spots.map((p) => p.x);
  const ys = spots.map((p) => p.y);
  return {
    minX: Math.min(...xs) - PICTURE_MARGIN_M,
    maxX: Math.max(...xs) + PICTURE_MARGIN_M,
    minY: Math.min(...ys) - PICTURE_MARGIN_M,
    maxY: Math.max(...ys) + PICTURE_MARGIN_M,
  };
}

// A grid line every metre across the whole canvas, its figure (metres) along the bottom and the
// left side; the world's axes brighter, named at their positive ends.
function metreGrid(context, width, height, at, toWorld) {
  context.fillStyle = "#000";
  context.fillRect(0, 0, width, height);
  const low = toWorld(0, height);
  const high = toWorld(width, 0);
  context.font = "12px system-ui, sans-serif";
  context.lineWidth = 1;
  for (let x = Math.ceil(low.x); x <= high.x; x++) {
    const [px] = at({ x, y: 0 });
    context.strokeStyle = x === 0 ? "#4a5562" : "#222a33";
    context.beginPath();
    context.moveTo(px, 0);
    context.lineTo(px, height);
    context.stroke();
    context.fillStyle = PREVIOUS;
    context.textAlign = "center";
    context.fillText(String(x), px, height - 8);
  }
  for (let y = Math.ceil(low.y); y <= high.y; y++) {
    const [, py] = at({ x: 0, y });
    context.strokeStyle = y === 0 ? "#4a5562" : "#222a33";
    context.beginPath();
    context.moveTo(0, py);
    context.lineTo(width, py);
    context.stroke();
    context.fillStyle = PREVIOUS;
    context.textAlign = "left";
    context.fillText(String(y), 6, py + 4);
  }
  const [ox, oy] = at({ x: 0, y: 0 });
  context.fillStyle = "#aab3be";
  context.textAlign = "right";
  context.fillText("x m", width - 6, oy - 6);
  context.textAlign = "left";
  context.fillText("y m", ox + 6, 14);
}

// An arrow from (x, y) by (dx, dy) pixels, its head 6 px long.
function arrow(context, x, y, dx, dy) {
  const angle = Math.atan2(dy, dx);
  const [ex, ey] = [x + dx, y + dy];
  context.beginPath();
  context.moveTo(x, y);
  context.lineTo(ex, ey);
  for (const side of [-1, 1]) {
    context.moveTo(ex, ey);
    context.lineTo(ex - 6 * Math.cos(angle + side * 0.5), ey - 6 * Math.sin(angle + side * 0.5));
  }
  context.stroke();
}

// The calibration's report from above (world frame: x right, y up): each floor mark the board
// was laid at as a cross; each camera where its input file had it (a grey ring) and where the
// solve put it (a dot with its name), the line between them and the move in mm (a few mm: the
// line hides under the dot at this scale, the figure says it), and a short arrow where it looks.
export function drawCalibration() {
  const message = graph.result;
  report.calibrationPictureDrawn = 0;
  if (!message) return;  // hidden with the report
  const canvas = $("calibration-top");
  const context = canvas.getContext("2d");
  const { width, height } = canvas;
  const cameras = message.cameras;
  // Each mark once: the board is laid twice at each, the second time turned.
  const marks = [...new Map(message.floor.map((f) => [`${f.mark_x},${f.mark_y}`, { x: f.mark_x, y: f.mark_y }])).values()];
  const placed = cameras.flatMap((c) => [c.pose.position, ...(c.has_previous_pose ? [c.previous_pose.position] : [])]);
  const box = extent([...placed, ...marks, { x: 0, y: 0 }]);
  const areaWidth = width - PICTURE_PAD.left - PICTURE_PAD.right;
  const areaHeight = height - PICTURE_PAD.top - PICTURE_PAD.bottom;
  const ppm = Math.min(areaWidth / (box.maxX - box.minX), areaHeight / (box.maxY - box.minY));
  const cx = PICTURE_PAD.left + areaWidth / 2;
  const cy = PICTURE_PAD.top + areaHeight / 2;
  const mid = { x: (box.minX + box.maxX) / 2, y: (box.minY + box.maxY) / 2 };
  const at = (p) => [cx + (p.x - mid.x) * ppm, cy - (p.y - mid.y) * ppm];
  const toWorld = (px, py) => ({ x: mid.x + (px - cx) / ppm, y: mid.y - (py - cy) / ppm });
  metreGrid(context, width, height, at, toWorld);

  context.strokeStyle = MARK;
  context.lineWidth = 2;
  for (const mark of marks) {
    const [px, py] = at(mark);
    context.beginPath();
    context.moveTo(px - 6, py);
    context.lineTo(px + 6, py);
    context.moveTo(px, py - 6);
    context.lineTo(px, py + 6);
    context.stroke();
  }

  context.font = "13px system-ui, sans-serif";
  for (const c of cameras) {
    const [px, py] = at(c.pose.position);
    context.lineWidth = 1.5;
    if (c.has_previous_pose) {
      const [qx, qy] = at(c.previous_pose.position);
      context.strokeStyle = PREVIOUS;
      context.beginPath();
      context.arc(qx, qy, 9, 0, 2 * Math.PI);
      context.moveTo(qx, qy);
      context.lineTo(px, py);
      context.stroke();
    }
    // Its optical axis (+z of its frame) seen from above: short when it looks down.
    const look = rotate(c.pose.orientation, { x: 0, y: 0, z: 1 });
    context.strokeStyle = CALIBRATED;
    arrow(context, px, py, LOOK_PX * look.x, -LOOK_PX * look.y);
    context.fillStyle = CALIBRATED;
    context.beginPath();
    context.arc(px, py, 5, 0, 2 * Math.PI);
    context.fill();
    // The labels on the side away from the picture's middle, where the arrows point.
    const outward = c.pose.position.x >= mid.x ? 1 : -1;
    context.textAlign = outward > 0 ? "left" : "right";
    context.fillStyle = "#d8dee6";
    context.fillText(c.name, px + outward * 13, py - 3);
    if (c.has_previous_pose) {
      context.fillStyle = "#aab3be";
      context.fillText(`${(c.moved_m * 1e3).toFixed(2)} mm`, px + outward * 13, py + 13);
    }
  }
  context.textAlign = "left";
  report.calibrationPictureDrawn = cameras.length;
}
