// The built-in viewer: the bridge's channels (connection.js), chosen by their types
// (topics.js), their messages decoded from the advertised schemas (cdr.js) into what the
// viewer shows (state.js), drawn on canvases (draw.js, and view3d.js for the volume in 3D) and
// written into the page (panels.js) at the browser's animation frames. window.viewerState
// exposes what was drawn, for the browser test and for a curious console.
import { decode } from "./cdr.js";
import { connect } from "./connection.js";
import { drawCalibration, drawCameras, drawFloor, drawTop, drawVolumeTop } from "./draw.js";
import * as panels from "./panels.js";
import { advertised, counted, dirty, receive, report, rollRates, setCameras } from "./state.js";
import { choose } from "./topics.js";
import * as view3d from "./view3d.js";

window.viewerState = report;

const bridge = connect({
  opened(url) {
    report.connected = true;
    panels.connected(url);
  },
  closed(url, wasOpen) {
    report.connected = false;
    panels.disconnected(url, wasOpen);
  },
  serverInfo(message) {
    report.server = message.name;
  },
  channels(channels) {
    const { cameras, subscribed } = choose(channels);
    setCameras(cameras);
    advertised(channels);
    bridge.subscribe(subscribed);
    panels.layout(channels);
    panels.topics();
  },
  message(channel, payload, receivedMs) {
    counted(channel.topic, payload.length);
    let message;
    try {
      message = decode(channel.structs, channel.schemaName, payload);
    } catch (error) {
      console.warn(`${channel.topic}: ${error.message}`);
      return;
    }
    receive(channel, message, receivedMs);
  },
});

setInterval(() => {
  rollRates();
  panels.topics();
  panels.rates();
  panels.health();  // statuses that stopped coming turn STALE
  view3d.tick();  // and their cameras grey in the 3D view
}, 1000);

function frame() {
  if (dirty.cameras) drawCameras();
  if (dirty.side) {
    drawTop();
    drawFloor();
    panels.turret();
  }
  if (dirty.volume) drawVolumeTop();
  // Many messages between two animation frames make one drawing.
  if (dirty.volume || dirty.view3d || dirty.health || view3d.wanted()) view3d.draw();
  if (dirty.poses) panels.poses();
  if (dirty.alerts) panels.alerts();
  if (dirty.health) panels.health();
  if (dirty.coverage) panels.coverage();
  if (dirty.solve) panels.solve();
  if (dirty.result) {
    panels.result();
    drawCalibration();
  }
  for (const panel of Object.keys(dirty)) dirty[panel] = false;
  requestAnimationFrame(frame);
}

drawTop();
drawFloor();
requestAnimationFrame(frame);
