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
// and, given SCREENSHOT_3D, the volume in 3D with its cameras and bodies (saved there);
// with --swarm COUNT (a volume whose
// cameras send centroids), the volume from above with its cameras from /tf, COUNT robots and
// at least as many markers of the cloud, and no camera panel. With --view3d COUNT (the same
// volume), the volume in 3D (view3d.js): its 8 cameras, COUNT robots and the marker cloud drawn
// (the page's counters, and the WebGL canvas's pixels where a camera and a robot project),
// orbit and zoom by the mouse, a click on a robot showing its figures, a double click following
// it, each frame's drawing time over 10 s ("PASS 3D: ... median X ms p99 Y ms over N frames";
// FAIL when fewer than 5 frames were drawn; bench/viewer_3d_bench.sh holds the median to 33 ms),
// a screenshot of the 3D panel, and the page without WebGL. With
// --view3d-tf COUNT (a volume whose bridge offers /tf but not /mocap/poses, as a ROS 2 graph's
// would), the 3D view's cameras and COUNT bodies drawn from /tf. With --coverage COUNT (a
// calibration session), COUNT cameras' coverage with their regions and bars, growing. With
// --calibration-result COUNT (a calibration's solve), its report of COUNT cameras: the cameras'
// and the floor's tables, the picture from above, and one line per figure as the page shows it,
// "PAGE " and the line mocap_volume_calibrate prints (without its camera file), for the test to
// compare with the tool's report; the screenshot holds the coverage and the solve.
// HTTPS certificates are not checked (the TLS test's is self-signed). One line per check; exit 0
// when all passed.
//
//   node browser_check.mjs URL SCREENSHOT [--outage FLAG_FILE | --floor | --refused | --tf |
//                                          --volume [SCREENSHOT_3D] | --swarm COUNT |
//                                          --view3d COUNT | --view3d-tf COUNT | --coverage COUNT |
//                                          --calibration-result COUNT]
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

const quantile = (values, q) => [...values].sort((a, b) => a - b)[Math.min(values.length - 1, Math.floor(q * values.length))];

