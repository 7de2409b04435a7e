// Reads a C3D file as the C3D User Guide (c3d.org, "The C3D File Format User Guide") describes it
// and prints it as one JSON object: written from the description, not from mocap_bag's writer.
// The file is 512-byte blocks numbered from 1. Block 1 is the header: 16-bit words numbered from
// 1; word 1 is two bytes, the first block of the parameter section and the key 0x50; word 2 the
// 3D point count; 3 the analog measurements per frame; 4/5 the first/last frame; 6 the maximum
// interpolation gap; 7-8 the float scale factor (negative: point data stored as floats); 9 the
// first block of the data section; 10 the analog samples per frame; 11-12 the float frame rate.
// The parameter section starts with 4 bytes: two ignored, its block count, the processor type
// (84 Intel, 85 DEC, 86 MIPS: the byte order and float format of every number after it). Then
// records: name length (negative: locked), id (negative: a group, positive: a parameter of the
// group with the negated id), name, a signed 16-bit offset from that offset word to the next
// record (0: this is the last), then for a group a description (length byte, text), for a
// parameter the element type (-1 char, 1 byte, 2 int16, 4 float), dimension count, dimensions
// (bytes, the first varying fastest), data and description. Each frame of the data section holds
// POINT:USED points of four words (int16 x, y, z times POINT:SCALE and a word whose high byte is
// the camera mask and low byte the residual over |scale|; or four floats, the fourth converted to
// an integer first), a negative fourth word marking an invalid point, then the frame's analog
// samples, skipped here. More than 255 labels continue in POINT:LABELS2, LABELS3, ...; more than
// 65535 frames are counted by TRIAL:ACTUAL_START_FIELD / ACTUAL_END_FIELD (two 16-bit words, the
// low one first, making a 32-bit frame number: low + high x 65536).
// Prints {header, processor, parameters: {GROUP: {PARAM: value}}, group_descriptions, labels,
// descriptions, units, rate, frame_count, frames: [[[x, y, z] | null per point] per frame],
// residuals: [[r | null per point] per frame]}. Char parameters: a right-trimmed string for one
// dimension, arrays of them for more; numbers: a scalar for no dimensions, else arrays nested
// with the last dimension outermost. Bytes and the counts POINT:USED, FRAMES, DATA_START,
// ANALOG:USED and the TRIAL words read unsigned, other int16 signed. Fails, naming what is wrong,
// when the header and parameters disagree or the data does not fit the file.
// With --frames I,J,... (0-based) every frame is read and checked, and only those are printed
// (frames and residuals hold them in that order).
//   node c3d_read.mjs FILE [--frames I,J,...]
import { readFileSync } from "node:fs";

const fail = (message) => { console.error(`c3d_read: ${message}`); process.exit(1); };
const [, , fileName, option, list] = process.argv;
if (!fileName || (option !== undefined && (option !== "--frames" || !list)) || process.argv.length > 5) {
  fail("usage: node c3d_read.mjs FILE [--frames I,J,...]");
}
const printed = list?.split(",").map(Number);
let file;
try { file = readFileSync(fileName); } catch (e) { fail(`cannot read ${fileName}: ${e.message}`); }
const view = new DataView(file.buffer, file.byteOffset, file.byteLength);
const BLOCK = 512;
const blockOffset = (block) => (block - 1) * BLOCK;
const need = (offset, length, what) => {
  if (offset < 0 || offset + length > file.length) fail(`${what}: bytes ${offset}..${offset + length} lie beyond the end of the file (${file.length} bytes)`);
};

// --- header block, first word (bytes, not affected by the processor type) ---
need(0, BLOCK, "header block");
const parameterBlock = file[0];
if (file[1] !== 0x50) fail(`header byte 2 is 0x${file[1].toString(16)}, not the C3D key 0x50`);
if (parameterBlock < 2) fail(`header byte 1 puts the parameter section at block ${parameterBlock}, inside the header`);

