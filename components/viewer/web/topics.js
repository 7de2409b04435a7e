// Which of the advertised channels the viewer reads: chosen by their schema names (message
// types), never by topic names, so that a launch file's remaps and another graph's names show
// as well as the defaults. Every channel is read, for its rate, except images, which are
// large: only the cameras' own are fetched. Where several topics share a type, their messages
// say what shows where (state.js): fiducials, constellations and poses go with the image of
// their header's frame and stamp, the poses' table takes the estimates, the floor what stands
// on it.

export const TYPES = {
  image: "sensor_msgs/msg/Image",
  cameraInfo: "sensor_msgs/msg/CameraInfo",
  fiducials: "mocap_msgs/msg/FiducialArray",
  constellations: "mocap_msgs/msg/ConstellationArray",
  poses: "mocap_msgs/msg/ConstellationPoseArray",
  tf: "tf2_msgs/msg/TFMessage",
  pose: "geometry_msgs/msg/PoseStamped",
  joints: "sensor_msgs/msg/JointState",
  robots: "mocap_msgs/msg/RobotPoseArray",
  footprints: "mocap_msgs/msg/CameraFootprintArray",
  alert: "mocap_msgs/msg/Alert",
  markers: "sensor_msgs/msg/PointCloud2",
  diagnostics: "diagnostic_msgs/msg/DiagnosticArray",
  coverage: "mocap_msgs/msg/CalibrationCoverage",
  progress: "mocap_msgs/msg/CalibrationProgress",
  result: "mocap_msgs/msg/VolumeCalibrationResult",
};

const namespace = (topic) => topic.slice(0, topic.lastIndexOf("/"));

// What a topic is about, in labels: its namespace's last name ("/volume/cam_0/image_raw":
// "cam_0"), else the topic.
export const subject = (topic) => namespace(topic).split("/").pop() || topic;

// A camera publishes its image and its CameraInfo side by side (image_transport's rule), so
// the images with a CameraInfo in their namespace are cameras'; the others, such as an overlay
// drawn on a camera's image, are not fetched. When no image has one (a camera that sends no
// calibration), every image is a camera's. Returns {cameras: their image topics in order,
// subscribed: the ids of every channel to read}.
export function choose(channels) {
  const all = [...channels.values()];
  const calibrated = new Set(all.filter((c) => c.schemaName === TYPES.cameraInfo).map((c) => namespace(c.topic)));
  const images = all.filter((c) => c.schemaName === TYPES.image);
  const withInfo = images.filter((c) => calibrated.has(namespace(c.topic)));
  const cameras = withInfo.length ? withInfo : images;
  const subscribed = new Set(all.filter((c) => c.schemaName !== TYPES.image || cameras.includes(c)).map((c) => c.id));
  return { cameras: cameras.map((c) => c.topic).sort(), subscribed };
}
