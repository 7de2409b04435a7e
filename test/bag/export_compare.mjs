// A recording and its exports compared value by value: the bag's /mocap/poses and /mocap/markers
// read by @mcap/core and decoded by Foxglove's ros2idl parser and CDR reader (not our bag code),
// each export read by the reader written from its format's description (c3d_read.mjs,
// trc_read.mjs, motive_csv_read.mjs, tum_read.mjs). Every pose and marker of the bag must be in
// every export at its frame, to 1 µm (text) or to the float (C3D: one unit in the last place of
// its millimetres), each in the axes its format takes (C3D and TUM z up, TRC and CSV y up), and
// every other cell a gap. Bodies as C3D and TRC carry them: four points, the origin and the axis
// ends 0.1 m out.
//
//   node export_compare.mjs BAG.mcap BODY_NAMES EXPORT_PREFIX
//
// BODY_NAMES: the fusion's bodies then robots, comma-separated (a cloud's `body` indexes them);
// EXPORT_PREFIX: the exports are EXPORT_PREFIX.c3d, .trc, .csv and the folder EXPORT_PREFIX_tum.
// Prints a table (format, frames, values compared, largest difference, gaps) and exits 1 on the
// first disagreement, naming it.
import fs from "node:fs";
import path from "node:path";
import { execFileSync } from "node:child_process";
import { McapStreamReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import ros2idl from "@foxglove/ros2idl-parser";
import rosmsg2 from "@foxglove/rosmsg2-serialization";

const [bagFile, bodyList, prefix] = process.argv.slice(2);
const bodyNames = bodyList.split(",");
const here = path.dirname(new URL(import.meta.url).pathname);
const fail = (message) => {
  console.error(`export_compare: ${message}`);
  process.exit(1);
};

// ---- the bag ----
await zstd.isLoaded;
await lz4.isLoaded;
const reader = new McapStreamReader({
  decompressHandlers: {
    zstd: (buffer, size) => new Uint8Array(zstd.decompress(buffer, Number(size))),
    lz4: (buffer, size) => new Uint8Array(lz4(buffer, Number(size))),
  },
});
reader.append(new Uint8Array(fs.readFileSync(bagFile)));
const schemas = new Map(), channels = new Map(), decoders = new Map();
const stampOf = (header) => BigInt(header.stamp.sec) * 1000000000n + BigInt(header.stamp.nanosec ?? header.stamp.nsec);
const frames = new Map();  // stamp (BigInt) -> {poses: Map name -> {p, q}, markers: Map name -> [x,y,z]}
const frameAt = (stamp) => {
  if (!frames.has(stamp)) frames.set(stamp, { poses: new Map(), markers: new Map() });
  return frames.get(stamp);
};
for (let record; (record = reader.nextRecord()); ) {
  if (record.type === "Schema") schemas.set(record.id, record);
  if (record.type === "Channel") channels.set(record.id, record);
  if (record.type !== "Message") continue;
  const channel = channels.get(record.channelId);
  if (channel.topic !== "/mocap/poses" && channel.topic !== "/mocap/markers") continue;
  if (!decoders.has(channel.id)) {
    const schema = schemas.get(channel.schemaId);
    decoders.set(channel.id, new rosmsg2.MessageReader(ros2idl.parseRos2idl(new TextDecoder().decode(schema.data))));
  }
  const message = decoders.get(channel.id).readMessage(record.data);
  const frame = frameAt(stampOf(message.header));
  if (channel.topic === "/mocap/poses") {
    for (const pose of message.poses) {
      const { position: p, orientation: q } = pose.pose.pose;
      const norm = Math.hypot(q.x, q.y, q.z, q.w);
      if (!(norm >= 1e-6) || ![p.x, p.y, p.z].every(Number.isFinite)) continue;  // no pose
      frame.poses.set(pose.name, { p: [p.x, p.y, p.z], q: [q.x / norm, q.y / norm, q.z / norm, q.w / norm] });
    }
    continue;
  }
  // PointCloud2: fields by name, little-endian.
  const field = Object.fromEntries(message.fields.map((f) => [f.name, f.offset]));
  const view = new DataView(message.data.buffer, message.data.byteOffset, message.data.byteLength);
  for (let i = 0; i < message.width * message.height; ++i) {
    const at = i * message.point_step;
    const xyz = ["x", "y", "z"].map((n) => view.getFloat32(at + field[n], true));
    const body = view.getInt32(at + field.body, true);
    const name = body >= 0
      ? `${bodyNames[body] ?? `body${body}`}_${view.getUint16(at + field.marker, true) + 1}`
      : `unlabeled_${view.getUint32(at + field.id, true)}`;
    frame.markers.set(name, xyz);
  }
}
const stamps = [...frames.keys()].sort((a, b) => (a < b ? -1 : a > b ? 1 : 0));
if (stamps.length === 0) fail(`${bagFile}: no /mocap/poses or /mocap/markers`);

// ---- what each export must hold ----
const rotate = ([x, y, z, w], v) => {
  // v rotated by the unit quaternion (x, y, z, w)
  const [vx, vy, vz] = v;
  const tx = 2 * (y * vz - z * vy), ty = 2 * (z * vx - x * vz), tz = 2 * (x * vy - y * vx);
  return [vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx)];
};
// Every point of a frame: the markers, and each body's origin and axis ends.
const pointsOf = (frame) => {
  const points = new Map(frame.markers);
  for (const [name, { p, q }] of frame.poses) {
    for (const [suffix, v] of [["origin", [0, 0, 0]], ["x", [0.1, 0, 0]], ["y", [0, 0.1, 0]], ["z", [0, 0, 0.1]]]) {
      const r = rotate(q, v);
      points.set(`${name}_${suffix}`, [p[0] + r[0], p[1] + r[1], p[2] + r[2]]);
    }
  }
  return points;
};
const yUp = ([x, y, z]) => [x, z, -y];
const read = (script, file) =>
  JSON.parse(execFileSync("node", [path.join(here, script), file], { maxBuffer: 1 << 30 }).toString());

