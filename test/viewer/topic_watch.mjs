// Watches one topic come and go on a bridge with @foxglove/ws-protocol's client, nothing of
// ours: prints "CONNECTED" once the server's first frames arrived, "ADVERTISED TOPIC SCHEMA"
// when the topic is advertised, "MESSAGE TOPIC {json}" for its first message (decoded with
// @foxglove/rosmsg2-serialization from the advertised schema) and "UNADVERTISED TOPIC" when it
// is withdrawn; then exits 0. Exits 1 with one line on stderr after 120 s or if the server
// closes the connection.
//
//   node topic_watch.mjs URL TOPIC
import wsProtocol from "@foxglove/ws-protocol";
import ros2idl from "@foxglove/ros2idl-parser";
import rosmsg2 from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, topic] = process.argv.slice(2);
if (!url || !topic) {
  console.error("usage: node topic_watch.mjs URL TOPIC");
  process.exit(2);
}
const fail = (message) => {
  console.error(`topic_watch: ${message}`);
  process.exit(1);
};
setTimeout(() => fail("timed out after 120 s"), 120000);

const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
let channel = null;
let reader = null;
let subscription = null;
let messages = 0;
client.on("error", (error) => fail(`connection error: ${error?.message ?? error}`));
client.on("close", (event) => fail(`closed by the server: ${event.code} ${event.reason}`));
client.on("serverInfo", () => console.log("CONNECTED"));
client.on("advertise", (channels) => {
  for (const c of channels) {
    if (c.topic !== topic) continue;
    channel = c;
    reader = new rosmsg2.MessageReader(ros2idl.parseRos2idl(c.schema));
    subscription = client.subscribe(c.id);
    console.log(`ADVERTISED ${topic} ${c.schemaName}`);
  }
});
client.on("message", ({ subscriptionId, data }) => {
  if (subscriptionId !== subscription || messages++ > 0) return;
  const message = reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  const plain = JSON.stringify(message, (_key, value) => (typeof value === "bigint" ? Number(value) : value));
  console.log(`MESSAGE ${topic} ${plain}`);
});
client.on("unadvertise", (ids) => {
  if (!channel || !ids.includes(channel.id)) return;
  console.log(`UNADVERTISED ${topic}`);
  process.exit(messages > 0 ? 0 : 1);
});
