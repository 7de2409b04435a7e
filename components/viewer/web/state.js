// The viewer's state: what the graph said last, kept for each panel from the decoded messages
// of the channels topics.js chose, with which panels have news; draw.js and panels.js show it
// at the browser's next animation frame.
import { compose, yaw } from "./geometry.js";
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
// The 3D view's trails: each body's last seconds, a point every 1/30 s at most (a swarm's poses
// come 240 times a second: 100 trails of every pose would be most of a frame's lines).
const TRACK_S = 3;
const TRACK_STEP_S = 1 / 30;
// tf frames deeper than this under the world are not looked for (and a loop ends).
const TF_DEPTH = 16;

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
  // The 3D view (view3d.js): what its last frame drew.
  view3d: "",  // "drawn", or why not ("needs WebGL")
  view3dFrames: 0,
  view3dRenderer: "",  // WebGL's renderer
  view3dBuffer: [0, 0],  // the drawing buffer's size (pixels)
  view3dCanvas: [0, 0],  // the canvas's size on the page (CSS pixels)
  // Each frame's time (ms) from the start of its drawing until the GPU had drawn it: the last 1000.
  view3dDrawMs: [],
  view3dCamerasDrawn: 0,  // as frusta
  view3dCamerasByLevel: {},  // "OK", "WARN", "ERROR", "STALE" -> cameras drawn in its colour
  view3dBodiesDrawn: 0,  // with their axes (oriented)
  view3dRobotsDrawn: 0,  // single-marker robots, as points
  view3dMarkersDrawn: 0,  // points of the marker cloud
  view3dLabeledMarkers: 0,
  view3dTrailSegments: 0,
  view3dLabelsDrawn: 0,
  view3dLabelsHidden: 0,  // bodies' names left out: they would cover others
  view3dBodiesFrom: "",  // "/mocap/poses" or "/tf"
  view3dEye: null,  // {azimuthDeg, elevationDeg, distanceM, target}
  view3dSelected: "",  // the body whose figures are shown
  view3dFollowing: "",
  // Where the last frame put each camera and body: name -> [x, y], CSS pixels in the canvas.
  view3dScreen: { cameras: {}, bodies: {} },
  // The calibration coverage shown (/calibration/coverage): cameras, the session's progress
  // (0 to 1), sightings counted over every camera's regions, each camera's missing regions.
  coverageCameras: 0,
  coverageProgress: null,
  coverageViews: 0,
  coverageMissing: {},
  // The calibration's solve shown (/calibration/progress): its stage ("reading", "solving",
  // "writing", "done", "failed"), its share done (0 to 1) and what it says.
  solveStage: "",
  solveProgress: null,
  solveDetail: "",
  // Its report shown (/calibration/result), as the message has it (moved_mm and turned_deg null
  // for a camera whose file had no pose; off_mark_mm null for a single mark):
  // {frames_used, rms_px, points, iterations}, [{name, rms_px, shots, x, y, z, moved_mm,
  // turned_deg}], [{mark_x, mark_y, cameras, rms_px, off_mark_mm}], and the cameras drawn in its
  // picture of the volume from above.
  resultSummary: null,
  resultCameras: [],
  resultFloor: [],
  calibrationPictureDrawn: 0,
};

// The panels with news since the last animation frame.
export const dirty = {
  cameras: false, side: false, volume: false, poses: false, alerts: false, health: false, view3d: false,
  coverage: false, solve: false, result: false,
};

