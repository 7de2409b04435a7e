// The viewer's own CDR decoder (components/viewer/web/cdr.js) against
// @foxglove/rosmsg2-serialization on the same bytes, for every topic the bridge offers: the
// two must agree field for field. Prints one line per topic; exits 0 once every topic that
// carries messages has agreed on at least COUNT of them, or on fewer and then gone quiet for
// 5 s (a topic that publishes on events, /alerts); topics silent for 10 s are reported, not
// waited for; 1 on any disagreement.
//
//   node viewer_decoder_check.mjs URL COUNT
import wsProtocol from "@foxglove/ws-protocol";
import ros2idl from "@foxglove/ros2idl-parser";
import rosmsg2 from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";
import { decode, parseSchema } from "../../components/viewer/web/cdr.js";

const { FoxgloveClient } = wsProtocol;
const [url, countText] = process.argv.slice(2);
const count = Number(countText);

// Foxglove's reader renames builtin_interfaces' nanosec to nsec and returns typed arrays.
function normalize(value) {
  if (ArrayBuffer.isView(value)) return Array.from(value);
  if (Array.isArray(value)) return value.map(normalize);
  if (typeof value === "bigint") return Number(value);
  if (value && typeof value === "object") {
    return Object.fromEntries(
      Object.entries(value).map(([k, v]) => [k === "nsec" ? "nanosec" : k, normalize(v)]),
    );
  }
  return value;
}
function same(a, b) {
  if (typeof a === "number" && typeof b === "number") {
    return a === b || (Number.isNaN(a) && Number.isNaN(b));
  }
  if (Array.isArray(a) && Array.isArray(b)) return a.length === b.length && a.every((x, k) => same(x, b[k]));
  if (a && b && typeof a === "object" && typeof b === "object") {
    const keys = Object.keys(a);
    return keys.length === Object.keys(b).length && keys.every((k) => same(a[k], b[k]));
  }
  return a === b;
}

const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const subscriptions = new Map();
const agreed = new Map();
const lastMessage = new Map();
setTimeout(() => {
  for (const [topic, n] of agreed) console.log(`${topic}: ${n} message(s) agreed`);
  console.error("viewer_decoder_check: timed out");
  process.exit(1);
}, 50000);
client.on("advertise", (channels) => {
  for (const channel of channels) {
    const id = client.subscribe(channel.id);
    subscriptions.set(id, {
      channel,
      theirs: new rosmsg2.MessageReader(ros2idl.parseRos2idl(channel.schema)),
      ours: parseSchema(channel.schema),
    });
    agreed.set(channel.topic, 0);
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const { channel, theirs, ours } = subscriptions.get(subscriptionId);
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  const a = normalize(ours && decode(ours, channel.schemaName, bytes));
  const b = normalize(theirs.readMessage(bytes));
  if (!same(a, b)) {
    console.error(`${channel.topic}: the decoders disagree\nours:   ${JSON.stringify(a).slice(0, 400)}\ntheirs: ${JSON.stringify(b).slice(0, 400)}`);
    process.exit(1);
  }
  agreed.set(channel.topic, agreed.get(channel.topic) + 1);
  lastMessage.set(channel.topic, Date.now());
});
const started = Date.now();
setInterval(() => {
  const now = Date.now();
  const carrying = [...agreed].filter(([, n]) => n > 0);
  const elapsed = now - started;
  // Done when every topic that carries messages has carried `count`, or fewer and nothing for
  // 5 s (one that publishes on events, each message of which agreed), or after 40 s.
  const enough =
    carrying.length > 0 &&
    carrying.every(([topic, n]) => n >= count || now - lastMessage.get(topic) > 5000);
  if (elapsed < 10000 || (!enough && elapsed < 40000)) return;
  for (const [topic, n] of agreed) console.log(`${topic}: ${n > 0 ? `${n} message(s) agreed` : "silent"}`);
  process.exit(0);
}, 500);