// The --view3d checks, on a page showing a swarm of `count` robots.
async function view3d(page, count, errors) {
  const seen = await snapshot(page, new Function("s", `return s?.view3dCamerasDrawn >= 8 && ` +
    `s.view3dBodiesDrawn + s.view3dRobotsDrawn >= ${count} && s.view3dMarkersDrawn >= ${count};`), 90000);
  check(true, `3D: ${seen.view3dCamerasDrawn} cameras as frusta (${JSON.stringify(seen.view3dCamerasByLevel)}), ` +
    `${seen.view3dBodiesDrawn} robots with their axes and ${seen.view3dRobotsDrawn} single-marker robots ` +
    `from ${seen.view3dBodiesFrom}, ${seen.view3dMarkersDrawn} markers (${seen.view3dLabeledMarkers} labeled), ` +
    `${seen.view3dTrailSegments} trail segments, ${seen.view3dLabelsDrawn} labels`);
  const where = await state(page);
  const inside = (p) => p && p[0] > 30 && p[1] > 30 && p[0] < where.view3dCanvas[0] - 30 && p[1] < where.view3dCanvas[1] - 30;
  // What the WebGL canvas holds where a camera and a robot project (a frame drawn for the probe).
  for (const kind of ["cameras", "bodies"]) {
    const name = Object.keys(where.view3dScreen[kind]).find((n) => inside(where.view3dScreen[kind][n]));
    const probe = name && (await page.evaluate((n) => window.view3dProbe.drawnAround(n, 6), name));
    check(probe?.drawn > 0, `pixels drawn where ${kind === "cameras" ? "camera" : "robot"} ${name} projects: ` +
      `${probe?.drawn} of ${probe?.total} around it, ${probe?.frameDrawn} of the frame's ${probe?.frameTotal}`);
  }

  // Each frame's drawing over 10 s of the swarm's data, at the view's first look.
  await page.evaluate(() => (window.viewerState.view3dDrawMs.length = 0));
  const frames0 = (await state(page)).view3dFrames;
  await page.waitForTimeout(10000);
  const timed = await state(page);
  const times = timed.view3dDrawMs;
  const size = timed.view3dBuffer;
  const line = `3D: a frame drawn in median ${quantile(times, 0.5)?.toFixed(1)} ms p99 ${quantile(times, 0.99)?.toFixed(1)} ms ` +
    `over ${times.length} frames (${timed.view3dFrames - frames0} in 10 s) at ${size[0]}x${size[1]}, ` +
    `${timed.view3dRenderer}`;
  // Measured, not held to the 33 ms target here (a test does not depend on timing):
  // bench/viewer_3d_bench.sh holds it on a quiet machine.
  check(times.length >= 5, line);

  // Orbit (left drag) and zoom (wheel) move the eye.
  const canvas = await page.locator("#view3d").boundingBox();
  const cx = canvas.x + canvas.width / 2;
  const cy = canvas.y + canvas.height / 2;
  const before = (await state(page)).view3dEye;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await page.mouse.move(cx + 160, cy + 40, { steps: 8 });
  await page.mouse.up();
  const orbited = await snapshot(page, new Function("s", `return s.view3dEye.azimuthDeg !== ${before.azimuthDeg};`), 5000);
  check(Math.abs(orbited.view3dEye.azimuthDeg - before.azimuthDeg) > 10 && orbited.view3dEye.elevationDeg !== before.elevationDeg,
    `orbit by dragging: azimuth ${before.azimuthDeg.toFixed(0)}° -> ${orbited.view3dEye.azimuthDeg.toFixed(0)}°, ` +
    `elevation ${before.elevationDeg.toFixed(0)}° -> ${orbited.view3dEye.elevationDeg.toFixed(0)}°`);
  await page.mouse.wheel(0, -500);
  const zoomed = await snapshot(page, new Function("s", `return s.view3dEye.distanceM < ${orbited.view3dEye.distanceM};`), 5000);
  check(true, `zoom by the wheel: ${orbited.view3dEye.distanceM.toFixed(1)} m -> ${zoomed.view3dEye.distanceM.toFixed(1)} m`);
  await page.mouse.click(cx, cy, { button: "right" });  // a right click is no pick
  await page.click("#view3d-home");

  // A click on a robot shows its figures; a double click follows it.
  let clicked = null;
  for (let attempt = 0; attempt < 5 && !clicked; attempt++) {
    await page.waitForTimeout(300);
    const s = await state(page);
    const name = Object.keys(s.view3dScreen.bodies).find((n) => inside(s.view3dScreen.bodies[n]));
    if (!name) continue;
    const [x, y] = s.view3dScreen.bodies[name];
    await page.mouse.click(canvas.x + x, canvas.y + y);
    clicked = await snapshot(page, (v) => v.view3dSelected !== "", 3000).catch(() => null);
  }
  const boxText = clicked ? await page.textContent("#view3d-box") : "";
  check(clicked && (await page.isVisible("#view3d-box")) && boxText.includes(clicked.view3dSelected) &&
    /cameras\s*\d/.test(boxText) && /px rms/.test(boxText),
    `a click on ${clicked?.view3dSelected} shows its figures: ${boxText.replace(/\s+/g, " ").trim()}`);
  await page.waitForTimeout(500);
  // A page on busy cores can take long to settle for its picture.
  await page.locator("#view3d-section").screenshot({ path: screenshot, timeout: 90000 });
  console.log(`screenshot ${screenshot}`);
  if (clicked) {
    // Where the robot is drawn now: it flies on while the screenshot is taken, and on busy cores
    // a frame may come between reading its place and the double click (tried again, as above).
    let followed = null;
    for (let attempt = 0; attempt < 5 && !followed; attempt++) {
      const at = (await state(page)).view3dScreen.bodies[clicked.view3dSelected];
      if (!at) {
        await page.waitForTimeout(300);
        continue;
      }
      await page.mouse.dblclick(canvas.x + at[0], canvas.y + at[1]);
      followed = await snapshot(page, (v) => v.view3dFollowing !== "", 3000).catch(() => null);
    }
    check(followed !== null, `a double click follows ${followed?.view3dFollowing || "nothing"}`);
  }
  check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);

  // A browser without WebGL: the page says so in the panel and draws the rest.
  const plain = await chromium.launch({
    executablePath: process.env.MOCAP_CHROMIUM ?? "/usr/bin/chromium",
    args: ["--no-sandbox", "--disable-gpu", "--disable-3d-apis"],
  });
  try {
    const other = await plain.newPage({ viewport: { width: 1600, height: 1000 } });
    const otherErrors = [];
    other.on("pageerror", (error) => otherErrors.push(error.message));
    await other.goto(url);
    const without = await snapshot(other, new Function("s", `return s?.volumeCamerasDrawn >= 8 && s.volumeBodiesDrawn >= ${count};`), 60000);
    const text = await other.textContent("#view3d-note");
    check(without.view3d === "needs WebGL" && /needs WebGL/.test(text) && otherErrors.length === 0,
      `without WebGL: "${text.split(",")[0]}", the volume from above still drawn (${without.volumeBodiesDrawn} robots)` +
      `${otherErrors.length ? "; page errors: " + otherErrors.join("; ") : ""}`);
  } finally {
    await plain.close();
  }
}

