// N clients of the bridge that subscribe to every topic but the overlay images and read
// everything, until killed (the benchmark's load). Prints "N clients connected".
//
//   node stream_clients.mjs URL N
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const [url, nText] = process.argv.slice(2);
let connected = 0;
for (let k = 0; k < Number(nText); k++) {
  const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  client.on("advertise", (channels) => {
    for (const c of channels) if (c.topic !== "/mocap/overlay") client.subscribe(c.id);
    if (++connected === Number(nText)) console.log(`${connected} clients connected`);
  });
  client.on("message", () => {});
}
