// Image-to-browser latency: the built-in viewer in headless chromium for SECONDS, then each
// drawn camera image's age when it was drawn (page clock minus the image's capture stamp; one
// machine, one clock). Prints "frames N median M p95 P" (ms).
//
//   node browser_latency.mjs URL SECONDS
import { chromium } from "playwright-core";

const [url, seconds] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.MOCAP_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--disable-gpu"],
});
const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
await page.goto(url);
await page.waitForFunction(() => window.viewerState?.images > 0, null, { timeout: 30000 });
await page.evaluate(() => (window.viewerState.drawLatenciesMs.length = 0));
await page.waitForTimeout(Number(seconds) * 1000);
const latencies = (await page.evaluate(() => window.viewerState.drawLatenciesMs)).sort((a, b) => a - b);
const at = (q) => latencies[Math.min(latencies.length - 1, Math.floor(q * latencies.length))];
console.log(`frames ${latencies.length} median ${at(0.5)?.toFixed(1)} p95 ${at(0.95)?.toFixed(1)}`);
await browser.close();