const table = [];
function compare(format, check) {
  const tally = { format, frames: 0, values: 0, largest: 0, gaps: 0 };
  check(tally, (what, got, expected, bound) => {
    const difference = Math.abs(got - expected);
    if (!(difference <= bound)) fail(`${format}: ${what}: ${got}, the bag's ${expected} (bound ${bound})`);
    tally.values += 1;
    tally.largest = Math.max(tally.largest, difference);
  });
  table.push(tally);
}
const floatUlp = (v) => {
  const f = Math.fround(Math.abs(v));
  const bits = new Float32Array([f]), next = new Uint32Array(bits.buffer);
  next[0] += 1;
  return bits[0] - f;
};
const allNames = new Set();
for (const stamp of stamps) for (const name of pointsOf(frames.get(stamp)).keys()) allNames.add(name);

compare("c3d", (tally, same) => {
  const c3d = read("c3d_read.mjs", `${prefix}.c3d`);
  if (c3d.frames.length !== stamps.length) fail(`c3d: ${c3d.frames.length} frames, the bag ${stamps.length}`);
  if (c3d.units !== "mm") fail(`c3d: units ${c3d.units}`);
  const missing = [...allNames].filter((n) => !c3d.labels.includes(n));
  if (missing.length) fail(`c3d: no point ${missing[0]}`);
  stamps.forEach((stamp, f) => {
    const points = pointsOf(frames.get(stamp));
    tally.frames += 1;
    c3d.labels.forEach((label, i) => {
      const got = c3d.frames[f][i], expected = points.get(label);
      if (!expected) {
        if (got !== null) fail(`c3d: ${label} at frame ${f + 1}: a value where the bag has none`);
        tally.gaps += 1;
        return;
      }
      if (got === null) fail(`c3d: ${label} at frame ${f + 1}: a gap where the bag has it`);
      for (let a = 0; a < 3; ++a) same(`${label} frame ${f + 1} axis ${a}`, got[a], 1000 * expected[a], floatUlp(1000 * expected[a]));
    });
  });
});

compare("trc", (tally, same) => {
  const trc = read("trc_read.mjs", `${prefix}.trc`);
  if (trc.rows.length !== stamps.length) fail(`trc: ${trc.rows.length} rows, the bag ${stamps.length}`);
  const missing = [...allNames].filter((n) => !trc.markers.includes(n));
  if (missing.length) fail(`trc: no marker ${missing[0]}`);
  stamps.forEach((stamp, f) => {
    const points = pointsOf(frames.get(stamp));
    const row = trc.rows[f];
    tally.frames += 1;
    same(`time of frame ${f + 1}`, Number(row.time), Number(stamp - stamps[0]) * 1e-9, 1e-9);
    for (const name of trc.markers) {
      const got = row.points[name], expected = points.get(name);
      if (!expected) {
        if (got !== null) fail(`trc: ${name} at frame ${f + 1}: a value where the bag has none`);
        tally.gaps += 1;
        continue;
      }
      if (got === null) fail(`trc: ${name} at frame ${f + 1}: a gap where the bag has it`);
      const e = yUp(expected);
      for (let a = 0; a < 3; ++a) same(`${name} frame ${f + 1} axis ${a}`, got[a], e[a], 1e-6);
    }
  });
});

