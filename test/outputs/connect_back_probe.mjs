// Both ends of a VRPN UDP connection request, for the test of where the server connects back:
//   listen PORT SECONDS        accepts TCP connections on PORT for SECONDS (answering nothing),
//                              then prints {"connections": N, "from": [ADDRESS...]}
//   lob HOST PORT TEXT COUNT   sends COUNT datagrams "TEXT" with a NUL, as VRPN's client does,
//                              200 ms apart, to HOST:PORT
import net from "node:net";
import dgram from "node:dgram";

const [mode, ...args] = process.argv.slice(2);
if (mode === "listen") {
  const [port, seconds] = args.map(Number);
  const from = [];
  const sockets = [];
  const server = net.createServer((socket) => {
    from.push(socket.remoteAddress.replace(/^::ffff:/, ""));
    sockets.push(socket);
  });
  server.listen(port, "0.0.0.0", () => {
    setTimeout(() => {
      console.log(JSON.stringify({ connections: from.length, from }));
      for (const socket of sockets) socket.destroy();
      server.close();
    }, seconds * 1000);
  });
} else if (mode === "lob") {
  const [host, port, text, count] = args;
  const socket = dgram.createSocket("udp4");
  for (let i = 0; i < Number(count); ++i) {
    await new Promise((resolve) => socket.send(Buffer.from(`${text}\0`), Number(port), host, resolve));
    await new Promise((resolve) => setTimeout(resolve, 200));
  }
  socket.close();
} else {
  console.error("usage: node connect_back_probe.mjs listen PORT SECONDS | lob HOST PORT TEXT COUNT");
  process.exit(2);
}
