// A NatNet client (OptiTrack's streaming protocol) for testing a NatNet server. It was written
// from the protocol's public description only: the NatNet SDK 4.3 samples PacketClient.cpp,
// NatNetClient.py (+ DataDescriptions.py, MoCapData.py) and the header NatNetTypes.h, with none of
// the server's code, so that it decodes what the server sends on its own and catches its mistakes.
//
// It connects the way the SDK's Python sample does (NAT_CONNECT from a command socket on an
// ephemeral port), prints the server's sSender_Server, optionally switches the bitstream version
// ("Bitstream,M.m") and sends other NAT_REQUESTs, decodes NAT_MODELDEF and then --frames
// NAT_FRAMEOFDATA packets completely, checking every 4.1+ byte-size field and each packet's size
// field. One JSON line per event on stdout:
//   {"type":"server_info", ...}            {"type":"response","request":..,"code"|"text":..}
//   {"type":"unrecognized","request":..}   {"type":"message_string","text":..}
//   {"type":"descriptions", ...}           {"type":"frame", ...}
//   {"type":"unexpected", ...}             {"type":"done","frames":N, ...}
// It exits 0 after --frames frames; 1 with one line on stderr ("natnet_client: ...") on a
// timeout, a packet that does not decode, or a length that disagrees with a size field; 2 on a
// bad command line.
//
//   node natnet_client.mjs --server HOST [--command-port 1510] [--local ADDRESS] [--version 4.2]
//     [--bitstream M.m] [--multicast GROUP --data-port 1511] [--frames 10] [--timeout-s 10]
//     [--overall-timeout-s S] [--keepalive-s 1] [--no-keepalive] [--requests "Echo,hi;FrameRate"]
//
// Offsets in error messages count from the datagram's first byte (the 4-byte header included).
import dgram from "node:dgram";
import process from "node:process";

const USAGE = "usage: node natnet_client.mjs --server HOST [--command-port 1510] [--local ADDRESS]"
  + " [--version 4.2] [--bitstream M.m] [--multicast GROUP --data-port 1511] [--frames N]"
  + " [--timeout-s S] [--overall-timeout-s S] [--keepalive-s 1] [--no-keepalive]"
  + " [--requests \"Echo,hello;FrameRate\"]";

// Message ids (NatNetTypes.h).
const NAT = {
  CONNECT: 0, SERVERINFO: 1, REQUEST: 2, RESPONSE: 3, REQUEST_MODELDEF: 4, MODELDEF: 5,
  REQUEST_FRAMEOFDATA: 6, FRAMEOFDATA: 7, MESSAGESTRING: 8, DISCONNECT: 9, KEEPALIVE: 10,
  DISCONNECTBYTIMEOUT: 11, ECHOREQUEST: 12, ECHORESPONSE: 13, DISCOVERY: 14,
  UNRECOGNIZED_REQUEST: 100,
};
const MESSAGE_NAMES = Object.fromEntries(Object.entries(NAT).map(([name, id]) => [id, `NAT_${name}`]));
const messageName = (id) => MESSAGE_NAMES[id] ?? `message id ${id}`;

// --- command line ------------------------------------------------------------------------------

function usageError(text) {
  process.stderr.write(`natnet_client: ${text}; ${USAGE}\n`);
  process.exit(2);
}

function parseVersion(text, flag, maxParts) {
  const match = /^(\d+)\.(\d+)(?:\.(\d+))?(?:\.(\d+))?$/.exec(text ?? "");
  const parts = match ? match.slice(1).map((part) => Number(part ?? 0)) : null;
  if (!parts || parts.some((part) => part > 255) || text.split(".").length > maxParts) {
    usageError(`${flag} wants a version like 4.2, not "${text}"`);
  }
  return parts;
}

function parsePositive(text, flag, { integer = false, allowZero = false } = {}) {
  const value = Number(text);
  const ok = Number.isFinite(value) && (allowZero ? value >= 0 : value > 0)
    && (!integer || Number.isInteger(value));
  if (!ok) usageError(`${flag} wants a ${integer ? "whole " : ""}number, not "${text}"`);
  return value;
}

