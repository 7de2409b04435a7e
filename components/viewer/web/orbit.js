// The 3D view's eye: it orbits a target point in the world frame (REP 103: z up), as the views of
// Motive, Vicon Tracker and QTM do, and gives the matrices WebGL draws with and the labels are
// placed with. Matrices are column-major Float32Arrays, as WebGL takes them.

const FIELD_OF_VIEW = (40 * Math.PI) / 180;  // vertical
const MIN_ELEVATION = (-80 * Math.PI) / 180;
const MAX_ELEVATION = (89 * Math.PI) / 180;
const MIN_DISTANCE_M = 0.3;
const MAX_DISTANCE_M = 200;
const RADIANS_PER_PIXEL = 0.008;

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => {
  const n = Math.hypot(a[0], a[1], a[2]) || 1;
  return [a[0] / n, a[1] / n, a[2] / n];
};

function multiply(a, b) {
  const out = new Float32Array(16);
  for (let column = 0; column < 4; column++) {
    for (let row = 0; row < 4; row++) {
      let sum = 0;
      for (let k = 0; k < 4; k++) sum += a[k * 4 + row] * b[column * 4 + k];
      out[column * 4 + row] = sum;
    }
  }
  return out;
}

export class Orbit {
  constructor() {
    this.target = [0, 0, 0.8];
    this.distance = 9;
    // From the south-west corner, a little above: x to the right, y away from the viewer.
    this.azimuth = (-62 * Math.PI) / 180;
    this.elevation = (30 * Math.PI) / 180;
    this.aspect = 16 / 9;
    this.viewProjection = new Float32Array(16);
    this.update();
  }

  // Where the eye is: `distance` from the target, `azimuth` around z from x, `elevation` above
  // the floor's plane.
  eye() {
    const c = Math.cos(this.elevation);
    return [
      this.target[0] + this.distance * c * Math.cos(this.azimuth),
      this.target[1] + this.distance * c * Math.sin(this.azimuth),
      this.target[2] + this.distance * Math.sin(this.elevation),
    ];
  }

  // The eye's right and up directions in the world.
  axes() {
    const forward = normalize(this.target.map((t, i) => t - this.eye()[i]));
    const right = normalize(cross(forward, [0, 0, 1]));
    return { forward, right, up: cross(right, forward) };
  }

  update() {
    const eye = this.eye();
    const { forward: f, right: r, up: u } = this.axes();
    const view = new Float32Array([
      r[0], u[0], -f[0], 0,
      r[1], u[1], -f[1], 0,
      r[2], u[2], -f[2], 0,
      -(r[0] * eye[0] + r[1] * eye[1] + r[2] * eye[2]),
      -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]),
      f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2], 1,
    ]);
    // Near and far follow the distance, so that depth keeps its precision close up and far out.
    const near = this.distance * 0.01;
    const far = this.distance * 10 + 20;
    const t = 1 / Math.tan(FIELD_OF_VIEW / 2);
    const projection = new Float32Array([
      t / this.aspect, 0, 0, 0,
      0, t, 0, 0,
      0, 0, (far + near) / (near - far), -1,
      0, 0, (2 * far * near) / (near - far), 0,
    ]);
    this.viewProjection = multiply(projection, view);
  }

  // A world point on a `width` x `height` view: {x, y} in pixels from the top left, with
  // `depth` (the clip w, metres along the view), or null behind the eye.
  project(p, width, height) {
    const m = this.viewProjection;
    const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
    if (w <= 1e-6) return null;
    const x = (m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12]) / w;
    const y = (m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13]) / w;
    return { x: ((x + 1) / 2) * width, y: ((1 - y) / 2) * height, depth: w };
  }

  // Left drag: turns the eye around the target.
  orbit(dx, dy) {
    this.azimuth -= dx * RADIANS_PER_PIXEL;
    this.elevation = Math.min(MAX_ELEVATION, Math.max(MIN_ELEVATION, this.elevation + dy * RADIANS_PER_PIXEL));
    this.update();
  }

  // Right or shift drag: moves the target with the pointer, in the view's plane, on a view
  // `height` pixels high.
  pan(dx, dy, height) {
    const metresPerPixel = (2 * this.distance * Math.tan(FIELD_OF_VIEW / 2)) / height;
    const { right, up } = this.axes();
    for (let i = 0; i < 3; i++) this.target[i] += (-dx * right[i] + dy * up[i]) * metresPerPixel;
    this.update();
  }

  // The wheel: a notch (100) brings the eye a tenth nearer or farther.
  zoom(delta) {
    this.distance = Math.min(MAX_DISTANCE_M, Math.max(MIN_DISTANCE_M, this.distance * Math.exp(delta * 0.001)));
    this.update();
  }

  // Looks at the box [min, max] (world points) whole.
  fit(min, max) {
    this.target = [(min[0] + max[0]) / 2, (min[1] + max[1]) / 2, Math.max(0, (min[2] + max[2]) / 2) * 0.6];
    const radius = Math.hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]) / 2;
    this.distance = Math.min(MAX_DISTANCE_M, Math.max(2, (radius / Math.sin(FIELD_OF_VIEW / 2)) * 0.95));
    this.update();
  }

  // What the test reads to see that the view moved.
  state() {
    return {
      azimuthDeg: (this.azimuth * 180) / Math.PI,
      elevationDeg: (this.elevation * 180) / Math.PI,
      distanceM: this.distance,
      target: [...this.target],
    };
  }
}
