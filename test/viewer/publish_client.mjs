// Publishes into a graph through a bridge with client_publish on, as Foxglove's teleop panel
// does, with @foxglove/ws-protocol's client and @foxglove/rosmsg2-serialization's writer:
//  - advertises TOPIC as geometry_msgs/msg/Twist (CDR) and sends a Twist with linear.x = VALUE
//    every 100 ms, the CDR written from the schema the bridge advertised for that type;
//  - advertises REFUSED_TOPIC, which the bridge must refuse with a status message;
//  - on another connection, sends Message Data on a channel it never advertised, which must
//    close that connection with the reason.
// Prints "SERVER capabilities=..", "STATUS level message", "PUBLISHING", "UNADVERTISED_CHANNEL:
// closed CODE REASON". Runs until killed, or exits 1 with a line on stderr.
//
//   node publish_client.mjs URL TOPIC VALUE REFUSED_TOPIC
import wsProtocol from "@foxglove/ws-protocol";
import ros2idl from "@foxglove/ros2idl-parser";
import rosmsg2 from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, topic, valueText, refusedTopic] = process.argv.slice(2);
if (!url || !topic || !valueText || !refusedTopic) {
  console.error("usage: node publish_client.mjs URL TOPIC VALUE REFUSED_TOPIC");
  process.exit(2);
}
const fail = (message) => {
  console.error(`publish_client: ${message}`);
  process.exit(1);
};
const TWIST = "geometry_msgs/msg/Twist";

const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
client.on("error", (error) => fail(`connection error: ${error?.message ?? error}`));
client.on("close", (event) => fail(`closed by the server: ${event.code} ${event.reason}`));
client.on("status", (status) => console.log(`STATUS ${status.level} ${status.message}`));
let started = false;
client.on("serverInfo", (info) => {
  console.log(`SERVER capabilities=${info.capabilities.join(",")} encodings=${(info.supportedEncodings ?? []).join(",")}`);
  if (!info.capabilities.includes("clientPublish")) fail("the server does not offer clientPublish");
});
client.on("advertise", (channels) => {
  const twist = channels.find((c) => c.schemaName === TWIST);
  if (!twist || started) return;
  started = true;
  const writer = new rosmsg2.MessageWriter(ros2idl.parseRos2idl(twist.schema));
  const id = client.advertise({ topic, encoding: "cdr", schemaName: TWIST });
  client.advertise({ topic: refusedTopic, encoding: "cdr", schemaName: TWIST });
  const x = Number(valueText);
  const bytes = writer.writeMessage({ linear: { x, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0.25 } });
  console.log("PUBLISHING");
  setInterval(() => client.sendMessage(id, bytes), 100);
});

// A client that sends Message Data on a channel it never advertised.
const rogue = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
rogue.on("open", () => rogue.send(Buffer.from([0x01, 99, 0, 0, 0, 1, 2, 3, 4])));
rogue.on("error", () => {});
rogue.on("close", (code, reason) => console.log(`UNADVERTISED_CHANNEL: closed ${code} ${reason.toString()}`));