function parseArgs(argv) {
  const options = {
    server: null, commandPort: 1510, local: "0.0.0.0", version: [4, 2, 0, 0], bitstream: null,
    multicast: null, dataPort: 1511, frames: 10, timeoutS: 10, overallTimeoutS: null,
    keepaliveS: 1, keepalive: true, requests: [],
  };
  for (let i = 0; i < argv.length; i++) {
    const flag = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) usageError(`${flag} needs a value`);
      return argv[++i];
    };
    switch (flag) {
      case "--server": options.server = value(); break;
      case "--command-port": options.commandPort = parsePositive(value(), flag, { integer: true }); break;
      case "--local": options.local = value(); break;
      case "--version": options.version = parseVersion(value(), flag, 4); break;
      case "--bitstream": options.bitstream = parseVersion(value(), flag, 2); break;
      case "--multicast": options.multicast = value(); break;
      case "--data-port": options.dataPort = parsePositive(value(), flag, { integer: true }); break;
      case "--frames": options.frames = parsePositive(value(), flag, { integer: true, allowZero: true }); break;
      case "--timeout-s": options.timeoutS = parsePositive(value(), flag); break;
      case "--overall-timeout-s": options.overallTimeoutS = parsePositive(value(), flag); break;
      case "--keepalive-s": options.keepaliveS = parsePositive(value(), flag); break;
      case "--no-keepalive": options.keepalive = false; break;
      case "--requests": options.requests = value().split(";").filter((request) => request.length > 0); break;
      case "--help": case "-h": process.stdout.write(`${USAGE}\n`); process.exit(0); break;
      default: usageError(`unknown argument "${flag}"`);
    }
  }
  if (!options.server) usageError("--server is required");
  if (options.commandPort > 65535 || options.dataPort > 65535) usageError("ports go up to 65535");
  // Without a given bound, allow each exchange its --timeout-s and each frame a second.
  options.overallTimeoutS ??= (4 + options.requests.length) * options.timeoutS + options.frames;
  return options;
}

// --- reading packets ---------------------------------------------------------------------------

class DecodeError extends Error {}

// Reads little-endian fields of one datagram between offset and end, naming the field on a short read.
class Reader {
  constructor(datagram, offset, end) {
    this.bytes = datagram;
    this.view = new DataView(datagram.buffer, datagram.byteOffset, datagram.byteLength);
    this.offset = offset;
    this.end = end;
  }

  left() { return this.end - this.offset; }

  take(count, what) {
    if (count > this.left()) {
      throw new DecodeError(`${what}: needs ${count} bytes at offset ${this.offset}, only ${this.left()} left`);
    }
    const at = this.offset;
    this.offset += count;
    return at;
  }

  u8(what) { return this.view.getUint8(this.take(1, what)); }
  i16(what) { return this.view.getInt16(this.take(2, what), true); }
  u16(what) { return this.view.getUint16(this.take(2, what), true); }
  i32(what) { return this.view.getInt32(this.take(4, what), true); }
  u32(what) { return this.view.getUint32(this.take(4, what), true); }
  // Floats stay exactly as sent: a float32 widens to a double without rounding.
  f32(what) { return this.view.getFloat32(this.take(4, what), true); }
  f64(what) { return this.view.getFloat64(this.take(8, what), true); }
  u64(what) { return this.view.getBigUint64(this.take(8, what), true); }
  vec3(what) { return [this.f32(`${what} x`), this.f32(`${what} y`), this.f32(`${what} z`)]; }
  quat(what) { return [this.f32(`${what} qx`), this.f32(`${what} qy`), this.f32(`${what} qz`), this.f32(`${what} qw`)]; }

  cstring(what) {
    const nul = this.bytes.indexOf(0, this.offset);
    if (nul < 0 || nul >= this.end) {
      throw new DecodeError(`${what}: string at offset ${this.offset} has no terminating NUL before offset ${this.end}`);
    }
    const text = this.bytes.toString("utf8", this.offset, nul);
    this.offset = nul + 1;
    return text;
  }

  // A signed element count, checked against what can still fit so that a wrong count fails at once.
  count(what, minItemBytes) {
    const at = this.offset;
    const value = this.i32(what);
    if (value < 0 || value * minItemBytes > this.left()) {
      throw new DecodeError(`${what} is ${value} (offset ${at}), but only ${this.left()} bytes are left`
        + ` for items of at least ${minItemBytes} bytes`);
    }
    return value;
  }

  repeat(count, read) {
    const items = [];
    for (let i = 0; i < count; i++) items.push(read(i));
    return items;
  }
}

const atLeast = (version, major, minor) => version[0] > major || (version[0] === major && version[1] >= minor);
const versionText = (version) => version.join(".");

// NAT_SERVERINFO's payload is sSender_Server, packed (NatNetTypes.h: #pragma pack(1)):
// szName[256], Version[4], NatNetVersion[4], uint64 HighResClockFrequency, uint16 DataPort,
// bool IsMulticast, uint8 MulticastGroupAddress[4] = 279 bytes.
const SERVER_INFO_BYTES = 279;

