// The 3D view's WebGL drawing (view3d.js): lines of any width, round points and translucent
// triangles in world coordinates, each kind gathered into one vertex array and drawn with one
// call. Our own rather than a library's: four primitives are all the view needs, the
// page loads nothing the bridge does not compile in, and a frame costs what is uploaded and
// drawn here, which the test measures. WebGL 1, so that any browser with WebGL draws it.

// Triangles: a position and a colour.
const PLAIN_VERTEX = `
attribute vec3 position;
attribute vec4 colour;
uniform mat4 viewProjection;
varying vec4 vColour;
void main() {
  gl_Position = viewProjection * vec4(position, 1.0);
  vColour = colour;
}`;

const PLAIN_FRAGMENT = `
precision mediump float;
varying vec4 vColour;
void main() { gl_FragColor = vColour; }`;

// Browsers draw GL lines one pixel wide whatever lineWidth says (ANGLE's limit), and without
// multisampling (which doubles a frame's time in a software renderer) with jagged edges: every
// line is a quad, its two ends projected and pushed apart on screen by half its width and a
// pixel each side, its edges faded over that pixel. An end behind the eye is first moved along
// the segment to just in front of it, so that a segment crossing the eye's plane still draws
// its visible part.
const WIDE_VERTEX = `
attribute vec3 from;
attribute vec3 to;
attribute vec2 corner;  // x: 0 at from, 1 at to; y: -1 or 1, the side
attribute vec4 colour;
attribute float width;  // pixels
uniform mat4 viewProjection;
uniform vec2 viewport;  // half the drawing buffer, pixels
varying vec4 vColour;
varying float vAcross;  // pixels from the line's middle
varying float vHalf;  // half the width
void main() {
  vec4 a = viewProjection * vec4(from, 1.0);
  vec4 b = viewProjection * vec4(to, 1.0);
  const float near = 1e-4;
  if (a.w < near && b.w < near) {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // behind the eye: outside the clip volume
    return;
  }
  if (a.w < near) a = mix(a, b, (near - a.w) / (b.w - a.w));
  if (b.w < near) b = mix(b, a, (near - b.w) / (a.w - b.w));
  vec2 along = b.xy / b.w * viewport - a.xy / a.w * viewport;
  along = length(along) > 1e-6 ? normalize(along) : vec2(1.0, 0.0);
  vec2 across = vec2(-along.y, along.x);
  vec4 end = corner.x < 0.5 ? a : b;
  float halfWidth = width * 0.5;
  // Half a width past each end as well, so that a trail's segments meet without notches.
  vec2 push = across * corner.y * (halfWidth + 1.0) + along * (corner.x < 0.5 ? -halfWidth : halfWidth);
  gl_Position = vec4(end.xy + push / viewport * end.w, end.z, end.w);
  vColour = colour;
  vAcross = corner.y * (halfWidth + 1.0);
  vHalf = halfWidth;
}`;

const WIDE_FRAGMENT = `
precision mediump float;
varying vec4 vColour;
varying float vAcross;
varying float vHalf;
void main() {
  float cover = clamp(vHalf + 0.5 - abs(vAcross), 0.0, 1.0);
  gl_FragColor = vec4(vColour.rgb, vColour.a * cover);
}`;

// Round points with a darker rim, so that a marker stands out on a line of its colour, their
// edge faded over a pixel.
const POINT_VERTEX = `
attribute vec3 position;
attribute vec4 colour;
attribute float size;  // pixels
uniform mat4 viewProjection;
varying vec4 vColour;
varying float vSize;
void main() {
  gl_Position = viewProjection * vec4(position, 1.0);
  gl_PointSize = size + 2.0;
  vColour = colour;
  vSize = size + 2.0;
}`;

const POINT_FRAGMENT = `
precision mediump float;
varying vec4 vColour;
varying float vSize;
void main() {
  float r = length(gl_PointCoord - vec2(0.5)) * vSize;  // pixels from the middle
  float radius = vSize * 0.5 - 1.0;
  float cover = clamp(radius + 0.5 - r, 0.0, 1.0);
  if (cover <= 0.0) discard;
  float rim = smoothstep(radius - 2.5, radius - 1.0, r);
  gl_FragColor = vec4(mix(vColour.rgb, vColour.rgb * 0.3, rim), vColour.a * cover);
}`;

