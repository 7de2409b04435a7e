// Clients that break the Foxglove WebSocket protocol, each on its own connection, against a
// running bridge: prints one line per case, "CASE: what happened", and exits 0 once all ended.
//
//   node bad_clients.mjs URL
import WebSocket from "ws";

const url = process.argv[2];
const subprotocol = "foxglove.websocket.v1";

// Opens a connection, runs `act` once open, and resolves with how it ended.
function attempt(name, protocols, act) {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, protocols);
    const timer = setTimeout(() => {
      ws.terminate();
      resolve(`${name}: still open after 10 s`);
    }, 10000);
    ws.on("unexpected-response", (_request, response) => {
      clearTimeout(timer);
      resolve(`${name}: HTTP ${response.statusCode}`);
    });
    ws.on("open", () => act(ws));
    ws.on("error", () => {});
    ws.on("close", (code, reason) => {
      clearTimeout(timer);
      resolve(`${name}: closed ${code} ${reason.toString()}`);
    });
  });
}

const results = await Promise.all([
  attempt("garbage", [subprotocol], (ws) => ws.send("{not json")),
  attempt("unknown_op", [subprotocol], (ws) => ws.send(JSON.stringify({ op: "explode" }))),
  attempt("binary", [subprotocol], (ws) => ws.send(Buffer.from([1, 0, 0, 0, 0, 42]))),
  attempt("wrong_subprotocol", ["chat"], () => {}),
  // Larger than the bridge takes from a client (1 MiB).
  attempt("oversize", [subprotocol], (ws) => ws.send("x".repeat((1 << 20) + 1024))),
  // Half a frame, then the connection is gone.
  attempt("half_message", [subprotocol], (ws) => {
    ws._socket.write(Buffer.from([0x81, 0x7e, 0x01]));  // a text frame header, cut short
    setTimeout(() => ws._socket.destroy(), 200);
  }),
]);
for (const line of results) console.log(line);
process.exit(0);