function decodeServerInfo(datagram) {
  const size = datagram.length - 4;
  if (size < SERVER_INFO_BYTES) {
    throw new DecodeError(`NAT_SERVERINFO payload is ${size} bytes; sSender_Server needs ${SERVER_INFO_BYTES}`);
  }
  const r = new Reader(datagram, 4, datagram.length);
  const nameField = datagram.subarray(4, 4 + 256);
  const nul = nameField.indexOf(0);
  if (nul < 0) throw new DecodeError("NAT_SERVERINFO application name fills all 256 bytes without a NUL");
  r.take(256, "application name");
  const applicationVersion = r.repeat(4, () => r.u8("application version"));
  const natnetVersion = r.repeat(4, () => r.u8("NatNet version"));
  const clockFrequency = r.u64("high-resolution clock frequency");
  const dataPort = r.u16("data port");
  const multicastByte = r.u8("multicast flag");
  const group = r.repeat(4, () => r.u8("multicast group"));
  return {
    type: "server_info",
    application: nameField.toString("utf8", 0, nul),
    application_version: versionText(applicationVersion),
    natnet_version: versionText(natnetVersion),
    high_resolution_clock_frequency: clockFrequency.toString(),
    data_port: dataPort,
    multicast: multicastByte !== 0,
    multicast_flag_byte: multicastByte,
    multicast_group: group.join("."),
    bytes: datagram.length,
    // kept for the session, not printed
    natnetVersionParts: natnetVersion,
    clockFrequency,
  };
}

// NAT_RESPONSE carries either a 4-byte int (a result code, 0 = success) or a NUL-terminated
// string: the SDK's clients tell them apart by nDataBytes == 4 alone.
function decodeResponse(datagram, request) {
  const size = datagram.length - 4;
  if (size === 4) return { type: "response", request, code: datagram.readInt32LE(4) };
  const r = new Reader(datagram, 4, datagram.length);
  const text = r.cstring(`NAT_RESPONSE to "${request}"`);
  if (r.left() !== 0) {
    throw new DecodeError(`NAT_RESPONSE to "${request}": ${r.left()} bytes follow the string's NUL (offset ${r.offset})`);
  }
  return { type: "response", request, text };
}

function decodeMessageString(datagram) {
  const r = new Reader(datagram, 4, datagram.length);
  return { type: "message_string", text: r.cstring("NAT_MESSAGESTRING") };
}

// --- NAT_MODELDEF --------------------------------------------------------------------------------

const DESCRIPTION_TYPES = ["marker set", "rigid body", "skeleton", "force plate", "device", "camera", "asset"];

function readRigidBodyDescription(r, version, label) {
  const body = {};
  body.name = version[0] >= 2 ? r.cstring(`${label} name`) : null;
  body.id = r.i32(`${label} id`);
  body.parent_id = r.i32(`${label} parent id`);
  body.offset = r.vec3(`${label} offset`);
  if (atLeast(version, 4, 2)) body.orientation_offset = r.quat(`${label} orientation offset`);
  body.markers = [];
  if (version[0] >= 3) {
    // Arrays one after another: all positions, then all required active labels, then (4.0+) all names.
    const count = r.count(`${label} marker count`, 16);
    const positions = r.repeat(count, (i) => r.vec3(`${label} marker ${i} position`));
    const labels = r.repeat(count, (i) => r.i32(`${label} marker ${i} active label`));
    const names = version[0] >= 4 ? r.repeat(count, (i) => r.cstring(`${label} marker ${i} name`)) : null;
    body.markers = positions.map((position, i) => ({
      position, active_label: labels[i], name: names ? names[i] : null,
    }));
  }
  return body;
}

function readMarkerDescription(r, label) {
  return {
    name: r.cstring(`${label} name`),
    id: r.i32(`${label} id`),
    position: r.vec3(`${label} position`),
    size: r.f32(`${label} size`),
    params: r.i16(`${label} params`),
  };
}

function readChannelNames(r, label) {
  const count = r.count(`${label} channel count`, 1);
  return r.repeat(count, (i) => r.cstring(`${label} channel ${i} name`));
}