// --- parameter section header: the processor type decides how every number is read ---
const parameterStart = blockOffset(parameterBlock);
need(parameterStart, 4, `parameter section header (block ${parameterBlock})`);
const parameterBlockCount = file[parameterStart + 2];
const processorByte = file[parameterStart + 3];
const processor = { 84: "intel", 85: "dec", 86: "mips" }[processorByte];
if (!processor) fail(`parameter section byte 4 is ${processorByte}, no processor type (84 Intel, 85 DEC, 86 MIPS)`);
if (parameterBlockCount < 1) fail("parameter section header gives 0 blocks");
const parameterEnd = parameterStart + parameterBlockCount * BLOCK;
need(parameterStart, parameterBlockCount * BLOCK, `parameter section (${parameterBlockCount} blocks from block ${parameterBlock})`);

const little = processor !== "mips";
const int8 = (o) => view.getInt8(o);
const uint8 = (o) => view.getUint8(o);
const int16 = (o) => view.getInt16(o, little);
const uint16 = (o) => view.getUint16(o, little);
// DEC (VAX F) floats: two little-endian 16-bit words, the first holding sign, 8-bit exponent
// (bias 128) and the high 7 fraction bits, the second the low 16; value 0.1f x 2^(e-128).
const float32 = processor === "dec"
  ? (o) => {
    const high = view.getUint16(o, true), low = view.getUint16(o + 2, true);
    const exponent = (high >> 7) & 0xff;
    if (exponent === 0) return 0;
    const fraction = ((high & 0x7f) * 65536 + low) / 8388608;
    return (high & 0x8000 ? -1 : 1) * (1 + fraction) * 2 ** (exponent - 129);
  }
  : (o) => view.getFloat32(o, little);

// --- header words (1-based, 16 bits) ---
const word = (n) => 2 * (n - 1);
const header = {
  parameter_block: parameterBlock,
  point_count: uint16(word(2)),
  analog_per_frame: uint16(word(3)),
  first_frame: uint16(word(4)),
  last_frame: uint16(word(5)),
  max_gap: uint16(word(6)),
  scale: float32(word(7)),
  data_start: uint16(word(9)),
  analog_samples_per_frame: uint16(word(10)),
  frame_rate: float32(word(11)),
};

// --- parameter records ---
const ascii = (o, n) => file.toString("latin1", o, o + n);
const text = (o, n) => file.toString("utf8", o, o + n);
const trimRight = (s) => s.replace(/[\s\0]+$/u, "");
const groupsById = new Map();   // negated id -> {name, description}
const records = [];             // parameters in file order
for (let pos = parameterStart + 4; ;) {
  if (pos + 2 > parameterEnd) fail(`parameter records run past the parameter section's ${parameterBlockCount} blocks without an end (a next-record offset of 0)`);
  const nameLength = Math.abs(int8(pos));
  const id = int8(pos + 1);
  if (nameLength === 0 || id === 0) break;  // zero bytes where a record would start: the end
  const where = `parameter record at byte ${pos}`;
  if (pos + 2 + nameLength + 2 > parameterEnd) fail(`${where}: runs past the parameter section`);
  const name = ascii(pos + 2, nameLength).toUpperCase();
  if (!/^[A-Z0-9_]+$/.test(name)) fail(`${where}: name ${JSON.stringify(name)} is not upper-case letters, digits and underscores`);
  const offsetAt = pos + 2 + nameLength;
  const offset = int16(offsetAt);
  const next = offset === 0 ? null : offsetAt + offset;
  if (next !== null && next <= pos) fail(`${where} (${name}): next-record offset ${offset} does not point forward`);
  let cursor = offsetAt + 2;
  const limit = next ?? parameterEnd;
  const take = (n, what) => {
    if (cursor + n > limit) fail(`${where} (${name}): its ${what} runs past ${next === null ? "the parameter section" : `the next record (offset ${offset})`}`);
    const at = cursor; cursor += n; return at;
  };
  if (id < 0) {
    const descriptionLength = uint8(take(1, "description length"));
    const description = text(take(descriptionLength, "description"), descriptionLength);
    if (groupsById.has(-id)) fail(`${where}: group ${name} reuses group id ${-id} of ${groupsById.get(-id).name}`);
    groupsById.set(-id, { name, description });
  } else {
    const type = int8(take(1, "element type"));
    if (![-1, 1, 2, 4].includes(type)) fail(`${where} (${name}): element type ${type} is none of -1 char, 1 byte, 2 int16, 4 float`);
    const dimensionCount = uint8(take(1, "dimension count"));
    if (dimensionCount > 7) fail(`${where} (${name}): ${dimensionCount} dimensions, more than 7`);
    const dims = [];
    for (let i = 0; i < dimensionCount; i++) dims.push(uint8(take(1, "dimensions")));
    const count = dims.reduce((a, b) => a * b, 1);
    const size = count * Math.abs(type);
    const dataAt = take(size, "data");
    const descriptionLength = uint8(take(1, "description length"));
    take(descriptionLength, "description");
    records.push({ name, group: id, type, dims, dataAt, where });
  }
  if (next === null) break;
  pos = next;
}

