// Reads a CSV file as OptiTrack Motive exports a take (Data Export: CSV, docs.optitrack.com, and
// Motive's own exports of format versions 1.21 to 1.23 kept in public repositories): CRLF lines;
// line 1 key,value pairs starting "Format Version"; line 2 empty; then the header rows Type, Name,
// ID (and Parent, if there) each labelled in column B, or unlabelled as in 1.21, the category row
// (Rotation, Position, Mean Marker Error or Error Per Marker, Marker Quality), and
// "Frame,Time (Seconds),X,Y,Z,W,..."; one row per frame after that, values "%.6f", a cell left
// empty where there is no data. A rigid body is Rotation X Y Z W, Position X Y Z and maybe its
// error; a Rigid Body Marker or a Marker is Position X Y Z, a Rigid Body Marker maybe followed by
// its Marker Quality. Prints one JSON object, written from that description, not from mocap_bag's
// writer: info (line 1), columns (every data column), rigid_bodies and markers (by name; a name
// carried by columns of two types is keyed "<name> (<type>)" for each), frames.
//   node motive_csv_read.mjs FILE
import { readFileSync } from "node:fs";

const fail = (message) => { console.error(`motive_csv_read: ${message}`); process.exit(1); };
const at = (line, column) => `line ${line}, column ${column + 1}`;

const text = readFileSync(process.argv[2] ?? fail("usage: node motive_csv_read.mjs FILE"), "utf8");
if (!text.endsWith("\r\n")) fail("the file does not end with CRLF");
const lines = text.slice(0, -2).split("\r\n");
lines.forEach((line, i) => { if (line.includes("\n") || line.includes("\r")) fail(`line ${i + 1} has a bare LF or CR`); });

// One line into cells: comma separated, a cell may be quoted with "" for a quote inside it.
const cellsOf = (line, number) => {
  const cells = [];
  let i = 0;
  for (;;) {
    let cell = "";
    if (line[i] === '"') {
      for (i++; ; i++) {
        if (i >= line.length) fail(`${at(number, cells.length)}: quote not closed`);
        if (line[i] === '"' && line[i + 1] === '"') { cell += '"'; i++; } else if (line[i] === '"') break; else cell += line[i];
      }
      i++;
      if (i < line.length && line[i] !== ",") fail(`${at(number, cells.length)}: text after a closing quote`);
    } else {
      while (i < line.length && line[i] !== ",") { if (line[i] === '"') fail(`${at(number, cells.length)}: quote inside a cell`); cell += line[i++]; }
    }
    cells.push(cell);
    if (i >= line.length) return cells;
    i++;
  }
};

// Line 1: the take's information as key,value pairs.
const first = cellsOf(lines[0], 1);
if (first[0] !== "Format Version") fail(`${at(1, 0)}: "${first[0]}", not "Format Version"`);
if (first.length % 2 !== 0) fail(`line 1: ${first.length} cells, not key,value pairs`);
const info = {};
for (let i = 0; i < first.length; i += 2) {
  if (first[i] === "") fail(`${at(1, i)}: empty key`);
  if (first[i] in info) fail(`${at(1, i)}: key "${first[i]}" twice`);
  info[first[i]] = first[i + 1];
}
if (lines.length < 2 || lines[1] !== "") fail("line 2 is not empty");

// Header rows, up to the one starting "Frame".
const axisLine = lines.findIndex((line, i) => i > 1 && line.startsWith("Frame,"));
if (axisLine < 0) fail('no line starts "Frame,"');
const header = lines.slice(2, axisLine).map((line, i) => cellsOf(line, i + 3));
const axes = cellsOf(lines[axisLine], axisLine + 1);
if (axes[1] !== "Time (Seconds)" && axes[1] !== "Time") fail(`${at(axisLine + 1, 1)}: "${axes[1]}", not "Time (Seconds)"`);
const rows = {};
if (header.length > 0 && header[0][0] === "" && header[0][1] === "Type") {
  const labels = header.map((cells) => cells[1]);
  const expected = labels.includes("Parent") ? ["Type", "Name", "ID", "Parent", ""] : ["Type", "Name", "ID", ""];
  if (labels.join("|") !== expected.join("|")) fail(`lines 3-${axisLine}: header rows labelled ${JSON.stringify(labels)}, not ${JSON.stringify(expected)}`);
  header.forEach((cells, i) => {
    if (cells[0] !== "") fail(`${at(i + 3, 0)}: not empty`);
    rows[expected[i] === "" ? "category" : expected[i]] = cells;
  });
} else if (header.length === 4 && header.every((cells) => cells[0] === "" && cells[1] === "")) {
  [rows.Type, rows.Name, rows.ID, rows.category] = header; // 1.21: rows not labelled
} else fail(`lines 3-${axisLine}: header rows neither Type, Name, ID, [Parent,] category nor four unlabelled rows`);
const width = axes.length;
header.forEach((cells, i) => { if (cells.length !== width) fail(`line ${i + 3}: ${cells.length} cells, line ${axisLine + 1} has ${width}`); });
const start = axes[2] === "TimeCode" ? 3 : 2;
for (const cells of Object.values(rows)) for (let c = 2; c < start; c++) if (cells[c] !== "") fail(`header column ${c + 1} is not empty above TimeCode`);

const columns = [];
for (let c = start; c < width; c++) {
  const column = { type: rows.Type[c], name: rows.Name[c], id: rows.ID[c], category: rows.category[c], axis: axes[c] };
  if (rows.Parent) column.parent = rows.Parent[c];
  if (column.type === "" || column.name === "") fail(`column ${c + 1}: no type or no name in the header rows`);
  columns.push(column);
}