function readDescription(r, version, type, label, out) {
  switch (type) {
    case 0: {
      const name = r.cstring(`${label} name`);
      const count = r.count(`${label} marker count`, 1);
      out.marker_sets.push({ name, markers: r.repeat(count, (i) => r.cstring(`${label} marker ${i} name`)) });
      return name;
    }
    case 1: {
      const body = readRigidBodyDescription(r, version, label);
      out.rigid_bodies.push(body);
      return body.name;
    }
    case 2: {
      const name = r.cstring(`${label} name`);
      const id = r.i32(`${label} id`);
      const count = r.count(`${label} bone count`, 20);
      const bones = r.repeat(count, (i) => readRigidBodyDescription(r, version, `${label} bone ${i}`));
      out.skeletons.push({ name, id, rigid_bodies: bones });
      return name;
    }
    case 3: {
      if (version[0] < 3) { out.force_plates.push({}); return null; }  // the SDK reads nothing before 3.0
      const plate = { id: r.i32(`${label} id`), serial: r.cstring(`${label} serial`) };
      plate.width = r.f32(`${label} width`);
      plate.length = r.f32(`${label} length`);
      plate.origin = r.vec3(`${label} origin`);
      plate.cal_matrix = r.repeat(12, (row) => r.repeat(12, (col) => r.f32(`${label} cal matrix [${row}][${col}]`)));
      plate.corners = r.repeat(4, (i) => r.vec3(`${label} corner ${i}`));
      plate.plate_type = r.i32(`${label} plate type`);
      plate.channel_data_type = r.i32(`${label} channel data type`);
      plate.channel_names = readChannelNames(r, label);
      out.force_plates.push(plate);
      return plate.serial;
    }
    case 4: {
      if (version[0] < 3) { out.devices.push({}); return null; }
      const device = { id: r.i32(`${label} id`), name: r.cstring(`${label} name`), serial: r.cstring(`${label} serial`) };
      device.device_type = r.i32(`${label} device type`);
      device.channel_data_type = r.i32(`${label} channel data type`);
      device.channel_names = readChannelNames(r, label);
      out.devices.push(device);
      return device.name;
    }
    case 5: {
      const camera = { name: r.cstring(`${label} name`), position: r.vec3(`${label} position`), orientation: r.quat(`${label} orientation`) };
      out.cameras.push(camera);
      return camera.name;
    }
    case 6: {
      const asset = { name: r.cstring(`${label} name`), asset_type: r.i32(`${label} asset type`), id: r.i32(`${label} id`) };
      const bodyCount = r.count(`${label} rigid body count`, 20);
      asset.rigid_bodies = r.repeat(bodyCount, (i) => readRigidBodyDescription(r, version, `${label} rigid body ${i}`));
      const markerCount = r.count(`${label} marker count`, 23);
      asset.markers = r.repeat(markerCount, (i) => readMarkerDescription(r, `${label} marker ${i}`));
      out.assets.push(asset);
      return asset.name;
    }
    default:
      throw new DecodeError(`${label}: unknown description type ${type}`);
  }
}

function decodeDescriptions(datagram, version) {
  const r = new Reader(datagram, 4, datagram.length);
  const hasSizes = atLeast(version, 4, 1);
  const out = {
    type: "descriptions", version: versionText(version), count: 0, marker_sets: [], rigid_bodies: [],
    skeletons: [], force_plates: [], devices: [], cameras: [], assets: [], bytes: datagram.length,
  };
  out.count = r.count("NAT_MODELDEF description count", hasSizes ? 8 : 4);
  for (let i = 0; i < out.count; i++) {
    const typeAt = r.offset;
    const type = r.i32(`description ${i} type`);
    const label = `description ${i} (${DESCRIPTION_TYPES[type] ?? `type ${type}`}, offset ${typeAt})`;
    // 4.1+: each description's own byte size (not per type, unlike the frame's sections).
    const declared = hasSizes ? r.i32(`${label} byte size`) : null;
    const start = r.offset;
    const name = readDescription(r, version, type, label, out);
    if (hasSizes && r.offset - start !== declared) {
      throw new DecodeError(`${label}${name != null ? ` "${name}"` : ""} says ${declared} bytes, read ${r.offset - start} (offset ${start})`);
    }
  }
  if (r.left() !== 0) {
    throw new DecodeError(`NAT_MODELDEF: ${out.count} descriptions end at offset ${r.offset}, the packet at ${r.end}`);
  }
  return out;
}

// --- NAT_FRAMEOFDATA ----------------------------------------------------------------------------

