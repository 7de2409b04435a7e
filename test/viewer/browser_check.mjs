// The built-in viewer in a real browser: Debian's chromium, headless, driven by playwright-core
// (nothing downloaded). Opens http://HOST:PORT/, waits for camera frames, checks that the
// overlay draws as many fiducial circles as the tracker found, each pose's axes and the
// turret's angles, and that the pose readout changes, saves a screenshot. With --outage FLAG_FILE it also checks the disconnected state:
// it prints "WAITING_FOR_STOP", the test stops the bridge, the page must say it is gone; it
// prints "WAITING_FOR_START", the test starts the bridge again and creates FLAG_FILE, and the
// page must reconnect and draw new frames. With --floor (a PixArt graph, no camera) it checks
// the floor instead: the ceiling cameras' footprints and the robots drawn. With --refused (a
// bridge asking for a token the URL lacks) it checks that the page says it is disconnected;
// with --tf (a bridge offering /tf but not /mocap/poses), that the top view draws the boards;
// with --volume (a volume of cameras), every camera's image with its fiducials and the volume
// from above with the cameras, their views and the bodies, and every status of /diagnostics OK;
// with --swarm COUNT (a volume whose
// cameras send centroids), the volume from above with its cameras from /tf, COUNT robots and
// at least as many markers of the cloud, and no camera panel.
// HTTPS certificates are not checked (the TLS test's is self-signed). One line per check; exit 0
// when all passed.
//
//   node browser_check.mjs URL SCREENSHOT [--outage FLAG_FILE | --floor | --refused | --tf |
//                                          --volume | --swarm COUNT]
import { chromium } from "playwright-core";
import { existsSync } from "node:fs";

const [url, screenshot, mode, flagFile] = process.argv.slice(2);
const browser = await chromium.launch({
  executablePath: process.env.MOCAP_CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--disable-gpu"],
});
let failed = false;
function check(ok, line) {
  console.log(`${ok ? "PASS" : "FAIL"} ${line}`);
  if (!ok) failed = true;
}
const state = (page) => page.evaluate(() => ({ ...window.viewerState }));
// Waits until `condition(viewerState)` holds and returns the state of that very moment.
// On a timeout the error carries the page's state, so that a failure says what was missing.
const snapshot = async (page, condition, timeout) => {
  try {
    const handle = await page.waitForFunction(
      (source) => {
        const s = window.viewerState;
        return new Function("s", `return (${source})(s)`)(s) ? { ...s } : null;
      },
      condition.toString(),
      { timeout },
    );
    return handle.jsonValue();
  } catch (error) {
    const { drawLatenciesMs, ...s } = (await state(page).catch(() => ({}))) ?? {};
    throw new Error(`${error.message.split("\n")[0]} waiting for ${condition}; the page's state: ${JSON.stringify(s)}`);
  }
};

