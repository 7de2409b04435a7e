// The viewer's state: what the graph said last, kept for each panel from the decoded messages
// of the channels topics.js chose, with which panels have news; draw.js and panels.js show it
// at the browser's next animation frame.
import { yaw } from "./geometry.js";
import { TYPES, subject } from "./topics.js";

const WORLD = "world";
// While estimated poses come, the boards of /tf are not drawn twice.
const POSES_FRESH_MS = 2000;
// A mobile base's pose is at its wheels; a camera's, a board's held up are higher.
const FLOOR_M = 0.2;
const TRAIL_LENGTH = 150;
const STAMPS_KEPT = 60;  // per frame: the last few images' fiducials, constellations, poses
// A pose's orientation variance (rad^2) from which it has none: a robot of one marker carries
// 1e9 (components/outputs/body_frames/body_frames.hpp).
const UNKNOWN_ORIENTATION_VARIANCE = 1e6;

// What was drawn: window.viewerState.
export const report = {
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
  transformsUsed: 0,  // /tf transforms drawn there, when no estimated poses come
  poseReadout: "",
  latencyMs: null,
  // Each drawn image's age when drawn (ms, page clock minus capture stamp): the last 1000.
  drawLatenciesMs: [],
  volumeImagesDrawn: {},  // camera -> images drawn
  volumeCirclesDrawn: {},  // camera -> circles drawn on its last image
  volumeConesDrawn: 0,  // cameras drawn from above with their view
  volumeCamerasDrawn: 0,  // cameras drawn from above, with their view or (no images) from /tf
  volumeBodiesDrawn: 0,  // bodies and robots drawn from above
  volumeMarkersDrawn: 0,  // points of the marker cloud drawn from above
  healthRows: {},  // status name -> its level as shown ("OK", "WARN", "ERROR", "STALE")
};

// The panels with news since the last animation frame.
export const dirty = { cameras: false, side: false, volume: false, poses: false, alerts: false, health: false };

export const graph = {
  cameras: new Map(),  // image topic -> {name, image, frameStamp, dirty}, in topic order
  infos: new Map(),  // camera frame -> its latest camera_info
  poses: new Map(),  // topic of estimated poses -> its latest message
  tf: new Map(),  // child frame -> its latest transform, from every TFMessage topic
  trails: new Map(),  // board -> [{x, z}], seen from above in its camera's optical frame
  bodies: new Map(),  // body -> {x, y, yaw (null: none), trail: [{x, y}]} in the world frame
  markers: null,  // the newest marker cloud in the world frame (PointCloud2), read when drawn
  bases: new Map(),  // topic -> the pose of what stands on the floor
  robots: new Map(),  // topic -> its latest robots
  footprints: new Map(),  // topic -> its latest cameras' footprints
  turret: null,  // {pan, tilt} in radians
  alerts: [],  // the newest first
  health: new Map(),  // /diagnostics status name -> {status, receivedAt (page clock, ms)}
  topics: new Map(),  // every advertised topic -> {type, count, bytes, rate, bandwidth}
};

// fiducials, constellations, poses: frame -> stamp -> what was found in that image.
const recent = { fiducials: new Map(), constellations: new Map(), poses: new Map() };
const estimating = new Set();  // topics whose poses are estimates
let posesAt = 0;  // page time of the last estimated poses

export const stampKey = (header) => `${header.stamp.sec}.${String(header.stamp.nanosec).padStart(9, "0")}`;
export const stampSeconds = (header) => header.stamp.sec + header.stamp.nanosec * 1e-9;

// What was found (`kind`: fiducials, constellations, poses) in the image of `header`;
// undefined when it has not come (yet).
export const foundIn = (kind, header) => recent[kind].get(header.frame_id)?.get(stampKey(header));

// `frame`'s transform in the world frame, when tf has it as the world's child.
export function inWorld(frame) {
  const t = graph.tf.get(frame);
  return t?.header.frame_id === WORLD ? t.transform : undefined;
}

function remember(kind, header, value) {
  const byStamp = recent[kind].get(header.frame_id) ?? new Map();
  byStamp.set(stampKey(header), value);
  while (byStamp.size > STAMPS_KEPT) byStamp.delete(byStamp.keys().next().value);
  recent[kind].set(header.frame_id, byStamp);
  // A camera publishes its image before the tracker has found anything in it: what belongs to
  // the image on show may come after it was drawn.
  for (const camera of graph.cameras.values()) {
    if (camera.image?.header.frame_id !== header.frame_id || camera.frameStamp !== stampKey(header)) continue;
    camera.dirty = true;
    dirty.cameras = true;
  }
}

function addToTrail(name, position) {
  const trail = graph.trails.get(name) ?? [];
  trail.push({ x: position.x, z: position.z });
  if (trail.length > TRAIL_LENGTH) trail.shift();
  graph.trails.set(name, trail);
}

// `pose` in the world frame, with its covariance (ConstellationPose.msg).
function addToVolume(name, pose, covariance) {
  const body = graph.bodies.get(name) ?? { trail: [] };
  body.x = pose.position.x;
  body.y = pose.position.y;
  const oriented = [21, 28, 35].some((i) => covariance[i] < UNKNOWN_ORIENTATION_VARIANCE);
  body.yaw = oriented ? yaw(pose.orientation) : null;
  body.trail.push({ x: body.x, y: body.y });
  if (body.trail.length > TRAIL_LENGTH) body.trail.shift();
  graph.bodies.set(name, body);
}

