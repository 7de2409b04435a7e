// Rotations as ROS writes them (quaternions {x, y, z, w}) and camera_info's pinhole camera, for
// drawing poses, frames and cameras' views.

export function rotate(q, v) {
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

export const yaw = (q) => Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));

export function rollPitchYaw(q) {
  const roll = Math.atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x * q.x + q.y * q.y));
  const pitch = Math.asin(Math.max(-1, Math.min(1, 2 * (q.w * q.y - q.z * q.x))));
  return [roll, pitch, yaw(q)];
}

// A camera-frame point into the image with camera_info's pinhole and plumb_bob distortion;
// null behind the camera.
export function project(info, p) {
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

// Half the camera's horizontal field of view.
export const halfView = (info) => Math.atan(info.width / 2 / info.k[0]);

// The rotation a then b applied to a vector: a * b.
export function multiply(a, b) {
  return {
    w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
    x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
    y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
    z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
  };
}

// tf's transform `outer` after `inner` ({translation, rotation}): parent_from_child chained.
export function compose(outer, inner) {
  const r = rotate(outer.rotation, inner.translation);
  return {
    translation: { x: outer.translation.x + r.x, y: outer.translation.y + r.y, z: outer.translation.z + r.z },
    rotation: multiply(outer.rotation, inner.rotation),
  };
}