try {
  // The TLS test's certificate is self-signed.
  const page = await browser.newPage({ viewport: { width: 1600, height: 1000 }, ignoreHTTPSErrors: true });
  const errors = [];
  page.on("pageerror", (error) => errors.push(error.message));
  await page.goto(url);
  if (mode === "--volume") {
    const cameras = (s) => Object.keys(s.volumeImagesDrawn);
    const seen = await snapshot(page, (s) => Object.keys(s?.volumeImagesDrawn ?? {}).length >= 4 &&
      Object.values(s.volumeImagesDrawn).every((n) => n >= 5) &&
      Object.values(s.volumeCirclesDrawn).every((n) => n > 0) &&
      s.volumeConesDrawn >= 4 && s.volumeBodiesDrawn >= 4, 90000);
    check(true, `volume cameras: ${cameras(seen).sort().map((c) => `${c} ${seen.volumeImagesDrawn[c]} images, ` +
      `${seen.volumeCirclesDrawn[c]} fiducials`).join("; ")}`);
    check(true, `from above: ${seen.volumeConesDrawn} cameras with their views, ${seen.volumeBodiesDrawn} bodies`);
    check(await page.isHidden("#camera-section"), "the single camera's panel is hidden");
    // The health panel: every process and component of the demo (5 processes, 17 components
    // with their diagnostics), all OK.
    const healthy = await snapshot(page, (s) => Object.keys(s?.healthRows ?? {}).length >= 22 &&
      Object.values(s.healthRows).every((level) => level === "OK"), 30000);
    check(true, `health: ${Object.keys(healthy.healthRows).length} statuses, all OK`);
    await page.waitForTimeout(1000);
    await page.screenshot({ path: screenshot, fullPage: true });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--swarm") {
    const count = Number(flagFile);
    const seen = await snapshot(page, new Function("s", `return s?.volumeBodiesDrawn >= ${count} && ` +
      `s.volumeMarkersDrawn >= ${count} && s.volumeCamerasDrawn >= 8;`), 90000);
    check(true, `from above: ${seen.volumeCamerasDrawn} cameras from /tf, ${seen.volumeBodiesDrawn} robots, ` +
      `${seen.volumeMarkersDrawn} markers of the cloud`);
    check(await page.isHidden("#camera-section"), "the single camera's panel is hidden");
    check(!(await page.isHidden("#volume")), "the volume's panel is shown");
    await page.waitForTimeout(1000);
    // The view's first screen: the volume from above and the first robots of the table.
    await page.screenshot({ path: screenshot });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--tf") {
    // A bridge offering /tf but not /mocap/poses: the top view draws the boards from tf2.
    const seen = await snapshot(page, (s) => s?.transformsUsed >= 30 && s.boardsOnTop > 0, 90000);
    check(true, `top view: ${seen.boardsOnTop} board(s) from ${seen.transformsUsed} /tf transforms`);
    check(seen.poseReadout === "", "no /mocap/poses reached the page");
    await page.screenshot({ path: screenshot, fullPage: true });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--refused") {
    // Served the page, refused the WebSocket (no token): the page must say so, and draw nothing.
    await page.waitForFunction(() => /disconnected/.test(document.querySelector("#status")?.textContent ?? ""),
      null, { timeout: 30000 });
    const text = await page.textContent("#status");
    check(!text.includes("token"), "the status line does not show a token");
    check(!(await state(page)).connected, `the page without the token says: ${text.split(":")[0]}`);
    await page.screenshot({ path: screenshot, fullPage: true });
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--floor") {
    await page.waitForFunction(() => window.viewerState?.footprintsDrawn > 0 && window.viewerState.robotsDrawn > 0,
      null, { timeout: 90000 });
    await page.waitForTimeout(1000);
    const floor = await state(page);
    check(true, `floor: ${floor.footprintsDrawn} footprints, ${floor.robotsDrawn} robots`);
    check(/no sensor_msgs\/msg\/Image/.test(await page.textContent("#camera-note")), "the page says there is no camera");
    await page.screenshot({ path: screenshot, fullPage: true });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  // The state as the condition saw it: a new frame may be drawn before its fiducials arrive.
  const first = await snapshot(page, (s) => s?.images >= 5 && s.fiducialsInFrame > 0, 90000);
  check(first.connected, `connected to ${first.server}`);
  check(first.circlesDrawn === first.fiducialsInFrame && first.circlesDrawn > 0,
    `${first.circlesDrawn} circles drawn for the ${first.fiducialsInFrame} fiducials of frame ${first.frameStamp}`);
  await page.waitForTimeout(1500);
  const later = await state(page);
  check(later.poseReadout !== "" && later.poseReadout !== first.poseReadout,
    `the pose readout changes (${JSON.stringify(later.poseReadout.slice(0, 60))}...)`);
  check(later.circlesDrawn === later.fiducialsInFrame,
    `${later.circlesDrawn} circles for ${later.fiducialsInFrame} fiducials, ${later.images - first.images} frames later`);
  // Shown, not bounded: the age depends on the machine's load (bench/viewer_bench.sh measures it).
  // Not negative: capture stamp and the bridge's receive time are on the graph's clock.
  check(Number.isFinite(later.latencyMs) && later.latencyMs >= 0,
    `pose latency shown at the page (capture to bridge): ${later.latencyMs?.toFixed(1)} ms`);
  // The walking board may be out of view for a while: wait for a frame that shows it.
  const axes = await snapshot(page, (s) => s.axesDrawn > 0, 60000).catch(() => state(page));
  check(axes.axesDrawn > 0 && axes.axesDrawn === axes.posesInFrame,
    `axes of ${axes.axesDrawn} of the ${axes.posesInFrame} pose(s) of frame ${axes.frameStamp} reprojected with camera_info`);
  const turret = await page.textContent("#turret");
  check(/pan -?\d+\.\d°/.test(turret), `the turret readout: ${turret}`);
  await page.screenshot({ path: screenshot, fullPage: true });
  console.log(`screenshot ${screenshot}`);

  if (mode === "--outage") {
    console.log("WAITING_FOR_STOP");
    await page.waitForFunction(() => !window.viewerState.connected, null, { timeout: 90000 });
    const text = await page.textContent("#status");
    check(/disconnected/.test(text), `the page says: ${text}`);
    console.log("WAITING_FOR_START");
    const deadline = Date.now() + 60000;
    while (!existsSync(flagFile) && Date.now() < deadline) await new Promise((r) => setTimeout(r, 100));
    const before = (await state(page)).images;
    await page.waitForFunction((n) => window.viewerState.connected && window.viewerState.images > n + 3,
      before, { timeout: 90000 });
    check(true, `reconnected: ${await page.textContent("#status")}`);
  }
  check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
} catch (error) {
  check(false, error.message.split("\n")[0]);
}
await browser.close();
process.exit(failed ? 1 : 0);