// Parameter values: scalars for no dimensions; arrays nested with the last dimension outermost
// (the first dimension varies fastest); char arrays split on their first dimension into strings.
const nest = (flat, dims) => {
  if (dims.length <= 1) return flat;
  const inner = dims.slice(0, -1);
  const step = inner.reduce((a, b) => a * b, 1);
  const out = [];
  for (let i = 0; i < dims[dims.length - 1]; i++) out.push(nest(flat.slice(i * step, (i + 1) * step), inner));
  return out;
};
// These are unsigned 16-bit counts in the description (POINT:USED, POINT:FRAMES, POINT:DATA_START,
// the TRIAL words); other int16 parameters are read signed.
const unsignedInt16 = new Set(["POINT:USED", "POINT:FRAMES", "POINT:DATA_START", "POINT:LONG_FRAMES", "ANALOG:USED", "TRIAL:ACTUAL_START_FIELD", "TRIAL:ACTUAL_END_FIELD"]);
const valueOf = (record, key) => {
  const { type, dims, dataAt } = record;
  if (type === -1) {
    if (dims.length === 0) return ascii(dataAt, 1);
    const length = dims[0];
    const strings = [];
    const count = dims.slice(1).reduce((a, b) => a * b, 1);
    for (let i = 0; i < count; i++) strings.push(trimRight(text(dataAt + i * length, length)));
    return dims.length === 1 ? strings[0] : nest(strings, dims.slice(1));
  }
  const read = type === 1 ? uint8 : type === 2 ? (unsignedInt16.has(key) ? uint16 : int16) : float32;
  const count = dims.reduce((a, b) => a * b, 1);
  const flat = [];
  for (let i = 0; i < count; i++) flat.push(read(dataAt + i * Math.abs(type)));
  return dims.length === 0 ? flat[0] : nest(flat, dims);
};

const groupNames = new Set();
for (const group of groupsById.values()) {
  if (groupNames.has(group.name)) fail(`group ${group.name} appears twice`);
  groupNames.add(group.name);
}
const parameters = {};
const group_descriptions = {};
for (const group of groupsById.values()) { parameters[group.name] = {}; group_descriptions[group.name] = group.description; }
const raw = {};  // "GROUP:PARAM" -> record
for (const record of records) {
  const group = groupsById.get(record.group);
  if (!group) fail(`${record.where}: parameter ${record.name} names group id ${record.group}, which no group record has`);
  const key = `${group.name}:${record.name}`;
  if (raw[key]) fail(`parameter ${key} appears twice`);
  raw[key] = record;
  parameters[group.name][record.name] = valueOf(record, key);
}
const param = (key) => (raw[key] ? parameters[key.split(":")[0]][key.split(":")[1]] : undefined);
const numeric = (key) => {
  const value = param(key);
  if (value === undefined) fail(`no ${key} parameter`);
  const scalar = Array.isArray(value) && value.length === 1 ? value[0] : value;
  if (typeof scalar !== "number") fail(`${key} is ${JSON.stringify(value)}, not a single number`);
  return scalar;
};

