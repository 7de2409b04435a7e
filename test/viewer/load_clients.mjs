// Load on the bridge: N well-behaved clients at once, each subscribed to TOPIC until it has
// COUNT messages, beside one client that subscribes to every topic and then never reads (its
// socket paused). Prints "clients: K of N received COUNT" when the well-behaved ones are done.
// Then it waits for FLAG_FILE (the test makes it once the bridge says it dropped the stalled
// client), reads again and prints how the stalled connection ended: "stalled: closed CODE" (or
// "stalled: still open"). Exit 0 when all N received their messages.
//
//   node load_clients.mjs URL N COUNT TOPIC FLAG_FILE
import wsProtocol from "@foxglove/ws-protocol";
import { existsSync } from "node:fs";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, nText, countText, topic, flagFile] = process.argv.slice(2);
const n = Number(nText);
const count = Number(countText);

function wellBehaved() {
  return new Promise((resolve) => {
    const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    let received = 0;
    const timer = setTimeout(() => resolve(false), 60000);
    client.on("advertise", (channels) => {
      const channel = channels.find((c) => c.topic === topic);
      if (channel) client.subscribe(channel.id);
    });
    client.on("message", () => {
      if (++received === count) {
        clearTimeout(timer);
        client.close();
        resolve(true);
      }
    });
  });
}

let stalledSocket = null;
let stalledEnd = null;
const stalledClosed = new Promise((resolve) => (stalledEnd = resolve));
const ws = new WebSocket(url, ["foxglove.websocket.v1"]);
ws.on("message", (data, binary) => {
  if (binary) return;
  const message = JSON.parse(data.toString());
  if (message.op !== "advertise") return;
  const subscriptions = message.channels.map((c, k) => ({ id: k + 1, channelId: c.id }));
  ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
  setTimeout(() => {
    // From now on nothing is read (ws would resume a merely paused socket).
    stalledSocket = ws._socket;
    stalledSocket.removeAllListeners("data");
    stalledSocket.pause();
  }, 100);
});
ws.on("close", (code) => stalledEnd(`stalled: closed ${code}`));
ws.on("error", () => {});

const results = await Promise.all(Array.from({ length: n }, wellBehaved));
const ok = results.filter(Boolean).length;
console.log(`clients: ${ok} of ${n} received ${count}`);
const deadline = Date.now() + 90000;
while (!existsSync(flagFile) && Date.now() < deadline) await new Promise((r) => setTimeout(r, 100));
// Read (and discard) what is left: the end of the connection comes after it.
stalledSocket?.on("data", () => {});
stalledSocket?.resume();
setTimeout(() => stalledEnd("stalled: still open"), 10000);
console.log(await stalledClosed);
process.exit(ok === n ? 0 : 1);
