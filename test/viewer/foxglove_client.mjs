// An independent client of the Foxglove WebSocket protocol: @foxglove/ws-protocol's
// FoxgloveClient over the `ws` package, decoding with @foxglove/ros2idl-parser and
// @foxglove/rosmsg2-serialization from the schema the server advertised. Nothing of ours.
//
//   node foxglove_client.mjs [--ros-definitions] URL COUNT TOPIC...
//
// --ros-definitions: a standard ROS 2 type (geometry_msgs, nav_msgs, tf2_msgs...) is decoded
// with ROS 2 Humble's own definitions from @foxglove/rosmsg-msgs-common, not the advertised
// schema ("decodedWith": "ros2humble" in its lines); other types as before.
//
// Subscribes to each TOPIC, prints one JSON line per decoded message ({"topic", "schemaName",
// "message"}; typed arrays as arrays, 64-bit integers as numbers, image data as its length)
// until every topic has COUNT messages, then exits 0. Exits 1 with one line on stderr if a
// topic is not advertised within 20 s or the messages do not arrive within 60 s.
import wsProtocol from "@foxglove/ws-protocol";
import ros2idl from "@foxglove/ros2idl-parser";
import rosmsg2 from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";
import rosCommon from "@foxglove/rosmsg-msgs-common";

const { FoxgloveClient } = wsProtocol;
const { parseRos2idl } = ros2idl;
const { MessageReader } = rosmsg2;

const rosDefinitions = process.argv[2] === "--ros-definitions";
const [url, countText, ...topics] = process.argv.slice(rosDefinitions ? 3 : 2);
const count = Number(countText);
if (!url || !(count > 0) || topics.length === 0) {
  console.error("usage: node foxglove_client.mjs URL COUNT TOPIC...");
  process.exit(2);
}

function fail(message) {
  console.error(`foxglove_client: ${message}`);
  process.exit(1);
}

function plain(value) {
  if (typeof value === "bigint") return Number(value);
  if (ArrayBuffer.isView(value)) {
    return value.length > 64 ? { bytes: value.length } : Array.from(value, plain);
  }
  if (Array.isArray(value)) return value.map(plain);
  if (value && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, plain(v)]));
  }
  return value;
}

// ROS 2 Humble's definition of `schemaName` ("nav_msgs/msg/Odometry") and of every type it
// uses, root first, as MessageReader takes them; null when it is not a standard type.
function humbleDefinitions(schemaName) {
  const all = rosCommon.ros2humble;
  const root = all[schemaName.replace("/msg/", "/")];
  if (!root) return null;
  const definitions = [root];
  const seen = new Set([root.name]);
  const visit = (definition) => {
    for (const field of definition.definitions) {
      if (!field.isComplex || seen.has(field.type)) continue;
      const used = all[field.type];
      if (!used) fail(`${schemaName}: ros2humble has no ${field.type}`);
      seen.add(field.type);
      definitions.push(used);
      visit(used);
    }
  };
  visit(root);
  return definitions;
}

const client = new FoxgloveClient({
  ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});
const bySubscription = new Map();
const received = new Map(topics.map((t) => [t, 0]));
let advertised = false;

const advertiseTimer = setTimeout(() => fail(`not advertised within 20 s: ${topics}`), 20000);
setTimeout(() => fail(`timed out; received ${JSON.stringify([...received])}`), 60000);

client.on("error", (error) => fail(`connection error: ${error?.message ?? error}`));
client.on("close", (event) => fail(`closed by the server: ${event.code} ${event.reason}`));
client.on("advertise", (channels) => {
  for (const channel of channels) {
    if (!topics.includes(channel.topic)) continue;
    if (channel.encoding !== "cdr" || channel.schemaEncoding !== "ros2idl") {
      fail(`${channel.topic}: encoding ${channel.encoding}, schema ${channel.schemaEncoding}`);
    }
    const humble = rosDefinitions ? humbleDefinitions(channel.schemaName) : null;
    const reader = new MessageReader(humble ?? parseRos2idl(channel.schema));
    const id = client.subscribe(channel.id);
    bySubscription.set(id, { channel, reader, decodedWith: humble ? "ros2humble" : "schema" });
  }
  if (bySubscription.size === topics.length && !advertised) {
    advertised = true;
    clearTimeout(advertiseTimer);
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const subscription = bySubscription.get(subscriptionId);
  if (!subscription) fail(`a message for unknown subscription ${subscriptionId}`);
  const topic = subscription.channel.topic;
  if (received.get(topic) >= count) return;
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  const message = subscription.reader.readMessage(bytes);
  console.log(
    JSON.stringify({
      topic,
      schemaName: subscription.channel.schemaName,
      decodedWith: subscription.decodedWith,
      message: plain(message),
    }),
  );
  received.set(topic, received.get(topic) + 1);
  if ([...received.values()].every((n) => n >= count)) process.exit(0);
});
