// Connects to the Foxglove bridge as a client of another library would (the `ws` package),
// with or without a token and TLS, and prints one JSON line of what happened:
//   {"opened": true, "op": "serverInfo", "name": ...}    the bridge accepted and spoke first
//   {"opened": false, "status": 401}                       refused during the HTTP upgrade
//   {"opened": false, "error": "..."}                      no connection (refused, TLS failure)
//
//   node secure_client.mjs URL [--bearer TOKEN] [--ca CERT.pem] [--origin ORIGIN] [--host HOST]
// --origin sends an Origin header, as a browser's page would (the library sends none by itself);
// --host replaces the Host header, as a page whose name was made to point here would send it.
// The token may also travel in URL (?token=...). Without --ca, TLS trusts only the system's
// CAs, so a self-signed certificate is refused.
import WebSocket from "ws";
import { readFileSync } from "node:fs";

const [url, ...rest] = process.argv.slice(2);
const options = { handshakeTimeout: 10000 };
options.headers = {};
for (let i = 0; i < rest.length; i += 2) {
  if (rest[i] === "--bearer") options.headers.Authorization = `Bearer ${rest[i + 1]}`;
  else if (rest[i] === "--ca") options.ca = readFileSync(rest[i + 1]);
  else if (rest[i] === "--origin") options.origin = rest[i + 1];
  else if (rest[i] === "--host") options.headers.Host = rest[i + 1];
  else throw new Error(`unknown option ${rest[i]}`);
}
const done = (result) => {
  console.log(JSON.stringify(result));
  process.exit(0);
};
const socket = new WebSocket(url, ["foxglove.websocket.v1"], options);
socket.on("unexpected-response", (request, response) => done({ opened: false, status: response.statusCode }));
socket.on("error", (error) => done({ opened: false, error: error.code ?? error.message }));
socket.on("message", (data) => {
  const message = JSON.parse(data.toString());
  done({ opened: true, op: message.op, name: message.name });
});
setTimeout(() => done({ opened: false, error: "timeout" }), 15000);
