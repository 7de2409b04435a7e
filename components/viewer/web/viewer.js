// The built-in viewer: the Foxglove WebSocket protocol from the page's own host (the bridge
// serves this file), messages decoded from their advertised schemas (cdr.js), drawn live.
// window.viewerState exposes what was drawn, for the browser test and for a curious console.
import { decode, parseSchema } from "./cdr.js";

const SUBPROTOCOL = "foxglove.websocket.v1";
const IMAGE = "/camera/ir/image_raw";
const CAMERA_INFO = "/camera/ir/camera_info";
const FIDUCIALS = "/mocap/fiducials";
const CONSTELLATIONS = "/mocap/constellations";
const POSES = "/mocap/poses";
const ALERTS = "/alerts";
const BASE = "/base/pose";
const ROBOTS = "/pixart/robots";
const TURRET = "/turret/joint_states";
const FOOTPRINTS = "/pixart/camera_footprints";
const TF = "/tf";
const TF_STATIC = "/tf_static";
// A volume's cameras: /volume/<camera>/image_raw, fiducials and camera_info.
const VOLUME = /^\/volume\/([^/]+)\/(image_raw|fiducials|camera_info)$/;
// Large and drawn by the overlay component already: not subscribed.
const SKIPPED = new Set(["/mocap/overlay"]);

const state = (window.viewerState = {
  connected: false,
  server: "",
  images: 0,
  frameStamp: null,  // stamp of the image on screen
  fiducialsInFrame: 0,  // the tracker's fiducials for that image
  circlesDrawn: 0,  // circles drawn on it
  axesDrawn: 0,  // poses whose axes were drawn on it (needs camera_info)
  posesInFrame: 0,  // the poses estimated from it
  footprintsDrawn: 0,  // on the floor
  robotsDrawn: 0,
  boardsOnTop: 0,  // boards drawn in the top view
  transformsUsed: 0,  // /tf transforms drawn there, when /mocap/poses does not come
  poseReadout: "",
  latencyMs: null,
  // Each drawn image's age when drawn (ms, page clock minus capture stamp): the last 1000.
  drawLatenciesMs: [],
  volumeImagesDrawn: {},  // camera -> images drawn
  volumeCirclesDrawn: {},  // camera -> circles drawn on its last image
  volumeConesDrawn: 0,  // cameras drawn from above with their view
  volumeBodiesDrawn: 0,  // bodies drawn from above
});

const $ = (id) => document.getElementById(id);
const statusLine = $("status");
const camera = $("camera");
const cameraContext = camera.getContext("2d");
const offscreen = document.createElement("canvas");
const offscreenContext = offscreen.getContext("2d");

const stampKey = (header) => `${header.stamp.sec}.${String(header.stamp.nanosec).padStart(9, "0")}`;
const stampSeconds = (header) => header.stamp.sec + header.stamp.nanosec * 1e-9;

// --- connection ---------------------------------------------------------------------------

let socket = null;
let channels = new Map();  // channel id -> {topic, schemaName, structs}
let bySubscription = new Map();
let topics = new Map();  // topic -> {type, count, bytes, rate, bandwidth}
let nextSubscription = 1;