function readFrameRigidBody(r, version, label) {
  const body = { id: r.i32(`${label} id`), position: r.vec3(`${label} position`), orientation: r.quat(`${label} orientation`) };
  if (version[0] < 3) {
    // Before 3.0 each body repeated its markers (removed as redundant in 3.0).
    const count = r.count(`${label} marker count`, 12);
    const positions = r.repeat(count, (i) => r.vec3(`${label} marker ${i} position`));
    const ids = version[0] >= 2 ? r.repeat(count, (i) => r.i32(`${label} marker ${i} id`)) : null;
    const sizes = version[0] >= 2 ? r.repeat(count, (i) => r.f32(`${label} marker ${i} size`)) : null;
    body.markers = positions.map((position, i) => ({ position, id: ids ? ids[i] : null, size: sizes ? sizes[i] : null }));
  }
  body.mean_error = version[0] >= 2 ? r.f32(`${label} mean error`) : null;
  body.params = atLeast(version, 2, 6) ? r.i16(`${label} params`) : null;
  body.tracking_valid = body.params === null ? null : (body.params & 0x01) !== 0;
  return body;
}

function readLabeledMarker(r, version, label) {
  const id = r.i32(`${label} id`);
  // High 16 bits: the model (asset) id, low 16 bits: the marker's id in it.
  const marker = { id, model_id: id >> 16, marker_id: id & 0xffff };
  marker.position = r.vec3(`${label} position`);
  marker.size = r.f32(`${label} size`);
  // params from 2.6 on; bits 3-5 are defined from 3.0 on (PacketClient.cpp).
  const params = atLeast(version, 2, 6) ? r.i16(`${label} params`) : null;
  const bit = (mask) => (params === null ? null : (params & mask) !== 0);
  marker.params = params;
  marker.occluded = bit(0x01);
  marker.point_cloud_solved = bit(0x02);
  marker.model_solved = bit(0x04);
  marker.has_model = bit(0x08);
  marker.unlabeled = bit(0x10);
  marker.active = bit(0x20);
  // Metres per ray as sent; the SDK samples display it times 1000.
  marker.residual = version[0] >= 3 ? r.f32(`${label} residual`) : null;
  return marker;
}

function readAnalogBundle(r, label) {
  const bundle = { id: r.i32(`${label} id`) };
  const channels = r.count(`${label} channel count`, 4);
  bundle.channels = r.repeat(channels, (c) => {
    const frames = r.count(`${label} channel ${c} frame count`, 4);
    return r.repeat(frames, (f) => r.f32(`${label} channel ${c} value ${f}`));
  });
  return bundle;
}

