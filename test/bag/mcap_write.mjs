// An MCAP file as ROS 2 Jazzy's `ros2 bag record` writes it, written by @mcap/core's own writer
// (not ours): profile "ros2", a "ros2msg" schema, a "cdr" channel with rosbag2's QoS metadata,
// zstd-compressed chunks (Foxglove's zstd), message indexes and the summary.
//
//   node mcap_write.mjs FILE.mcap COUNT
//
// Message i on /chatter is the std_msgs/msg/String "message i", logged at 1.7e18 + i ms; and
// three messages on /unnamed, a channel without a schema (so of no known type), after them.
import fs from "node:fs";
import { McapWriter } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";

const [file, countText] = process.argv.slice(2);
const count = Number(countText);
await zstd.isLoaded;

const chunks = [];
let position = 0n;
const writable = {
  position: () => position,
  write: async (buffer) => {
    chunks.push(Buffer.from(buffer));
    position += BigInt(buffer.length);
  },
};
const writer = new McapWriter({
  writable,
  chunkSize: 1024,
  compressChunk: (data) => ({ compression: "zstd", compressedData: zstd.compress(data) }),
});
await writer.start({ profile: "ros2", library: "rosbag2 (@mcap/core test writer)" });
const schemaId = await writer.registerSchema({
  name: "std_msgs/msg/String",
  encoding: "ros2msg",
  data: new TextEncoder().encode("string data\n"),
});
const qos =
  "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n" +
  "  deadline:\n    sec: 9223372036\n    nsec: 854775807\n" +
  "  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n" +
  "  liveliness: 1\n  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n" +
  "  avoid_ros_namespace_conventions: false\n";
const channelId = await writer.registerChannel({
  topic: "/chatter",
  schemaId,
  messageEncoding: "cdr",
  metadata: new Map([["offered_qos_profiles", qos]]),
});
for (let i = 0; i < count; i++) {
  // CDR, little endian: the encapsulation header, then the string's length with its NUL.
  const text = new TextEncoder().encode(`message ${i}`);
  const data = new Uint8Array(4 + 4 + text.length + 1);
  data.set([0, 1, 0, 0]);
  new DataView(data.buffer).setUint32(4, text.length + 1, true);
  data.set(text, 8);
  const time = 1700000000000000000n + BigInt(i) * 1000000n;
  await writer.addMessage({ channelId, sequence: i, logTime: time, publishTime: time, data });
}
const unnamed = await writer.registerChannel({
  topic: "/unnamed",
  schemaId: 0,
  messageEncoding: "cdr",
  metadata: new Map(),
});
for (let i = 0; i < 3; i++) {
  const time = 1700000000000000000n + BigInt(count + i) * 1000000n;
  const data = new Uint8Array([0, 1, 0, 0, i, 0, 0, 0]);
  await writer.addMessage({ channelId: unnamed, sequence: i, logTime: time, publishTime: time, data });
}
await writer.end();
fs.writeFileSync(file, Buffer.concat(chunks));
