// Which pages in a real browser may open a WebSocket on the bridge: Debian's chromium, headless,
// driven by playwright-core. Serves a page of its own on http://127.0.0.1:PAGE_PORT (another
// origin than the bridge's: a page any site could be) and, from it and from the bridge's own
// page, opens ws://127.0.0.1:BRIDGE_PORT/ with Foxglove's subprotocol. Prints one JSON line per
// page: {"page": ORIGIN, "opened": true|false}. Then asks the bridge for its page over plain
// HTTP with another Host header, as a page whose name was made to point here would, and prints
// {"host": HOST, "status": CODE}. Exit 0 once all are known.
//
//   node origin_check.mjs BRIDGE_PORT PAGE_PORT
import { chromium } from "playwright-core";
import { createServer, get } from "node:http";

const [bridgePort, pagePort] = process.argv.slice(2).map(Number);
const bridge = `ws://127.0.0.1:${bridgePort}/`;
const server = createServer((request, response) => {
  response.writeHead(200, { "Content-Type": "text/html" });
  response.end("<!doctype html><title>another page</title>");
});
await new Promise((resolve) => server.listen(pagePort, "127.0.0.1", resolve));

const browser = await chromium.launch({
  executablePath: process.env.MOCAP_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--disable-gpu"],
});
try {
  for (const url of [`http://127.0.0.1:${pagePort}/`, `http://127.0.0.1:${bridgePort}/`]) {
    const page = await browser.newPage();
    await page.goto(url);
    const opened = await page.evaluate(
      (address) =>
        new Promise((resolve) => {
          const socket = new WebSocket(address, ["foxglove.websocket.v1"]);
          socket.onopen = () => {
            socket.close();
            resolve(true);
          };
          socket.onerror = () => resolve(false);
          setTimeout(() => resolve(false), 10000);
        }),
      bridge,
    );
    console.log(JSON.stringify({ page: new URL(url).origin, opened }));
    await page.close();
  }
} finally {
  await browser.close();
  server.close();
}
const host = `attacker.example:${bridgePort}`;
const status = await new Promise((resolve, reject) =>
  get({ host: "127.0.0.1", port: bridgePort, path: "/", headers: { Host: host } }, (response) => {
    response.resume();
    resolve(response.statusCode);
  }).on("error", reject),
);
console.log(JSON.stringify({ host, status }));