function decodeFrame(datagram, version, clockFrequency) {
  const r = new Reader(datagram, 4, datagram.length);
  // NatNet 4.1 added the section byte sizes, the asset section and the precision timestamp.
  const since41 = atLeast(version, 4, 1);
  const frame = { type: "frame", version: versionText(version), frame_number: r.i32("frame number") };
  const sectionSizes = since41 ? {} : null;
  try {
    // Each section: an int32 count, in 4.1+ an int32 byte size of everything after it, the items.
    const section = (key, label, minItemBytes, readItem) => {
      const count = r.count(`${label} count`, minItemBytes);
      const declared = since41 ? r.i32(`${label} section byte size`) : null;
      const start = r.offset;
      const items = r.repeat(count, (i) => readItem(i));
      if (since41) {
        sectionSizes[key] = declared;
        if (r.offset - start !== declared) {
          throw new DecodeError(`${label} section says ${declared} bytes, read ${r.offset - start} (offset ${start})`);
        }
      }
      return items;
    };

    frame.marker_sets = section("marker_sets", "marker set", 5, (i) => {
      const name = r.cstring(`marker set ${i} name`);
      const count = r.count(`marker set ${i} ("${name}") marker count`, 12);
      return { name, markers: r.repeat(count, (j) => r.vec3(`marker set ${i} marker ${j}`)) };
    });
    frame.unlabeled_markers = section("unlabeled_markers", "legacy unlabeled marker", 12,
      (i) => r.vec3(`legacy unlabeled marker ${i}`));
    const bodyBytes = version[0] >= 3 ? 38 : 28;
    frame.rigid_bodies = section("rigid_bodies", "rigid body", bodyBytes,
      (i) => readFrameRigidBody(r, version, `rigid body ${i}`));
    frame.skeletons = atLeast(version, 2, 1)
      ? section("skeletons", "skeleton", 8, (i) => {
        const id = r.i32(`skeleton ${i} id`);
        const count = r.count(`skeleton ${i} bone count`, bodyBytes);
        return { id, rigid_bodies: r.repeat(count, (j) => readFrameRigidBody(r, version, `skeleton ${i} bone ${j}`)) };
      })
      : [];
    frame.assets = since41
      ? section("assets", "asset", 12, (i) => {
        const id = r.i32(`asset ${i} id`);
        const bodyCount = r.count(`asset ${i} rigid body count`, 38);
        const rigidBodies = r.repeat(bodyCount, (j) => readFrameRigidBody(r, version, `asset ${i} rigid body ${j}`));
        const markerCount = r.count(`asset ${i} marker count`, 26);
        const markers = r.repeat(markerCount, (j) => {
          const label = `asset ${i} marker ${j}`;
          return {
            id: r.i32(`${label} id`), position: r.vec3(`${label} position`), size: r.f32(`${label} size`),
            params: r.i16(`${label} params`), residual: r.f32(`${label} residual`),
          };
        });
        return { id, rigid_bodies: rigidBodies, markers };
      })
      : [];
    frame.labeled_markers = atLeast(version, 2, 3)
      ? section("labeled_markers", "labeled marker", 16, (i) => readLabeledMarker(r, version, `labeled marker ${i}`))
      : [];
    frame.force_plates = atLeast(version, 2, 9)
      ? section("force_plates", "force plate", 8, (i) => readAnalogBundle(r, `force plate ${i}`))
      : [];
    frame.devices = atLeast(version, 2, 11)
      ? section("devices", "device", 8, (i) => readAnalogBundle(r, `device ${i}`))
      : [];

    // Suffix.
    frame.legacy_software_latency = version[0] < 3 ? r.f32("software latency") : null;
    frame.timecode = r.u32("timecode");
    frame.timecode_subframe = r.u32("timecode subframe");
    frame.timestamp = atLeast(version, 2, 7) ? r.f64("timestamp") : r.f32("timestamp");
    if (version[0] >= 3) {
      const midExposure = r.u64("camera mid-exposure stamp");
      const dataReceived = r.u64("camera data received stamp");
      const transmit = r.u64("transmit stamp");
      frame.camera_mid_exposure = midExposure.toString();
      frame.camera_data_received = dataReceived.toString();
      frame.transmit = transmit.toString();
      // As SampleClient.cpp does: host ticks * 1000 / HighResClockFrequency (signed here, not wrapped).
      const toMs = (ticks) => (clockFrequency > 0n ? Number(ticks) * 1000 / Number(clockFrequency) : null);
      frame.software_latency_ms = toMs(transmit - dataReceived);
      frame.system_latency_ms = midExposure !== 0n ? toMs(transmit - midExposure) : null;
    } else {
      frame.camera_mid_exposure = frame.camera_data_received = frame.transmit = null;
      frame.software_latency_ms = frame.system_latency_ms = null;
    }
    frame.precision_timestamp_secs = since41 ? r.u32("precision timestamp seconds") : null;
    frame.precision_timestamp_frac_secs = since41 ? r.u32("precision timestamp fractional seconds") : null;
    const params = r.u16("frame params");
    frame.params = params;
    frame.recording = (params & 0x01) !== 0;
    frame.tracked_models_changed = (params & 0x02) !== 0;
    frame.edit_mode = (params & 0x04) !== 0;
    frame.bitstream_changed = (params & 0x08) !== 0;
    frame.end_of_data_tag = r.i32("end-of-data tag");
    if (r.left() !== 0) {
      throw new DecodeError(`the frame ends at offset ${r.offset} but the packet holds ${r.end} bytes`
        + ` (${r.left()} more, size field ${r.end - 4})`);
    }
  } catch (error) {
    if (error instanceof DecodeError) error.message = `frame ${frame.frame_number}: ${error.message}`;
    throw error;
  }
  frame.section_sizes = sectionSizes;
  frame.bytes = datagram.length;
  return frame;
}

// --- wall clock ---------------------------------------------------------------------------------

// performance.timeOrigin is the wall clock at process start in microseconds (Node reads the system
// clock once at startup); performance.now() is the monotonic time since then. Their sum is a wall
// clock with sub-microsecond steps, unlike Date.now() (1 ms) as an anchor for process.hrtime. Kept
// as two BigInts so that the nanoseconds of the sum are not lost to a double's 53 bits. It does not
// follow clock steps or NTP slewing during the run, which is seconds long.
const originNs = BigInt(Math.round(performance.timeOrigin * 1e3)) * 1000n;
const unixNowNs = () => originNs + BigInt(Math.round(performance.now() * 1e6));

// --- the session --------------------------------------------------------------------------------

const options = parseArgs(process.argv.slice(2));
const unicast = options.multicast === null;
const print = (object) => process.stdout.write(`${JSON.stringify(object)}\n`);