// --- consistency of header and parameters ---
const used = numeric("POINT:USED");
if (header.point_count !== used) fail(`header word 2 says ${header.point_count} points, POINT:USED ${used}`);
const rate = numeric("POINT:RATE");
if (Math.abs(header.frame_rate - rate) > 1e-3 * Math.max(Math.abs(rate), Math.abs(header.frame_rate)))
  fail(`header frame rate ${header.frame_rate} differs from POINT:RATE ${rate}`);
const dataStart = numeric("POINT:DATA_START");
if (header.data_start !== dataStart) fail(`header word 9 puts the data at block ${header.data_start}, POINT:DATA_START at ${dataStart}`);
if (dataStart < parameterBlock + parameterBlockCount)
  fail(`data start block ${dataStart} lies inside the parameter section (blocks ${parameterBlock}..${parameterBlock + parameterBlockCount - 1})`);
const scale = numeric("POINT:SCALE");
if (Math.fround(scale) !== Math.fround(header.scale)) fail(`header scale ${header.scale} differs from POINT:SCALE ${scale}`);
if (scale === 0) fail("POINT:SCALE is 0: neither a positive integer scale nor a negative float marker");
const floatData = scale < 0;
if (raw["ANALOG:USED"]) {
  const analogUsed = numeric("ANALOG:USED");
  const expected = analogUsed === 0 ? 0 : analogUsed * header.analog_samples_per_frame;
  if (header.analog_per_frame !== expected)
    fail(`header word 3 says ${header.analog_per_frame} analog values a frame, ANALOG:USED ${analogUsed} x ${header.analog_samples_per_frame} samples (word 10) = ${expected}`);
}

// --- frame count: header first..last, or TRIAL:ACTUAL_START_FIELD..ACTUAL_END_FIELD when larger ---
if (header.last_frame < header.first_frame) fail(`header last frame ${header.last_frame} is before first frame ${header.first_frame}`);
let frameCount = header.last_frame - header.first_frame + 1;
if (raw["TRIAL:ACTUAL_START_FIELD"] || raw["TRIAL:ACTUAL_END_FIELD"]) {
  const field = (key) => {
    const value = param(key);
    if (value === undefined) fail(`${key === "TRIAL:ACTUAL_START_FIELD" ? "TRIAL:ACTUAL_END_FIELD" : "TRIAL:ACTUAL_START_FIELD"} without ${key}`);
    if (raw[key].type !== 2 || !Array.isArray(value) || value.length !== 2) fail(`${key} is ${JSON.stringify(value)}, not two int16 words`);
    return value[0] + value[1] * 65536;
  };
  const start = field("TRIAL:ACTUAL_START_FIELD"), end = field("TRIAL:ACTUAL_END_FIELD");
  if (end < start) fail(`TRIAL:ACTUAL_END_FIELD ${end} is before TRIAL:ACTUAL_START_FIELD ${start}`);
  frameCount = Math.max(frameCount, end - start + 1);
}
if (raw["POINT:FRAMES"]) {
  const frames = numeric("POINT:FRAMES");
  const saturated = raw["POINT:FRAMES"].type !== 4 && frames === 65535 && frameCount >= 65535;
  if (frames !== frameCount && !saturated) fail(`POINT:FRAMES is ${frames}, the header and TRIAL give ${frameCount} frames`);
}
if (raw["POINT:LONG_FRAMES"] && numeric("POINT:LONG_FRAMES") !== frameCount)
  fail(`POINT:LONG_FRAMES is ${numeric("POINT:LONG_FRAMES")}, the header and TRIAL give ${frameCount} frames`);

