// A VRPN tracker client written from VRPN's protocol description (vrpn/vrpn's
// Format_Of_Protocol.txt), with none of the server's code: it decodes what the server sends on
// its own. It connects as VRPN's client library does:
//   --tcp HOST PORT   straight to the server's TCP port ("Tracker0@tcp://HOST:PORT")
//   --lob HOST PORT   listens on a TCP port of its own and asks the server, in a UDP datagram
//                     "127.0.0.1 <its port>", to connect to it ("Tracker0@HOST")
// then exchanges cookies, describes its own ping type and the trackers it pings, pings each
// once, and prints one JSON line per event:
//   {"event": "cookie", "text": "vrpn: ver. 07.38  0"}
//   {"event": "pose", "tracker": NAME, "sec", "usec", "position": [x, y, z],
//    "quat": [x, y, z, w], "msSinceConnect"}
//   {"event": "velocity", "tracker", "sec", "usec", "velocity": [...], "quat": [...], "dt"}
//   {"event": "pong", "tracker": NAME}
// It exits 0 once it has COUNT poses of every TRACKER and a pong from each (COUNT 0: once the
// server's cookie has come); 1 on a timeout, a refused connection or a foreign cookie.
//
//   node vrpn_client.mjs (--tcp|--lob) HOST PORT COUNT TRACKER...
import net from "node:net";
import dgram from "node:dgram";

const [mode, host, portText, countText, ...trackers] = process.argv.slice(2);
const port = Number(portText);
const count = Number(countText);
if (!["--tcp", "--lob"].includes(mode) || !(port > 0) || !(count >= 0) || trackers.length === 0) {
  console.error("usage: node vrpn_client.mjs (--tcp|--lob) HOST PORT COUNT TRACKER...");
  process.exit(2);
}
const print = (object) => console.log(JSON.stringify(object));
setTimeout(() => {
  console.error(`vrpn_client: timed out; poses ${JSON.stringify(poses)}, pongs ${[...pongs]}`);
  process.exit(1);
}, 30000);

// --- framing, written out from the protocol description ---------------------------------
const COOKIE = Buffer.alloc(24);
COOKIE.write("vrpn: ver. 07.38  0", "latin1");
const padded = (n) => Math.ceil(n / 8) * 8;

function message(sender, type, payload) {
  const out = Buffer.alloc(24 + padded(payload.length));
  out.writeUInt32BE(24 + payload.length, 0);
  const now = Date.now();
  out.writeUInt32BE(Math.floor(now / 1000), 4);
  out.writeUInt32BE((now % 1000) * 1000, 8);
  out.writeInt32BE(sender, 12);
  out.writeInt32BE(type, 16);
  out.writeUInt32BE(0, 20);
  payload.copy(out, 24);
  return out;
}

function describing(kind, id, name) {
  const payload = Buffer.alloc(4 + name.length + 1);
  payload.writeUInt32BE(name.length + 1, 0);
  payload.write(name, 4, "latin1");
  return message(id, kind, payload);
}

// --- the session ---------------------------------------------------------------------------
const senders = new Map();  // the server's sender id -> name
const types = new Map();    // the server's type id -> name
const poses = Object.fromEntries(trackers.map((t) => [t, 0]));
const pongs = new Set();
let connectedAt = 0;
let input = Buffer.alloc(0);
let cookieSeen = false;

function finishedAll() {
  return trackers.every((t) => poses[t] >= count && pongs.has(t));
}

function onMessage(sender, type, sec, usec, payload) {
  if (type === -1 || type === -2) {
    const length = payload.readUInt32BE(0);
    const name = payload.toString("latin1", 4, 4 + length - 1);
    (type === -1 ? senders : types).set(sender, name);
    return;
  }
  const tracker = senders.get(sender);
  const typeName = types.get(type);
  if (typeName === "vrpn_Tracker Pos_Quat") {
    const d = (i) => payload.readDoubleBE(8 + 8 * i);
    print({ event: "pose", tracker, sensor: payload.readInt32BE(0), sec, usec,
            position: [d(0), d(1), d(2)], quat: [d(3), d(4), d(5), d(6)],
            msSinceConnect: Date.now() - connectedAt });
    if (tracker in poses) poses[tracker] += 1;
  } else if (typeName === "vrpn_Tracker Velocity") {
    const d = (i) => payload.readDoubleBE(8 + 8 * i);
    print({ event: "velocity", tracker, sec, usec, velocity: [d(0), d(1), d(2)],
            quat: [d(3), d(4), d(5), d(6)], dt: d(7) });
  } else if (typeName === "vrpn_Base pong_message") {
    print({ event: "pong", tracker });
    pongs.add(tracker);
  }
}

function session(socket) {
  connectedAt = Date.now();
  socket.setNoDelay(true);
  socket.write(COOKIE);
  // Our own numbering: type 0 is the ping; sender i is trackers[i].
  socket.write(describing(-2, 0, "vrpn_Base ping_message"));
  trackers.forEach((name, i) => socket.write(describing(-1, i, name)));
  trackers.forEach((name, i) => socket.write(message(i, 0, Buffer.alloc(0))));
  socket.on("data", (chunk) => {
    input = Buffer.concat([input, chunk]);
    if (!cookieSeen) {
      if (input.length < 24) return;
      const text = input.toString("latin1", 0, 24).replace(/\0+$/, "");
      if (!text.startsWith("vrpn: ver. 07.")) {
        console.error(`vrpn_client: not a VRPN cookie: ${JSON.stringify(text)}`);
        process.exit(1);
      }
      print({ event: "cookie", text });
      if (count === 0) process.exit(0);
      cookieSeen = true;
      input = input.subarray(24);
    }
    while (input.length >= 24) {
      const length = input.readUInt32BE(0);
      const whole = 24 + padded(length - 24);
      if (input.length < whole) break;
      onMessage(input.readInt32BE(12), input.readInt32BE(16), input.readUInt32BE(4),
                input.readUInt32BE(8), input.subarray(24, length));
      input = input.subarray(whole);
    }
    if (finishedAll()) {
      socket.end();
      process.exit(0);
    }
  });
  socket.on("error", (error) => {
    console.error(`vrpn_client: ${error.code ?? error.message}`);
    process.exit(1);
  });
  socket.on("close", () => {
    console.error("vrpn_client: the server closed the connection");
    process.exit(1);
  });
}

if (mode === "--tcp") {
  const socket = net.connect(port, host, () => session(socket));
  socket.on("error", (error) => {
    console.error(`vrpn_client: ${error.code ?? error.message}`);
    process.exit(1);
  });
} else {
  const listener = net.createServer((socket) => {
    listener.close();
    session(socket);
  });
  listener.listen(0, "127.0.0.1", () => {
    const request = Buffer.from(`127.0.0.1 ${listener.address().port}\0`, "latin1");
    const udp = dgram.createSocket("udp4");
    udp.send(request, port, host, () => udp.close());
  });
}