export const graph = {
  cameras: new Map(),  // image topic -> {name, image, frameStamp, dirty}, in topic order
  infos: new Map(),  // camera frame -> its latest camera_info
  poses: new Map(),  // topic of estimated poses -> its latest message
  tf: new Map(),  // child frame -> its latest transform, from every TFMessage topic
  trails: new Map(),  // board -> [{x, z}], seen from above in its camera's optical frame
  // body -> {x, y, yaw (null: none), trail: [{x, y}]} in the world frame; for the 3D view
  // also z, orientation (null: none), track: [{x, y, z, t}] (its last seconds, t in seconds of
  // the poses' stamps), pose (its latest ConstellationPose), latencyMs, count and rate.
  bodies: new Map(),
  // Frames that /tf moves under the world (a ROS 2 graph's bodies without /mocap/poses): frame ->
  // {x, y, z, orientation, track, updates}.
  tfBodies: new Map(),
  // The fusion's cameras' optical frames in its order (the order of its /tf_static message),
  // which the marker cloud's `cameras` bits follow.
  cameraOrder: [],
  markers: null,  // the newest marker cloud in the world frame (PointCloud2), read when drawn
  bases: new Map(),  // topic -> the pose of what stands on the floor
  robots: new Map(),  // topic -> its latest robots
  footprints: new Map(),  // topic -> its latest cameras' footprints
  turret: null,  // {pan, tilt} in radians
  alerts: [],  // the newest first
  health: new Map(),  // /diagnostics status name -> {status, receivedAt (page clock, ms)}
  coverage: null,  // the latest calibration coverage (volume_calibration_coverage)
  solve: null,  // the calibration's solve: its latest progress (volume_calibration_solve)
  result: null,  // and its report, once calibrated
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

// `frame`'s transform in the world frame through its parents, when tf joins it to the world.
export function worldTransform(frame) {
  let t = graph.tf.get(frame);
  if (!t) return undefined;
  let chained = t.transform;
  for (let depth = 0; t.header.frame_id !== WORLD; depth++) {
    t = graph.tf.get(t.header.frame_id);
    if (!t || depth === TF_DEPTH) return undefined;
    chained = compose(t.transform, chained);
  }
  return chained;
}

// A point of the 3D view's trail at `t` (s): one every TRACK_STEP_S, the last TRACK_S kept.
function addToTrack(track, p, t) {
  const last = track[track.length - 1];
  if (last && t - last.t < TRACK_STEP_S && t >= last.t) {
    // Newer than the step allows: the head moves, the trail keeps its spacing.
    last.x = p.x;
    last.y = p.y;
    last.z = p.z;
    return;
  }
  if (last && t < last.t) track.length = 0;  // time went back (a bag replayed): start again
  track.push({ x: p.x, y: p.y, z: p.z, t });
  while (track.length > 2 && track[1].t < t - TRACK_S) track.shift();
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

// A ConstellationPose in the world frame, of a message stamped `t` (s) that took `latencyMs`
// from capture to the bridge.
function addToVolume(constellationPose, t, latencyMs) {
  const { name, covariance } = constellationPose;
  const pose = constellationPose.pose.pose;
  const body = graph.bodies.get(name) ?? { trail: [], track: [], count: 0, rate: null };
  body.x = pose.position.x;
  body.y = pose.position.y;
  body.z = pose.position.z;
  const oriented = [21, 28, 35].some((i) => covariance[i] < UNKNOWN_ORIENTATION_VARIANCE);
  body.yaw = oriented ? yaw(pose.orientation) : null;
  body.orientation = oriented ? pose.orientation : null;
  body.pose = constellationPose;
  body.latencyMs = latencyMs;
  body.receivedAt = Date.now();
  body.count++;
  body.trail.push({ x: body.x, y: body.y });
  if (body.trail.length > TRAIL_LENGTH) body.trail.shift();
  addToTrack(body.track, pose.position, t);
  graph.bodies.set(name, body);
}

// The frames of a /tf message that move under the world, for the 3D view. A frame /tf sends
// more than once moves (/tf_static's come once); cameras' optical frames are cameras.
function addTfBodies(message) {
  for (const t of message.transforms) {
    const frame = t.child_frame_id;
    if (frame.endsWith("_optical")) continue;
    const world = worldTransform(frame);
    if (!world) continue;
    const body = graph.tfBodies.get(frame) ?? { track: [], updates: 0 };
    body.x = world.translation.x;
    body.y = world.translation.y;
    body.z = world.translation.z;
    body.orientation = world.rotation;
    body.updates++;
    addToTrack(body.track, world.translation, stampSeconds(t.header));
    graph.tfBodies.set(frame, body);
    if (body.updates > 1) dirty.view3d = true;
  }
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
      const t = stampSeconds(message.header);
      for (const pose of message.poses) addToVolume(pose, t, report.latencyMs);
      dirty.volume = true;
    } else {
      for (const pose of message.poses) addToTrail(pose.name, pose.pose.pose.position);
      dirty.side = true;
    }
  },
  [TYPES.tf](message) {
    const posesLately = Date.now() - posesAt < POSES_FRESH_MS;
    const cameras = message.transforms.filter((t) => t.header.frame_id === WORLD && t.child_frame_id.endsWith("_optical"));
    if (cameras.length > graph.cameraOrder.length) graph.cameraOrder = cameras.map((t) => t.child_frame_id);
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
    if (!posesLately) addTfBodies(message);
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
  [TYPES.coverage](message) {
    graph.coverage = message;
    dirty.coverage = true;
  },
  [TYPES.progress](message) {
    graph.solve = message;
    dirty.solve = true;
    // A solve starting, or one that failed: the report shown is an earlier solve's (the page
    // stays open from one to the next).
    if (graph.result && (message.stage === "reading" || message.stage === "failed")) {
      graph.result = null;
      dirty.result = true;
    }
  },
  [TYPES.result](message) {
    graph.result = message;
    dirty.result = true;
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
  for (const body of graph.bodies.values()) {
    body.rate = body.count;
    body.count = 0;
  }
}

// Whether estimated poses came lately: the 3D view then draws them, else /tf's frames.
export const posesFresh = () => Date.now() - posesAt < POSES_FRESH_MS;