// --- labels and descriptions: LABELS, LABELS2, LABELS3, ... as one list ---
const joined = (base) => {
  const out = [];
  for (let n = 1; ; n++) {
    const key = `POINT:${base}${n === 1 ? "" : n}`;
    if (!raw[key]) break;
    if (raw[key].type !== -1) fail(`${key} is not character data`);
    const value = param(key);
    const list = typeof value === "string" ? [value] : value;
    if (!Array.isArray(list) || list.some((s) => typeof s !== "string")) fail(`${key} is not a list of strings`);
    if (raw[`POINT:${base}${n + 1}`] && list.length !== 255) fail(`${key} holds ${list.length} entries, but ${base}${n + 1} follows it: it must hold 255`);
    out.push(...list);
  }
  for (const key of Object.keys(raw)) {
    const m = key.match(new RegExp(`^POINT:${base}(\\d+)$`));
    if (m && Number(m[1]) > 1 && !raw[`POINT:${base}${Number(m[1]) === 2 ? "" : Number(m[1]) - 1}`])
      fail(`${key} without the ${base} parameter before it`);
  }
  return out;
};
const allLabels = joined("LABELS");
if (allLabels.length < used) fail(`${allLabels.length} labels in POINT:LABELS..., POINT:USED ${used}`);
const labels = allLabels.slice(0, used);
const seen = new Set();
labels.forEach((label, i) => {
  if (label === "") fail(`label ${i + 1} is empty`);
  if (seen.has(label)) fail(`label ${JSON.stringify(label)} appears twice`);
  seen.add(label);
});
const descriptions = joined("DESCRIPTIONS").slice(0, used);
const units = raw["POINT:UNITS"] ? param("POINT:UNITS") : null;
if (units !== null && typeof units !== "string") fail(`POINT:UNITS is ${JSON.stringify(units)}, not one string`);

// --- data section: frames of USED points, then analog_per_frame analog values, skipped ---
const wordSize = floatData ? 4 : 2;
const frameBytes = (4 * used + header.analog_per_frame) * wordSize;
const dataAt = blockOffset(dataStart);
const dataEnd = dataAt + frameCount * frameBytes;
if (dataEnd > file.length)
  fail(`${frameCount} frames of ${frameBytes} bytes from block ${dataStart} need ${dataEnd} bytes, the file has ${file.length}`);
if (file.length - dataEnd >= BLOCK)
  fail(`${file.length - dataEnd} bytes follow the last of ${frameCount} frames: more than one block of padding`);
const magnitude = Math.abs(scale);
const frames = [];
const residuals = [];
for (let f = 0; f < frameCount; f++) {
  const points = [];
  const frameResiduals = [];
  const base = dataAt + f * frameBytes;
  for (let p = 0; p < used; p++) {
    const at = base + p * 4 * wordSize;
    let xyz, fourth;
    if (floatData) {
      xyz = [float32(at), float32(at + 4), float32(at + 8)];
      fourth = float32(at + 12);
      if (Number.isNaN(fourth)) fail(`frame ${f + 1}, point ${labels[p]}: fourth word is not a number`);
    } else {
      xyz = [int16(at) * scale, int16(at + 2) * scale, int16(at + 4) * scale];
      fourth = int16(at + 6);
    }
    if (fourth < 0) { points.push(null); frameResiduals.push(null); continue; }
    if (!xyz.every(Number.isFinite)) fail(`frame ${f + 1}, point ${labels[p]}: coordinates ${xyz} are not finite`);
    points.push(xyz);
    frameResiduals.push((Math.trunc(fourth) & 0xff) * magnitude);
  }
  frames.push(points);
  residuals.push(frameResiduals);
}

console.log(JSON.stringify({
  header, processor, parameters, group_descriptions, labels, descriptions, units, rate,
  frame_count: frameCount,
  frames: printed ? printed.map((i) => frames[i] ?? fail(`--frames: no frame ${i}`)) : frames,
  residuals: printed ? printed.map((i) => residuals[i]) : residuals,
}));