// Columns into groups: consecutive columns of one type, name and ID make one asset.
const rotationType = info["Rotation Type"] ?? "Quaternion";
const rotationAxes = rotationType === "Quaternion" ? "XYZW" : "XYZ";
const groups = [];
for (let c = 0; c < columns.length;) {
  const { type, name, id } = columns[c];
  let end = c;
  while (end < columns.length && columns[end].type === type && columns[end].name === name && columns[end].id === id) end++;
  const run = columns.slice(c, end);
  const signature = run.map((col) => `${col.category}/${col.axis}`).join(",");
  const position = "Position/X,Position/Y,Position/Z";
  const rotation = [...rotationAxes].map((a) => `Rotation/${a}`).join(",");
  const group = { type, name, first: start + c };
  if (type === "Rigid Body") {
    if (signature === `${rotation},${position}`) group.error = false;
    else if (signature === `${rotation},${position},Mean Marker Error/` || signature === `${rotation},${position},Error Per Marker/`) group.error = true;
    else fail(`columns ${start + c + 1}-${start + end}: rigid body "${name}" is ${signature}, not ${rotation},${position}[,Mean Marker Error]`);
  } else if (type === "Rigid Body Marker" || type === "Marker") {
    if (signature === position) group.quality = false;
    else if (type === "Rigid Body Marker" && signature === `${position},Marker Quality/`) group.quality = true;
    else fail(`columns ${start + c + 1}-${start + end}: ${type} "${name}" is ${signature}, not ${position}${type === "Marker" ? "" : "[,Marker Quality]"}`);
  } else fail(`column ${start + c + 1}: type "${type}" is none of Rigid Body, Rigid Body Marker, Marker`);
  groups.push(group);
  c = end;
}
const bodies = groups.filter((g) => g.type === "Rigid Body");
const triples = groups.filter((g) => g.type !== "Rigid Body");
const rigid_bodies = {};
for (const g of bodies) {
  if (g.name in rigid_bodies) fail(`column ${g.first + 1}: rigid body "${g.name}" twice`);
  rigid_bodies[g.name] = [];
}
const markers = {};
for (const g of triples) {
  const shared = triples.filter((o) => o.name === g.name);
  g.key = shared.every((o) => o.type === shared[0].type) ? g.name : `${g.name} (${g.type})`;
  if (g.key in markers) fail(`column ${g.first + 1}: ${g.type} "${g.name}" twice`);
  markers[g.key] = [];
}

// Data rows.
const number = /^-?\d+\.\d{6}$/;
const value = (cells, c, line) => {
  if (!number.test(cells[c])) fail(`${at(line, c)}: "${cells[c]}" is not a number written %.6f`);
  return Number(cells[c]);
};
const cellsAll = (cells, from, count, line, what) => {
  const part = cells.slice(from, from + count);
  if (part.every((cell) => cell === "")) return null;
  if (part.some((cell) => cell === "")) fail(`${at(line, from)}: ${what} partly empty`);
  return part.map((_, k) => value(cells, from + k, line));
};
let frames = 0;
let previous = null;
for (let l = axisLine + 1; l < lines.length; l++) {
  const line = l + 1;
  const cells = cellsOf(lines[l], line);
  if (cells.length !== width) fail(`line ${line}: ${cells.length} cells, the header rows have ${width}`);
  if (!/^\d+$/.test(cells[0])) fail(`${at(line, 0)}: frame "${cells[0]}" is not a whole number`);
  const frame = Number(cells[0]);
  if (previous !== null && frame !== previous + 1) fail(`${at(line, 0)}: frame ${frame} after frame ${previous}`);
  previous = frame;
  if (!number.test(cells[1])) fail(`${at(line, 1)}: time "${cells[1]}" is not written %.6f`);
  for (const g of bodies) {
    const n = rotationAxes.length;
    const rotation = cellsAll(cells, g.first, n, line, `rotation of rigid body "${g.name}"`);
    const position = cellsAll(cells, g.first + n, 3, line, `position of rigid body "${g.name}"`);
    if ((rotation === null) !== (position === null)) fail(`${at(line, g.first)}: rigid body "${g.name}" has a ${rotation ? "rotation" : "position"} but no ${rotation ? "position" : "rotation"}`);
    let error = null;
    if (g.error && cells[g.first + n + 3] !== "") {
      if (position === null) fail(`${at(line, g.first + n + 3)}: marker error of rigid body "${g.name}" without its pose`);
      error = value(cells, g.first + n + 3, line);
    }
    rigid_bodies[g.name].push({ frame, time: cells[1], rotation, position, mean_marker_error: error });
  }
  for (const g of triples) {
    const position = cellsAll(cells, g.first, 3, line, `${g.type} "${g.name}"`);
    if (g.quality && cells[g.first + 3] !== "") {
      if (position === null) fail(`${at(line, g.first + 3)}: Marker Quality of "${g.name}" without its position`);
      value(cells, g.first + 3, line);
    }
    markers[g.key].push(position);
  }
  frames++;
}
if ("Total Exported Frames" in info && frames !== Number(info["Total Exported Frames"])) {
  fail(`${frames} rows, Total Exported Frames ${info["Total Exported Frames"]}`);
}
console.log(JSON.stringify({ info, columns, rigid_bodies, markers, frames }));
