// Reads an OpenSim TRC file as OpenSim describes the format (tab-separated; PathFileType, a line
// of header keys and one of their values, the marker names each over three columns, their X/Y/Z
// labels, then one row per frame: frame number, time, x y z per marker, empty where missing) and
// prints it as one JSON object: written from the description, not from mocap_bag's writer.
//   node trc_read.mjs FILE
import { readFileSync } from "node:fs";

const fail = (message) => { console.error(`trc_read: ${message}`); process.exit(1); };
const lines = readFileSync(process.argv[2], "utf8").split("\n");
if (!lines[0].startsWith("PathFileType\t4")) fail("line 1 is no PathFileType 4");
const keys = lines[1].split("\t");
const values = lines[2].split("\t");
const header = Object.fromEntries(keys.map((key, i) => [key, values[i]]));
const nameCells = lines[3].split("\t");
if (nameCells[0] !== "Frame#" || nameCells[1] !== "Time") fail("line 4 does not start Frame# Time");
const markers = [];
for (let i = 2; i < nameCells.length; i += 3) if (nameCells[i] !== "") markers.push(nameCells[i]);
if (markers.length !== Number(header.NumMarkers)) fail(`${markers.length} names, NumMarkers ${header.NumMarkers}`);
const rows = [];
for (const line of lines.slice(5)) {
  if (line.trim() === "") continue;
  const cells = line.split("\t");
  if (cells.length !== 2 + 3 * markers.length) fail(`row ${rows.length + 1}: ${cells.length} cells`);
  const points = {};
  markers.forEach((name, m) => {
    const xyz = cells.slice(2 + 3 * m, 5 + 3 * m);
    points[name] = xyz.every((c) => c === "") ? null : xyz.map(Number);
  });
  rows.push({ frame: Number(cells[0]), time: cells[1], points });
}
if (rows.length !== Number(header.NumFrames)) fail(`${rows.length} rows, NumFrames ${header.NumFrames}`);
console.log(JSON.stringify({ header, markers, rows }));
