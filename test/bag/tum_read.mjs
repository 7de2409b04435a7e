// Reads TUM trajectory files as the TUM RGB-D benchmark describes them ("timestamp tx ty tz qx qy
// qz qw" a line, whitespace between, '#' a comment) and prints each pose as JSON: written from the
// format's description, not from mocap_bag's writer, so that a test can check the writer by it.
//   node tum_read.mjs FILE...
import { readFileSync } from "node:fs";

for (const path of process.argv.slice(2)) {
  readFileSync(path, "utf8").split("\n").forEach((line, index) => {
    const text = line.trim();
    if (text === "" || text.startsWith("#")) return;
    const fields = text.split(/\s+/);
    if (fields.length !== 8) {
      console.error(`${path}:${index + 1}: ${fields.length} fields, the format has 8`);
      process.exit(1);
    }
    // The stamp as integer nanoseconds: a double would round it.
    const [seconds, fraction = ""] = fields[0].split(".");
    const stampNs = BigInt(seconds) * 1000000000n + BigInt((fraction + "000000000").slice(0, 9));
    const values = fields.slice(1).map(Number);
    console.log(JSON.stringify({ file: path, stamp_ns: stampNs.toString(), position: values.slice(0, 3),
                                 quaternion: values.slice(3) }));
  });
}