function connect() {
  const url = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/`;
  // A bridge that asks for a token gets the one this page was opened with (?token=...).
  const token = new URLSearchParams(location.search).get("token");
  socket = new WebSocket(token ? `${url}?token=${encodeURIComponent(token)}` : url, [SUBPROTOCOL]);
  socket.binaryType = "arraybuffer";
  socket.onopen = () => {
    state.connected = true;
    statusLine.textContent = `connected to ${url}`;
    statusLine.className = "connected";
  };
  socket.onclose = () => {
    const was = state.connected;
    state.connected = false;
    channels = new Map();
    bySubscription = new Map();
    statusLine.textContent = `disconnected: no bridge at ${url}${was ? " (it went away)" : ""}; retrying every 2 s`;
    statusLine.className = "disconnected";
    setTimeout(connect, 2000);
  };
  socket.onmessage = (event) => {
    if (typeof event.data === "string") control(JSON.parse(event.data));
    else data(new Uint8Array(event.data));
  };
}

function control(message) {
  if (message.op === "serverInfo") {
    state.server = message.name;
  } else if (message.op === "advertise") {
    const subscriptions = [];
    for (const channel of message.channels) {
      if (channel.encoding !== "cdr" || channel.schemaEncoding !== "ros2idl") continue;
      let structs;
      try {
        structs = parseSchema(channel.schema);
      } catch (error) {
        console.warn(`${channel.topic}: ${error.message}`);
        continue;
      }
      channels.set(channel.id, { topic: channel.topic, schemaName: channel.schemaName, structs });
      topics.set(channel.topic, { type: channel.schemaName, count: 0, bytes: 0, rate: null, bandwidth: null });
      if (SKIPPED.has(channel.topic)) continue;
      const id = nextSubscription++;
      bySubscription.set(id, channels.get(channel.id));
      subscriptions.push({ id, channelId: channel.id });
    }
    if (subscriptions.length) socket.send(JSON.stringify({ op: "subscribe", subscriptions }));
    $("camera-note").textContent = topics.has(IMAGE) ? "" : `no ${IMAGE} in this graph`;
    const volume = [...topics.keys()].some((t) => VOLUME.test(t));
    $("volume").hidden = !volume;
    // A volume alone: the single camera's panels (its image, its top view, the floor) stay empty.
    const single = [IMAGE, BASE, ROBOTS, FOOTPRINTS].some((t) => topics.has(t));
    $("camera-section").hidden = volume && !topics.has(IMAGE);
    $("side-section").hidden = volume && !single;
    renderTopics();
  } else if (message.op === "unadvertise") {
    for (const id of message.channelIds) {
      const channel = channels.get(id);
      if (channel) topics.delete(channel.topic);
      channels.delete(id);
    }
    renderTopics();
  } else if (message.op === "status") {
    console.info(`bridge: ${message.message}`);
  }
}

function data(bytes) {
  if (bytes[0] !== 0x01 || bytes.length < 13) return;
  const view = new DataView(bytes.buffer, bytes.byteOffset);
  const channel = bySubscription.get(view.getUint32(1, true));
  if (!channel) return;
  // When the bridge received the message, on the graph's clock (the page's clock may be
  // another machine's).
  const receivedMs = Number(view.getBigUint64(5, true)) / 1e6;
  const payload = bytes.subarray(13);
  const topic = topics.get(channel.topic);
  if (topic) {
    topic.count++;
    topic.bytes += payload.length;
  }
  let message;
  try {
    message = decode(channel.structs, channel.schemaName, payload);
  } catch (error) {
    console.warn(`${channel.topic}: ${error.message}`);
    return;
  }
  const handler = handlers[channel.topic] ?? volumeHandler(channel.topic);
  if (handler) handler(message, receivedMs);
}

// --- what arrives -------------------------------------------------------------------------

const recentFiducials = new Map();  // stamp -> fiducials, the last few frames
const recentConstellations = new Map();
const recentPoses = new Map();
let cameraInfo = null;
let latestPoses = null;
let turret = null;  // {pan, tilt} in radians
let footprints = [];
const trails = new Map();  // pose name -> [{x, z}]
let posesAt = 0;  // page time of the last /mocap/poses

// A board's place in the camera's optical frame, seen from above (x right, z forward).
function addToTrail(name, position) {
  const trail = trails.get(name) ?? [];
  trail.push({ x: position.x, z: position.z });
  if (trail.length > 150) trail.shift();
  trails.set(name, trail);
}
let base = null;
let robots = [];
const alerts = [];
let dirty = { camera: false, side: false, volume: false };

// --- a volume of cameras ------------------------------------------------------------------

const worldFrames = new Map();  // frame -> its transform in "world" (/tf_static)
const volumeCameras = new Map();  // camera -> {figure, canvas, view, info, frameStamp, fiducials}
const volumeBodies = new Map();  // body -> {x, y, yaw, trail: [{x, y}]}

function addToVolume(name, pose) {
  const body = volumeBodies.get(name) ?? { trail: [] };
  const q = pose.orientation;
  body.x = pose.position.x;
  body.y = pose.position.y;
  body.yaw = Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
  body.trail.push({ x: body.x, y: body.y });
  if (body.trail.length > 150) body.trail.shift();
  volumeBodies.set(name, body);
}

function volumeCamera(name) {
  let c = volumeCameras.get(name);
  if (c) return c;
  const figure = document.createElement("figure");
  const canvas = document.createElement("canvas");
  canvas.width = 640;
  canvas.height = 360;
  const caption = document.createElement("figcaption");
  caption.textContent = name;
  figure.append(canvas, caption);
  const cameras = $("volume-cameras");
  const after = [...volumeCameras.keys()].sort().find((other) => other > name);
  cameras.insertBefore(figure, after ? volumeCameras.get(after).figure : null);
  const hidden = document.createElement("canvas");
  c = {
    figure,
    canvas,
    caption,
    view: { offscreen: hidden, context: hidden.getContext("2d"), imageData: null },
    info: null,
    frameStamp: null,
    fiducials: new Map(),
  };
  volumeCameras.set(name, c);
  return c;
}

// The handler of a volume camera's topic, or undefined.
function volumeHandler(topic) {
  const match = VOLUME.exec(topic);
  if (!match) return undefined;
  const c = volumeCamera(match[1]);
  if (match[2] === "image_raw") {
    return (image) => {
      if (!toPixels(image, c.view)) return;
      c.frameStamp = stampKey(image.header);
      c.dirty = true;
      dirty.volume = true;
    };
  }
  if (match[2] === "fiducials") {
    return (message) => {
      const key = stampKey(message.header);
      remember(c.fiducials, key, message.fiducials);
      // A camera publishes its image before it has found the fiducials in it: those of the
      // image on show may come after it was drawn.
      if (key === c.frameStamp) {
        c.dirty = true;
        dirty.volume = true;
      }
    };
  }
  return (info) => {
    c.info = info;
  };
}

function drawVolumeCameras() {
  for (const [name, c] of volumeCameras) {
    if (!c.dirty) continue;
    c.dirty = false;
    const context = c.canvas.getContext("2d");
    const scale = c.canvas.width / c.view.offscreen.width;
    context.drawImage(c.view.offscreen, 0, 0, c.canvas.width, c.canvas.height);
    const fiducials = c.fiducials.get(c.frameStamp) ?? [];
    context.strokeStyle = "#ffd54a";
    context.lineWidth = 1.5;
    for (const f of fiducials) {
      context.beginPath();
      context.arc(f.x * scale, f.y * scale, 5, 0, 2 * Math.PI);
      context.stroke();
    }
    c.caption.textContent = c.fiducials.has(c.frameStamp)
      ? `${name}: ${fiducials.length} fiducials`
      : `${name}: its fiducials not yet here`;
    state.volumeImagesDrawn[name] = (state.volumeImagesDrawn[name] ?? 0) + 1;
    state.volumeCirclesDrawn[name] = fiducials.length;
  }
}

function drawVolumeTop() {
  const canvas = $("volume-top");
  const context = canvas.getContext("2d");
  const ppm = 80;
  const ox = canvas.width / 2;
  const oy = canvas.height / 2;
  grid(context, canvas.width, canvas.height, ppm, ox, oy);
  const at = (p) => [ox + p.x * ppm, oy - p.y * ppm];
  context.font = "12px system-ui, sans-serif";
  let cones = 0;
  for (const [name, c] of volumeCameras) {
    const frame = c.info && worldFrames.get(c.info.header.frame_id);
    if (!frame) continue;
    // The optical axis and the image's sides, seen from above, out to 3 m.
    const half = Math.atan(c.info.width / 2 / c.info.k[0]);
    const axis = rotate(frame.rotation, { x: 0, y: 0, z: 1 });
    const heading = Math.atan2(axis.y, axis.x);
    const [px, py] = at(frame.translation);
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
    context.fillText(name, px + 8, py + (py > oy ? 16 : -8));
    cones++;
  }
  let k = 0;
  for (const [name, body] of volumeBodies) {
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
    context.arc(px, py, 6, 0, 2 * Math.PI);
    context.fill();
    context.beginPath();
    context.moveTo(px, py);
    context.lineTo(px + 16 * Math.cos(body.yaw), py - 16 * Math.sin(body.yaw));
    context.stroke();
    context.fillText(name, px + 9, py - 9);
  }
  state.volumeConesDrawn = cones;
  state.volumeBodiesDrawn = volumeBodies.size;
}

function remember(map, key, value) {
  map.set(key, value);
  while (map.size > 60) map.delete(map.keys().next().value);
}

const handlers = {
  [IMAGE](image) {
    if (!toPixels(image)) return;
    state.images++;
    state.frameStamp = stampKey(image.header);
    dirty.camera = true;
  },
  [FIDUCIALS](message) {
    remember(recentFiducials, stampKey(message.header), message.fiducials);
    dirty.camera = true;
  },
  [CONSTELLATIONS](message) {
    remember(recentConstellations, stampKey(message.header), message.constellations);
    dirty.camera = true;
  },
  [CAMERA_INFO](info) {
    cameraInfo = info;
  },
  [POSES](message, receivedMs) {
    latestPoses = message;
    remember(recentPoses, stampKey(message.header), message.poses);
    dirty.camera = true;
    // Capture to bridge, both on the graph's clocks: the page's Date.now() would add the
    // difference between this machine's clock and the graph's.
    state.latencyMs = receivedMs - stampSeconds(message.header) * 1000;
    posesAt = Date.now();
    if (message.header.frame_id === "world") {
      // A volume's bodies, in the world frame.
      for (const pose of message.poses) addToVolume(pose.name, pose.pose.pose);
      dirty.volume = true;
    } else {
      for (const pose of message.poses) addToTrail(pose.name, pose.pose.pose.position);
      dirty.side = true;
    }
    renderPoses();
  },
  // The boards as tf2 has them (pose_outputs, or any ROS 2 graph's /tf), drawn when
  // /mocap/poses does not come: those whose parent is a camera's optical frame.
  [TF](message) {
    if (Date.now() - posesAt < 2000) return;
    for (const t of message.transforms) {
      if (!t.header.frame_id.endsWith("_optical")) continue;
      addToTrail(t.child_frame_id, t.transform.translation);
      state.transformsUsed++;
      dirty.side = true;
    }
  },
  // Where a volume's cameras are (volume_fusion latches them).
  [TF_STATIC](message) {
    for (const t of message.transforms) {
      if (t.header.frame_id === "world") worldFrames.set(t.child_frame_id, t.transform);
    }
    dirty.volume = true;
  },
  [BASE](message) {
    base = message.pose;
    dirty.side = true;
  },
  [ROBOTS](message) {
    robots = message.robots;
    dirty.side = true;
  },
  [TURRET](message) {
    const joint = (name, index) => {
      const i = message.name.indexOf(name);
      return message.position[i >= 0 ? i : index];
    };
    turret = { pan: joint("pan", 0), tilt: joint("tilt", 1) };
    const deg = (a) => ((a * 180) / Math.PI).toFixed(1);
    $("turret").textContent = `turret: pan ${deg(turret.pan)}°, tilt ${deg(turret.tilt)}°`;
    dirty.side = true;
  },
  [FOOTPRINTS](message) {
    footprints = message.cameras;
    dirty.side = true;
  },
  [ALERTS](alert) {
    alerts.unshift(alert);
    alerts.length = Math.min(alerts.length, 8);
    renderAlerts();
  },
};

// An image message into a view's offscreen canvas (the camera's by default); false for
// encodings this viewer does not draw.
const mainView = { offscreen, context: offscreenContext, imageData: null, canvas: camera };
function toPixels(image, view = mainView) {
  const { width, height, encoding, step, data: pixels } = image;
  const channelsOf = { mono8: 1, bgr8: 3, rgb8: 3, bgra8: 4, rgba8: 4 }[encoding];
  if (!channelsOf || pixels.length < step * height) {
    $("camera-note").textContent = `cannot draw ${encoding} images`;
    return false;
  }
  if (!view.imageData || view.imageData.width !== width || view.imageData.height !== height) {
    view.imageData = new ImageData(width, height);
    view.offscreen.width = width;
    view.offscreen.height = height;
    if (view.canvas) {
      view.canvas.width = width;
      view.canvas.height = height;
    }
  }
  const out = view.imageData.data;
  const swap = encoding.startsWith("bgr");
  for (let y = 0; y < height; y++) {
    let i = y * step;
    let o = y * width * 4;
    for (let x = 0; x < width; x++, o += 4, i += channelsOf) {
      if (channelsOf === 1) {
        out[o] = out[o + 1] = out[o + 2] = pixels[i];
      } else {
        out[o] = pixels[swap ? i + 2 : i];
        out[o + 1] = pixels[i + 1];
        out[o + 2] = pixels[swap ? i : i + 2];
      }
      out[o + 3] = 255;
    }
  }
  view.context.putImageData(view.imageData, 0, 0);
  return true;
}

// --- drawing ------------------------------------------------------------------------------

let drawnStamp = null;
function drawCamera() {
  cameraContext.drawImage(offscreen, 0, 0);
  if (state.frameStamp !== drawnStamp) {
    drawnStamp = state.frameStamp;
    state.drawLatenciesMs.push(Date.now() - Number(drawnStamp) * 1000);
    if (state.drawLatenciesMs.length > 1000) state.drawLatenciesMs.shift();
  }
  const fiducials = recentFiducials.get(state.frameStamp) ?? [];
  const constellations = recentConstellations.get(state.frameStamp) ?? [];
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
  for (const c of constellations) {
    cameraContext.strokeStyle = "#5fd38d";
    cameraContext.fillStyle = "#5fd38d";
    let sx = 0;
    let sy = 0;
    let n = 0;
    for (const sub of c.sub_constellations) {
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
    if (n) cameraContext.fillText(c.name, sx / n + 12 * scale, sy / n - 12 * scale);
  }
  state.fiducialsInFrame = fiducials.length;
  state.circlesDrawn = circles;
  const poses = recentPoses.get(state.frameStamp) ?? [];
  state.posesInFrame = poses.length;
  state.axesDrawn = drawAxes(poses, scale);
}

// A camera-frame point into the image with camera_info's pinhole and plumb_bob distortion;
// null behind the camera.
function project(info, p) {
  if (p.z <= 1e-6) return null;
  const x = p.x / p.z;
  const y = p.y / p.z;
  const [k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0] = info.distortion_model === "plumb_bob" ? info.d : [];
  const r2 = x * x + y * y;
  const radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  const k = info.k;
  return { u: k[0] * xd + k[1] * yd + k[2], v: k[4] * yd + k[5] };
}

function rotate(q, v) {
  // v + 2 w (u x v) + 2 u x (u x v), u = (q.x, q.y, q.z)
  const tx = 2 * (q.y * v.z - q.z * v.y);
  const ty = 2 * (q.z * v.x - q.x * v.z);
  const tz = 2 * (q.x * v.y - q.y * v.x);
  return {
    x: v.x + q.w * tx + (q.y * tz - q.z * ty),
    y: v.y + q.w * ty + (q.z * tx - q.x * tz),
    z: v.z + q.w * tz + (q.x * ty - q.y * tx),
  };
}

const AXIS_LENGTH_M = 0.1;
const AXIS_COLOURS = ["#ff5252", "#5fd38d", "#6cb6ff"];  // x, y, z

// Each pose's axes, 10 cm long, reprojected into the image; returns how many poses were drawn.
function drawAxes(poses, scale) {
  if (!cameraInfo) return 0;
  let drawn = 0;
  cameraContext.lineWidth = 3 * scale;
  for (const pose of poses) {
    const { position: t, orientation: q } = pose.pose.pose;
    const at = (v) => {
      const r = rotate(q, v);
      return project(cameraInfo, { x: t.x + r.x, y: t.y + r.y, z: t.z + r.z });
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

const COLOURS = ["#ffd54a", "#5fd38d", "#6cb6ff", "#ff8f6b", "#d59bff"];

function drawTop() {
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
  state.boardsOnTop = trails.size;
  for (const [name, trail] of trails) {
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

function drawFloor() {
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
  context.strokeStyle = "#7d8794";
  context.fillStyle = "#7d8794";
  for (const f of footprints) {
    context.beginPath();
    f.corners.forEach((c, i) => (i ? context.lineTo : context.moveTo).call(context, ox + c.x * ppm, oy - c.y * ppm));
    context.closePath();
    context.stroke();
    context.fillText(f.name, ox + f.corners[0].x * ppm + 4, oy - f.corners[0].y * ppm + 12);
  }
  if (base) {
    const q = base.orientation;
    const yaw = Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
    marker(base.position.x, base.position.y, yaw, "#6cb6ff", "base");
    if (turret) {
      // Where the turret's camera looks: the base's heading turned by the pan joint.
      const heading = yaw + turret.pan;
      const half = cameraInfo ? Math.atan(cameraInfo.width / 2 / cameraInfo.k[0]) : 0.6;
      const px = ox + base.position.x * ppm;
      const py = oy - base.position.y * ppm;
      context.strokeStyle = "#ffd54a";
      context.beginPath();
      context.moveTo(px, py);
      context.lineTo(px + 40 * Math.cos(heading - half), py - 40 * Math.sin(heading - half));
      context.moveTo(px, py);
      context.lineTo(px + 40 * Math.cos(heading + half), py - 40 * Math.sin(heading + half));
      context.stroke();
    }
  }
  for (const r of robots) marker(r.x, r.y, r.theta, "#ff8f6b", r.name);
  state.footprintsDrawn = footprints.length;
  state.robotsDrawn = robots.length;
  if (!base && robots.length === 0) {
    context.fillStyle = "#7d8794";
    context.fillText(`no ${BASE} or ${ROBOTS} in this graph`, 12, 20);
  }
}

function degrees(q) {
  const roll = Math.atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x * q.x + q.y * q.y));
  const pitch = Math.asin(Math.max(-1, Math.min(1, 2 * (q.w * q.y - q.z * q.x))));
  const yaw = Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
  return [roll, pitch, yaw].map((a) => ((a * 180) / Math.PI).toFixed(1));
}

function renderPoses() {
  const rows = latestPoses.poses.map((pose) => {
    const p = pose.pose.pose.position;
    const [roll, pitch, yaw] = degrees(pose.pose.pose.orientation);
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
  const html = rows.join("") || `<tr><td colspan="12" class="note">no constellation identified</td></tr>`;
  $("poses").tBodies[0].innerHTML = html;
  state.poseReadout = $("poses").tBodies[0].textContent;
}

function renderAlerts() {
  const level = (l) => (l >= 2 ? "error" : "warning");
  $("alerts").innerHTML = alerts
    .map((a) => `<li class="${level(a.level)}">${new Date(stampSeconds(a.header) * 1000).toLocaleTimeString()} ${a.source}: ${a.text}</li>`)
    .join("");
}

function renderTopics() {
  const rows = [...topics.entries()].sort().map(([name, t]) =>
    `<tr><td>${name}</td><td>${t.type}</td><td>${t.rate === null ? "—" : t.rate.toFixed(1)}</td>
      <td>${t.bandwidth === null ? "—" : (t.bandwidth / 1000).toFixed(1)}</td></tr>`);
  $("topics").tBodies[0].innerHTML = rows.join("");
}

// Rates and bandwidth over the last second.
setInterval(() => {
  for (const t of topics.values()) {
    t.rate = t.count;
    t.bandwidth = t.bytes;
    t.count = 0;
    t.bytes = 0;
  }
  renderTopics();
  const volumeRates = [...topics.entries()].filter(([t]) => /^\/volume\/[^/]+\/image_raw$/.test(t))
    .map(([, t]) => t.rate ?? 0);
  const shown = volumeRates.length && !topics.has(IMAGE)
    ? `${volumeRates.length} cameras ${Math.min(...volumeRates)}–${Math.max(...volumeRates)} Hz shown`
    : `camera ${topics.get(IMAGE)?.rate ?? 0} Hz shown`;
  $("rates").textContent = state.connected
    ? `${shown} · poses ${topics.get(POSES)?.rate ?? 0} Hz · latency to bridge ${state.latencyMs === null ? "—" : state.latencyMs.toFixed(1) + " ms"}`
    : "";
}, 1000);

function frame() {
  if (dirty.camera && state.frameStamp) drawCamera();
  if (dirty.side) {
    drawTop();
    drawFloor();
  }
  if (dirty.volume) {
    drawVolumeCameras();
    drawVolumeTop();
  }
  dirty = { camera: false, side: false, volume: false };
  requestAnimationFrame(frame);
}

drawTop();
drawFloor();
connect();
requestAnimationFrame(frame);