const PLAIN_LAYOUT = [["position", 3], ["colour", 4]];
const WIDE_LAYOUT = [["from", 3], ["to", 3], ["corner", 2], ["colour", 4], ["width", 1]];
const POINT_LAYOUT = [["position", 3], ["colour", 4], ["size", 1]];
const WIDE_CORNERS = [[0, -1], [1, -1], [1, 1], [0, -1], [1, 1], [0, 1]];

function compile(gl, vertexSource, fragmentSource) {
  const program = gl.createProgram();
  for (const [type, source] of [[gl.VERTEX_SHADER, vertexSource], [gl.FRAGMENT_SHADER, fragmentSource]]) {
    const shader = gl.createShader(type);
    gl.shaderSource(shader, source);
    gl.compileShader(shader);
    if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(shader)}`);
    gl.attachShader(program, shader);
  }
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(`program: ${gl.getProgramInfoLog(program)}`);
  return program;
}

// Vertices of one kind, gathered on the CPU each frame into an array that only grows, and
// sent into one GPU buffer that only grows: after the first frames neither is allocated again.
class Batch {
  constructor(gl, program, layout, mode) {
    this.gl = gl;
    this.program = program;
    this.mode = mode;
    this.stride = layout.reduce((sum, [, n]) => sum + n, 0);
    let offset = 0;
    this.attributes = layout.map(([name, n]) => {
      const attribute = { location: gl.getAttribLocation(program, name), size: n, offset: offset * 4 };
      offset += n;
      return attribute;
    });
    this.data = new Float32Array(this.stride * 1024);
    this.length = 0;  // floats used
    this.buffer = gl.createBuffer();
    this.bufferFloats = 0;
  }

  get vertices() {
    return this.length / this.stride;
  }

  clear() {
    this.length = 0;
  }

  // Room for `floats` more.
  reserve(floats) {
    if (this.length + floats <= this.data.length) return;
    let size = this.data.length * 2;
    while (size < this.length + floats) size *= 2;
    const grown = new Float32Array(size);
    grown.set(this.data.subarray(0, this.length));
    this.data = grown;
  }

  draw(uniforms) {
    if (!this.length) return;
    const gl = this.gl;
    gl.useProgram(this.program);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.buffer);
    if (this.length > this.bufferFloats) {
      this.bufferFloats = this.data.length;
      gl.bufferData(gl.ARRAY_BUFFER, this.data.byteLength, gl.DYNAMIC_DRAW);
    }
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, this.data.subarray(0, this.length));
    for (const a of this.attributes) {
      gl.enableVertexAttribArray(a.location);
      gl.vertexAttribPointer(a.location, a.size, gl.FLOAT, false, this.stride * 4, a.offset);
    }
    uniforms(this.program);
    gl.drawArrays(this.mode, 0, this.vertices);
    for (const a of this.attributes) gl.disableVertexAttribArray(a.location);
  }
}

// A renderer on `canvas`, or null when the browser gives no WebGL. Colours are [r, g, b, a]
// in 0..1; positions are world coordinates (metres).
export function createRenderer(canvas) {
  // No depth buffer: the scene is lines and points, drawn in the order given (faces, then lines,
  // then points), which fading edges need anyway; no multisampling (see WIDE_VERTEX).
  const gl = canvas.getContext("webgl", { antialias: false, alpha: false, depth: false });
  if (!gl) return null;
  const plain = compile(gl, PLAIN_VERTEX, PLAIN_FRAGMENT);
  const wide = compile(gl, WIDE_VERTEX, WIDE_FRAGMENT);
  const round = compile(gl, POINT_VERTEX, POINT_FRAGMENT);
  const batches = {
    triangles: new Batch(gl, plain, PLAIN_LAYOUT, gl.TRIANGLES),
    lines: new Batch(gl, wide, WIDE_LAYOUT, gl.TRIANGLES),
    points: new Batch(gl, round, POINT_LAYOUT, gl.POINTS),
  };
  const { lines, triangles, points } = batches;
  const locations = new Map();
  const uniform = (program, name) => {
    const key = `${name}@${[plain, wide, round].indexOf(program)}`;
    if (!locations.has(key)) locations.set(key, gl.getUniformLocation(program, name));
    return locations.get(key);
  };

  // Writes straight into the batch's array: a frame of a swarm adds tens of thousands of
  // vertices, and temporary arrays for each would keep the collector busy.
  const vertex = (batch, p, c) => {
    const d = batch.data;
    let i = batch.length;
    d[i++] = p[0];
    d[i++] = p[1];
    d[i++] = p[2];
    d[i++] = c[0];
    d[i++] = c[1];
    d[i++] = c[2];
    d[i++] = c[3];
    batch.length = i;
  };

  return {
    gl,
    batches,
    clear() {
      for (const batch of Object.values(batches)) batch.clear();
    },
    // A line `width` pixels wide from a to b ([x, y, z]), coloured from `ca` at a to `cb` at b.
    line(a, b, ca, cb = ca, width = 1) {
      lines.reserve(6 * 13);
      const d = lines.data;
      let i = lines.length;
      for (const [along, side] of WIDE_CORNERS) {
        const c = along ? cb : ca;
        d[i++] = a[0];
        d[i++] = a[1];
        d[i++] = a[2];
        d[i++] = b[0];
        d[i++] = b[1];
        d[i++] = b[2];
        d[i++] = along;
        d[i++] = side;
        d[i++] = c[0];
        d[i++] = c[1];
        d[i++] = c[2];
        d[i++] = c[3];
        d[i++] = width;
      }
      lines.length = i;
    },
    // A round point `size` pixels across.
    point(p, c, size) {
      points.reserve(8);
      vertex(points, p, c);
      points.data[points.length++] = size;
    },
    triangle(a, b, d, c) {
      triangles.reserve(21);
      vertex(triangles, a, c);
      vertex(triangles, b, c);
      vertex(triangles, d, c);
    },
    // Everything gathered since clear(), with `viewProjection` (column-major, 16 numbers) on a
    // drawing buffer `width` x `height`, over `background`.
    draw(viewProjection, width, height, background) {
      gl.viewport(0, 0, width, height);
      gl.clearColor(background[0], background[1], background[2], 1);
      gl.clear(gl.COLOR_BUFFER_BIT);
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      const matrix = (program) => gl.uniformMatrix4fv(uniform(program, "viewProjection"), false, viewProjection);
      triangles.draw(matrix);
      lines.draw((program) => {
        matrix(program);
        gl.uniform2f(uniform(program, "viewport"), width / 2, height / 2);
      });
      points.draw(matrix);
    },
    // Blocks until the GPU has drawn the frame: reads one pixel back.
    finish() {
      const pixel = new Uint8Array(4);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    },
    // The drawing buffer's pixels in a square of `radius` around (x, y) (buffer pixels, y
    // down) that differ from `background` by more than `tolerance` (0..255) in any channel;
    // read right after a draw, before the browser shows and clears the buffer.
    countDrawn(x, y, radius, background, tolerance = 24) {
      const x0 = Math.max(0, Math.round(x - radius));
      const y0 = Math.max(0, Math.round(gl.drawingBufferHeight - y - radius));
      const w = Math.min(gl.drawingBufferWidth - x0, 2 * radius + 1);
      const h = Math.min(gl.drawingBufferHeight - y0, 2 * radius + 1);
      if (w <= 0 || h <= 0) return { drawn: 0, total: 0 };
      const pixels = new Uint8Array(w * h * 4);
      gl.readPixels(x0, y0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
      const bg = background.map((v) => v * 255);
      let drawn = 0;
      for (let i = 0; i < pixels.length; i += 4) {
        if (Math.abs(pixels[i] - bg[0]) > tolerance || Math.abs(pixels[i + 1] - bg[1]) > tolerance ||
            Math.abs(pixels[i + 2] - bg[2]) > tolerance) drawn++;
      }
      return { drawn, total: w * h };
    },
  };
}