// The text of each row's cells of the table `id`.
const tableCells = (page, id) => page.locator(`#${id} tbody tr`).evaluateAll((rows) =>
  rows.map((row) => [...row.cells].map((cell) => cell.textContent.trim())));

// The --calibration-result checks, on a page showing a calibration's solve of `count` cameras.
// Its report's lines are made of what the page shows (the summary, the tables' cells) in the
// words of calibration_session.cpp's report_lines().
async function calibrationResult(page, count, errors) {
  // Recording the sessions and solving them take a while (the page may open before the solve).
  const seen = await snapshot(page, new Function("s", `return s?.resultCameras.length >= ${count} && ` +
    `s.calibrationPictureDrawn >= ${count};`), 180000);
  // The report comes out before the solve says it is done.
  const done = await snapshot(page, (s) => s.solveStage === "done", 10000).catch(() => state(page));
  check(done.solveStage === "done" && done.solveProgress === 1, `the solve: ${done.solveStage} ` +
    `${(100 * done.solveProgress).toFixed(0)} %: ${done.solveDetail}`);
  const cameras = await tableCells(page, "result-cameras");
  const floor = await tableCells(page, "result-floor");
  check(cameras.length === count && floor.length === seen.resultFloor.length && floor.length > 0,
    `the report: ${cameras.length} camera rows, ${floor.length} floor rows`);
  check(seen.calibrationPictureDrawn === count, `the picture from above: ${seen.calibrationPictureDrawn} cameras drawn`);

  const summaryText = await page.textContent("#result-summary");
  const summary = summaryText.match(/^(\d+) capture times, RMS (\S+) px over (\d+) points, (\d+) iterations$/);
  check(summary !== null, `the summary: ${summaryText}`);
  if (summary) {
    const [, frames, rms, points, iterations] = summary;
    console.log(`PAGE waved: ${frames} capture times; RMS ${rms} px over ${points} points (${iterations} iterations)`);
  }
  for (const [mark, seenBy, rms, offMark] of floor) {
    const off = offMark ? `; ${offMark} mm from its mark` : "";
    console.log(`PAGE floor at ${mark}: the board seen by ${seenBy} cameras, RMS ${rms} px${off}`);
  }
  for (const [name, rms, , x, y, z, moved, turned] of cameras) {
    const against = moved ? `; ${moved} mm and ${turned} deg from the input file's pose` : "";
    console.log(`PAGE ${name}: at (${x}, ${y}, ${z}) m${against}, RMS ${rms} px`);
  }
  check(cameras.length === count && seen.calibrationPictureDrawn === count && summary !== null,
    `calibration result: ${count} cameras`);

  // The calibration's sections in one picture: the coverage (when shown) above the solve.
  await page.waitForTimeout(500);
  await page.evaluate(() => window.scrollTo(0, 0));
  const boxes = [];
  for (const id of ["#coverage-section", "#solve-section"]) {
    if (await page.isVisible(id)) boxes.push(await page.locator(id).boundingBox());
  }
  const left = Math.min(...boxes.map((b) => b.x));
  const top = Math.min(...boxes.map((b) => b.y));
  const clip = {
    x: left,
    y: top,
    width: Math.max(...boxes.map((b) => b.x + b.width)) - left,
    height: Math.max(...boxes.map((b) => b.y + b.height)) - top,
  };
  await page.screenshot({ path: screenshot, fullPage: true, clip, timeout: 90000 });
  console.log(`screenshot ${screenshot}`);
  check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
}

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
    // The 3D view: the four cameras with their camera_info, healthy, and the four boards.
    const drawn = await snapshot(page, (s) => s.view3dCamerasDrawn >= 4 && s.view3dCamerasByLevel.OK >= 4 &&
      s.view3dBodiesDrawn >= 4, 30000);
    check(true, `3D: ${drawn.view3dCamerasDrawn} cameras (${JSON.stringify(drawn.view3dCamerasByLevel)}), ` +
      `${drawn.view3dBodiesDrawn} bodies with their axes from ${drawn.view3dBodiesFrom}, ` +
      `${drawn.view3dMarkersDrawn} markers`);
    await page.waitForTimeout(1000);
    if (flagFile) await page.locator("#view3d-section").screenshot({ path: flagFile });
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
    // The volume from above and the first robots of the table (the 3D view is above them).
    await page.locator("#volume").evaluate((element) => element.scrollIntoView());
    await page.screenshot({ path: screenshot });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--view3d-tf") {
    const seen = await snapshot(page, new Function("s", `return s?.view3dBodiesFrom === "/tf" && ` +
      `s.view3dBodiesDrawn >= ${Number(flagFile)} && s.view3dCamerasDrawn >= 4;`), 90000);
    check(true, `3D from /tf: ${seen.view3dCamerasDrawn} cameras, ${seen.view3dBodiesDrawn} bodies with their axes, ` +
      `${seen.view3dTrailSegments} trail segments`);
    check(seen.poseReadout === "", "no /mocap/poses reached the page");
    await page.locator("#view3d-section").screenshot({ path: screenshot });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--coverage") {
    // A calibration session (volume_calibration.yaml): COUNT cameras' coverage, filling in.
    const count = Number(flagFile);
    const first = await snapshot(page, new Function("s", `return s?.coverageCameras >= ${count} && s.coverageViews > 0;`), 90000);
    const later = await snapshot(page, new Function("s", `return s.coverageViews > ${first.coverageViews};`), 30000);
    check(true, `coverage: ${later.coverageCameras} cameras, ${first.coverageViews} then ${later.coverageViews} ` +
      `sightings in their regions, the session ${(100 * later.coverageProgress).toFixed(0)} %; ` +
      `missing ${JSON.stringify(later.coverageMissing)}`);
    const regions = await page.locator("#coverage .regions div").count();
    const bars = await page.locator("#coverage .bar div").count();
    check(regions === 9 * count && bars === count, `${regions} regions and ${bars} bars drawn`);
    check(await page.isHidden("#camera-section"), "the single camera's panel is hidden");
    await page.locator("#coverage-section").screenshot({ path: screenshot });
    check(errors.length === 0, `no page errors${errors.length ? ": " + errors.join("; ") : ""}`);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--calibration-result") {
    await calibrationResult(page, Number(flagFile), errors);
    await browser.close();
    process.exit(failed ? 1 : 0);
  }
  if (mode === "--view3d") {
    await view3d(page, Number(flagFile), errors);
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