let finished = false;
let waiter = null;          // the exchange waiting for a reply: { ids, resolve }
let decodeVersion = null;
let clockFrequency = 0n;
let streaming = false;      // frames count from the end of the setup on
let framesDecoded = 0;
let skippedBeforeSetup = 0;
let framesOnOtherSocket = 0;
let frameTimer = null;
let keepaliveTimer = null;
let dataSocket = null;

const commandSocket = dgram.createSocket({ type: "udp4" });

function finish(code, errorText) {
  if (finished) return;
  finished = true;
  if (errorText) process.stderr.write(`natnet_client: ${String(errorText).replace(/\s*\n\s*/g, " ")}\n`);
  clearTimeout(frameTimer);
  clearInterval(keepaliveTimer);
  clearTimeout(overallTimer);
  for (const socket of [commandSocket, dataSocket]) {
    try { socket?.close(); } catch { /* already closed */ }
  }
  process.exitCode = code;
  // Should anything still hold the event loop, leave anyway.
  setTimeout(() => process.exit(code), 500).unref();
}

const overallTimer = setTimeout(() => {
  finish(1, `overall timeout of ${options.overallTimeoutS} s (${framesDecoded} of ${options.frames} frames decoded)`);
}, options.overallTimeoutS * 1000);

// Every request is built as NatNetClient.py's send_request() builds it: the 4-byte header
// (message id, nDataBytes), the body, then always one NUL byte. nDataBytes counts that NUL for
// NAT_CONNECT and NAT_REQUEST (body + 1) and is 0 for NAT_KEEPALIVE and NAT_REQUEST_MODELDEF,
// whose datagrams are therefore 5 bytes (PacketClient.cpp sends those as 4).
function sendRequest(id, body, what = messageName(id)) {
  const packet = Buffer.alloc(4 + body.length + 1);
  packet.writeUInt16LE(id, 0);
  packet.writeUInt16LE(body.length === 0 ? 0 : body.length + 1, 2);
  body.copy(packet, 4);
  commandSocket.send(packet, options.commandPort, options.server, (error) => {
    if (error) finish(1, `sending ${what} to ${options.server}:${options.commandPort}: ${error.message}`);
  });
}

// NAT_CONNECT's body as NatNetClient.py lays it out: sSender (szName[256] = "Ping", Version[4],
// NatNetVersion[4], all else zero) then sConnectionOptions (bool subscribedDataOnly = 0 at 264,
// BitstreamVersion[4] = --version at 265..268) and one zero byte: 270 bytes, nDataBytes 271.
function connectBody() {
  const body = Buffer.alloc(270);
  body.write("Ping", 0, "latin1");
  options.version.forEach((part, i) => { body[265 + i] = part; });
  return body;
}

function waitFor(ids, what) {
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => {
      waiter = null;
      reject(new Error(`no ${what} from ${options.server}:${options.commandPort} within ${options.timeoutS} s`));
    }, options.timeoutS * 1000);
    waiter = {
      ids,
      resolve: (reply) => { clearTimeout(timer); waiter = null; resolve(reply); },
    };
  });
}

function armFrameTimer() {
  clearTimeout(frameTimer);
  const where = unicast
    ? `the command socket, local port ${commandSocket.address().port}, where NAT_CONNECT came from`
    : `${options.multicast}:${options.dataPort}`;
  frameTimer = setTimeout(() => {
    finish(1, `no NAT_FRAMEOFDATA on ${where} for ${options.timeoutS} s (${framesDecoded} of ${options.frames} frames decoded)`);
  }, options.timeoutS * 1000);
}

function onFrame(datagram, socketName) {
  if (socketName !== (unicast ? "command" : "data")) { framesOnOtherSocket++; return; }
  if (!streaming) { skippedBeforeSetup++; return; }
  if (framesDecoded >= options.frames) return;
  armFrameTimer();
  let frame;
  try {
    frame = decodeFrame(datagram, decodeVersion, clockFrequency);
  } catch (error) {
    finish(1, error.message);
    return;
  }
  frame.decoded_unix_ns = unixNowNs().toString();
  print(frame);
  framesDecoded++;
  if (framesDecoded >= options.frames) finishDone();
}

function finishDone() {
  print({
    type: "done", frames: framesDecoded, skipped_before_setup: skippedBeforeSetup,
    frames_on_other_socket: framesOnOtherSocket,
  });
  finish(0);
}

