// The Foxglove WebSocket protocol from the page's own host (the bridge serves this page): the
// channels the bridge advertises, those this page can decode with their schemas parsed
// (cdr.js), subscriptions kept to the set the page asks for, and each message's bytes. When
// the bridge goes away it tries again every 2 s.
import { parseSchema } from "./cdr.js";

const SUBPROTOCOL = "foxglove.websocket.v1";
const RETRY_MS = 2000;

// `on`: opened(url), closed(url, wasOpen), serverInfo(message), channels(channels: id ->
// {id, topic, schemaName, structs}, after each change), message(channel, payload, receivedMs).
// Returns {subscribe(ids)}.
export function connect(on) {
  const url = `${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/`;
  // A bridge that asks for a token gets the one this page was opened with (?token=...).
  const token = new URLSearchParams(location.search).get("token");
  let socket = null;
  let open = false;
  let channels = new Map();
  let subscriptions = new Map();  // channel id -> subscription id
  let bySubscription = new Map();  // subscription id -> channel
  let nextSubscription = 1;

  function start() {
    socket = new WebSocket(token ? `${url}?token=${encodeURIComponent(token)}` : url, [SUBPROTOCOL]);
    socket.binaryType = "arraybuffer";
    socket.onopen = () => {
      open = true;
      on.opened(url);
    };
    socket.onclose = () => {
      const was = open;
      open = false;
      channels = new Map();
      subscriptions = new Map();
      bySubscription = new Map();
      on.closed(url, was);
      setTimeout(start, RETRY_MS);
    };
    socket.onmessage = (event) => {
      if (typeof event.data === "string") control(JSON.parse(event.data));
      else data(new Uint8Array(event.data));
    };
  }

  function control(message) {
    if (message.op === "serverInfo") {
      on.serverInfo(message);
    } else if (message.op === "advertise") {
      for (const channel of message.channels) {
        if (channel.encoding !== "cdr" || channel.schemaEncoding !== "ros2idl") continue;
        try {
          const structs = parseSchema(channel.schema);
          channels.set(channel.id, { id: channel.id, topic: channel.topic, schemaName: channel.schemaName, structs });
        } catch (error) {
          console.warn(`${channel.topic}: ${error.message}`);
        }
      }
      on.channels(channels);
    } else if (message.op === "unadvertise") {
      // The bridge forgets their subscriptions itself.
      for (const id of message.channelIds) {
        bySubscription.delete(subscriptions.get(id));
        subscriptions.delete(id);
        channels.delete(id);
      }
      on.channels(channels);
    } else if (message.op === "status") {
      console.info(`bridge: ${message.message}`);
    }
  }

  function data(bytes) {
    if (bytes[0] !== 0x01 || bytes.length < 13) return;
    const view = new DataView(bytes.buffer, bytes.byteOffset);
    const channel = bySubscription.get(view.getUint32(1, true));
    if (!channel) return;
    // When the bridge received the message, on the graph's clock (the page's clock may be
    // another machine's).
    const receivedMs = Number(view.getBigUint64(5, true)) / 1e6;
    on.message(channel, bytes.subarray(13), receivedMs);
  }

  // Subscribes to the advertised channels among `ids` (a Set) and unsubscribes from the others.
  function subscribe(ids) {
    const added = [];
    for (const id of ids) {
      if (subscriptions.has(id) || !channels.has(id)) continue;
      const subscription = nextSubscription++;
      subscriptions.set(id, subscription);
      bySubscription.set(subscription, channels.get(id));
      added.push({ id: subscription, channelId: id });
    }
    const dropped = [];
    for (const [id, subscription] of subscriptions) {
      if (ids.has(id)) continue;
      subscriptions.delete(id);
      bySubscription.delete(subscription);
      dropped.push(subscription);
    }
    if (added.length) socket.send(JSON.stringify({ op: "subscribe", subscriptions: added }));
    if (dropped.length) socket.send(JSON.stringify({ op: "unsubscribe", subscriptionIds: dropped }));
  }

  start();
  return { subscribe };
}