const handlers = {
  [TYPES.image](image, topic) {
    const camera = graph.cameras.get(topic);
    if (!camera) return;
    camera.image = image;
    camera.frameStamp = stampKey(image.header);
    camera.dirty = true;
    dirty.cameras = true;
  },
  [TYPES.cameraInfo](info) {
    // A camera's first: its view can be drawn from above.
    if (!graph.infos.has(info.header.frame_id)) dirty.volume = true;
    graph.infos.set(info.header.frame_id, info);
  },
  [TYPES.fiducials](message) {
    remember("fiducials", message.header, message.fiducials);
  },
  [TYPES.constellations](message) {
    remember("constellations", message.header, message.constellations);
  },
  [TYPES.poses](message, topic, receivedMs) {
    // Ground truth's poses rest on no camera (cameras_used 0, ConstellationPose.msg): a topic's
    // poses are shown once one of them rests on some.
    if (!estimating.has(topic)) {
      if (!message.poses.some((pose) => pose.cameras_used !== 0)) return;
      estimating.add(topic);
    }
    graph.poses.set(topic, message);
    remember("poses", message.header, message.poses);
    dirty.poses = true;
    // Capture to bridge, both on the graph's clocks: the page's Date.now() would add the
    // difference between this machine's clock and the graph's.
    report.latencyMs = receivedMs - stampSeconds(message.header) * 1000;
    posesAt = Date.now();
    if (message.header.frame_id === WORLD) {
      // A volume's bodies.
      for (const pose of message.poses) addToVolume(pose.name, pose.pose.pose, pose.covariance);
      dirty.volume = true;
    } else {
      for (const pose of message.poses) addToTrail(pose.name, pose.pose.pose.position);
      dirty.side = true;
    }
  },
  [TYPES.tf](message) {
    const posesLately = Date.now() - posesAt < POSES_FRESH_MS;
    for (const t of message.transforms) {
      graph.tf.set(t.child_frame_id, t);
      // Where a volume's cameras are (volume_fusion latches them).
      if (t.header.frame_id === WORLD) dirty.volume = true;
      // The boards as tf2 has them (pose_outputs, or any ROS 2 graph's /tf), drawn when no
      // estimated poses come: those whose parent is a camera's optical frame.
      if (posesLately || !t.header.frame_id.endsWith("_optical")) continue;
      addToTrail(t.child_frame_id, t.transform.translation);
      report.transformsUsed++;
      dirty.side = true;
    }
  },
  // What stands on the floor, such as a mobile base: a pose in the world frame at its ground.
  [TYPES.pose](message, topic) {
    const onFloor = message.header.frame_id === WORLD && Math.abs(message.pose.position.z) < FLOOR_M;
    if (onFloor) graph.bases.set(topic, message.pose);
    else if (!graph.bases.delete(topic)) return;  // nor was it before
    dirty.side = true;
  },
  // The turret's joints as they last came, measured or commanded.
  [TYPES.joints](message) {
    const joint = (name, index) => {
      const i = message.name.indexOf(name);
      return message.position[i >= 0 ? i : index];
    };
    graph.turret = { pan: joint("pan", 0), tilt: joint("tilt", 1) };
    dirty.side = true;
  },
  [TYPES.robots](message, topic) {
    graph.robots.set(topic, message.robots);
    dirty.side = true;
  },
  [TYPES.footprints](message, topic) {
    graph.footprints.set(topic, message.cameras);
    dirty.side = true;
  },
  // A volume's marker cloud (volume_fusion's /mocap/markers, or any PointCloud2 in the world
  // frame): the newest, drawn from above (its points read then, not at each of 240 a second).
  [TYPES.markers](message) {
    if (message.header.frame_id !== WORLD) return;
    graph.markers = message;
    dirty.volume = true;
  },
  // Every process's statuses, once a second each (diagnostic_msgs, as ROS 2 publishes them).
  [TYPES.diagnostics](message) {
    for (const status of message.status) graph.health.set(status.name, { status, receivedAt: Date.now() });
    dirty.health = true;
  },
  [TYPES.alert](alert) {
    graph.alerts.unshift(alert);
    graph.alerts.length = Math.min(graph.alerts.length, 8);
    dirty.alerts = true;
  },
};

// A decoded message of `channel`, which the bridge received at `receivedMs` (graph's clock).
export function receive(channel, message, receivedMs) {
  handlers[channel.schemaName]?.(message, channel.topic, receivedMs);
}

// The cameras topics.js chose; those already shown keep their last image.
export function setCameras(topics) {
  const empty = (topic) => ({ name: subject(topic), image: null, frameStamp: null, dirty: false });
  graph.cameras = new Map(topics.map((topic) => [topic, graph.cameras.get(topic) ?? empty(topic)]));
  dirty.cameras = true;
}

// The topics the bridge offers now, for their rates; those it offered before keep counting.
export function advertised(channels) {
  const types = new Map([...channels.values()].map((c) => [c.topic, c.schemaName]));
  for (const topic of graph.topics.keys()) {
    if (!types.has(topic)) graph.topics.delete(topic);
  }
  for (const [topic, type] of types) {
    if (!graph.topics.has(topic)) graph.topics.set(topic, { type, count: 0, bytes: 0, rate: null, bandwidth: null });
  }
}

export function counted(topic, bytes) {
  const t = graph.topics.get(topic);
  if (!t) return;
  t.count++;
  t.bytes += bytes;
}

// Rates and bandwidth over the last second.
export function rollRates() {
  for (const t of graph.topics.values()) {
    t.rate = t.count;
    t.bandwidth = t.bytes;
    t.count = 0;
    t.bytes = 0;
  }
}