function onDatagram(datagram, remote, socketName) {
  if (finished) return;
  const from = `${remote.address}:${remote.port}`;
  if (datagram.length < 4) {
    finish(1, `${from} sent a ${datagram.length}-byte datagram, shorter than the 4-byte header`);
    return;
  }
  const id = datagram.readUInt16LE(0);
  const size = datagram.readUInt16LE(2);
  if (datagram.length !== 4 + size) {
    finish(1, `${messageName(id)} from ${from}: the datagram is ${datagram.length} bytes but its size field says 4 + ${size}`);
    return;
  }
  if (waiter && waiter.ids.includes(id)) {
    waiter.resolve({ id, datagram });
    return;
  }
  try {
    switch (id) {
      case NAT.FRAMEOFDATA:
        onFrame(datagram, socketName);
        break;
      case NAT.MESSAGESTRING:
        print(decodeMessageString(datagram));
        break;
      case NAT.MODELDEF:
        print(decodeDescriptions(datagram, decodeVersion ?? options.version));
        break;
      default:
        print({ type: "unexpected", message_id: id, name: messageName(id), socket: socketName, from, bytes: datagram.length });
    }
  } catch (error) {
    finish(1, error.message);
  }
}

async function request(text) {
  const reply = waitFor([NAT.RESPONSE, NAT.UNRECOGNIZED_REQUEST], `reply to NAT_REQUEST "${text}"`);
  sendRequest(NAT.REQUEST, Buffer.from(text, "utf8"), `NAT_REQUEST "${text}"`);
  const { id, datagram } = await reply;
  return id === NAT.UNRECOGNIZED_REQUEST ? { type: "unrecognized", request: text } : decodeResponse(datagram, text);
}

async function main() {
  commandSocket.on("message", (datagram, remote) => onDatagram(datagram, remote, "command"));
  commandSocket.on("error", (error) => finish(1, `command socket: ${error.message}`));
  await new Promise((resolve) => commandSocket.bind({ port: 0, address: options.local }, resolve));

  if (!unicast) {
    // Multicast frames come to the group on the data port. Bound to the wildcard address: on Linux
    // a socket bound to a unicast address does not see group traffic; --local picks the interface.
    dataSocket = dgram.createSocket({ type: "udp4", reuseAddr: true });
    dataSocket.on("message", (datagram, remote) => onDatagram(datagram, remote, "data"));
    dataSocket.on("error", (error) => finish(1, `data socket: ${error.message}`));
    await new Promise((resolve) => dataSocket.bind({ port: options.dataPort, address: "0.0.0.0" }, resolve));
    try {
      dataSocket.addMembership(options.multicast, options.local === "0.0.0.0" ? undefined : options.local);
    } catch (error) {
      throw new Error(`joining ${options.multicast} on ${options.local}: ${error.message}`);
    }
  }

  // 1-2. Connect, read the server's description.
  const serverInfoReply = waitFor([NAT.SERVERINFO], "NAT_SERVERINFO");
  sendRequest(NAT.CONNECT, connectBody());
  if (unicast && options.keepalive) {
    // Unicast clients keep the server sending with NAT_KEEPALIVE (header only, plus the NUL the
    // Python sample appends) on the command socket; multicast clients send none.
    keepaliveTimer = setInterval(() => sendRequest(NAT.KEEPALIVE, Buffer.alloc(0)), options.keepaliveS * 1000);
  }
  const serverInfo = decodeServerInfo((await serverInfoReply).datagram);
  const { natnetVersionParts, clockFrequency: frequency, ...printable } = serverInfo;
  print(printable);
  clockFrequency = frequency;
  decodeVersion = natnetVersionParts;

  // 3. Bitstream version, then the caller's requests, one reply each before the next.
  if (options.bitstream) {
    const text = `Bitstream,${options.bitstream[0]}.${options.bitstream[1]}`;
    const reply = await request(text);
    print(reply);
    if (reply.type === "unrecognized") throw new Error(`the server did not recognize "${text}"`);
    if (reply.code !== undefined && reply.code !== 0) throw new Error(`the server answered "${text}" with code ${reply.code}`);
    decodeVersion = [options.bitstream[0], options.bitstream[1], 0, 0];
  }
  if (decodeVersion[0] === 0 && decodeVersion[1] === 0) {
    throw new Error("the server reports NatNet version 0.0; give --bitstream to pick the frame layout");
  }
  for (const text of options.requests) print(await request(text));

  // 4. Descriptions.
  const modelReply = waitFor([NAT.MODELDEF], "NAT_MODELDEF");
  sendRequest(NAT.REQUEST_MODELDEF, Buffer.alloc(0));
  print(decodeDescriptions((await modelReply).datagram, decodeVersion));

  // 5. Frames: in unicast on the command socket, in multicast on the group.
  if (options.frames === 0) { finishDone(); return; }
  streaming = true;
  armFrameTimer();
}

main().catch((error) => finish(1, error.message));