compare("csv", (tally, same) => {
  const csv = read("motive_csv_read.mjs", `${prefix}.csv`);
  if (csv.frames !== stamps.length) fail(`csv: ${csv.frames} rows, the bag ${stamps.length}`);
  // Motive's Y up: a turn of -90 degrees about x, q' = (-sin 45°, 0, 0, cos 45°) q.
  const s = Math.SQRT1_2;
  const turn = ([x, y, z, w]) => {
    const q = [s * x - s * w, s * y + s * z, s * z - s * y, s * w + s * x];
    return q[3] < 0 ? q.map((v) => -v) : q;
  };
  const markerName = (name) => {
    const cut = name.lastIndexOf("_"), body = name.slice(0, cut), number = name.slice(cut + 1);
    return body === "unlabeled" ? `Unlabeled ${number}` : `${body}:Marker${number}`;
  };
  const bodies = new Set(), markers = new Set();
  for (const stamp of stamps) {
    for (const name of frames.get(stamp).poses.keys()) bodies.add(name);
    for (const name of frames.get(stamp).markers.keys()) markers.add(name);
  }
  stamps.forEach((stamp, f) => {
    const frame = frames.get(stamp);
    tally.frames += 1;
    for (const body of bodies) {
      const row = csv.rigid_bodies[body]?.[f];
      if (!row) fail(`csv: no rigid body ${body} at frame ${f}`);
      const pose = frame.poses.get(body);
      if (!pose) {
        if (row.position !== null) fail(`csv: ${body} at frame ${f}: a pose where the bag has none`);
        tally.gaps += 1;
        continue;
      }
      if (row.position === null) fail(`csv: ${body} at frame ${f}: a gap where the bag has it`);
      const p = yUp(pose.p), q = turn(pose.q);
      for (let a = 0; a < 3; ++a) same(`${body} frame ${f} position ${a}`, row.position[a], p[a], 1e-6);
      for (let a = 0; a < 4; ++a) same(`${body} frame ${f} rotation ${a}`, row.rotation[a], q[a], 1e-6);
    }
    for (const name of markers) {
      const got = csv.markers[markerName(name)]?.[f], expected = frame.markers.get(name);
      if (got === undefined) fail(`csv: no marker ${markerName(name)}`);
      if (!expected) {
        if (got !== null) fail(`csv: ${name} at frame ${f}: a value where the bag has none`);
        tally.gaps += 1;
        continue;
      }
      if (got === null) fail(`csv: ${name} at frame ${f}: a gap where the bag has it`);
      const e = yUp(expected);
      for (let a = 0; a < 3; ++a) same(`${name} frame ${f} axis ${a}`, got[a], e[a], 1e-6);
    }
  });
});

compare("tum", (tally, same) => {
  const bodies = new Set();
  for (const stamp of stamps) for (const name of frames.get(stamp).poses.keys()) bodies.add(name);
  const files = [...bodies].map((b) => path.join(`${prefix}_tum`, `${b}.tum`));
  const lines = execFileSync("node", [path.join(here, "tum_read.mjs"), ...files], { maxBuffer: 1 << 30 })
    .toString().trim().split("\n").map((line) => JSON.parse(line));
  const byBody = new Map();
  for (const line of lines) {
    const body = path.basename(line.file, ".tum");
    if (!byBody.has(body)) byBody.set(body, new Map());
    byBody.get(body).set(BigInt(line.stamp_ns), line);
  }
  for (const stamp of stamps) {
    tally.frames += 1;
    for (const body of bodies) {
      const pose = frames.get(stamp).poses.get(body), line = byBody.get(body)?.get(stamp);
      if (!pose) {
        if (line) fail(`tum: ${body} at ${stamp}: a pose where the bag has none`);
        tally.gaps += 1;
        continue;
      }
      if (!line) fail(`tum: ${body} at ${stamp}: missing`);
      for (let a = 0; a < 3; ++a) same(`${body} at ${stamp} position ${a}`, line.position[a], pose.p[a], 1e-6);
      const dot = Math.abs(line.quaternion.reduce((sum, v, a) => sum + v * pose.q[a], 0));
      same(`${body} at ${stamp} orientation`, dot, 1, 1e-8);
    }
  }
});

console.log("| format | frames | values compared | largest difference | gaps where the bag has none |");
console.log("|---|---|---|---|---|");
for (const t of table) {
  const unit = t.format === "c3d" ? "mm" : "m";
  console.log(`| ${t.format} | ${t.frames} | ${t.values} | ${t.largest.toExponential(2)} ${unit} | ${t.gaps} |`);
}
