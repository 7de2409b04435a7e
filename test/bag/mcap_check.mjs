// An MCAP file read by readers that are not ours: @mcap/core's indexed reader, which needs the
// summary and the chunk and message indexes exactly right, and its stream reader, which reads
// a file front to back as a killed recording must be read; chunks decompressed by Foxglove's
// zstd and lz4 builds; every message decoded from the schema stored in the file by Foxglove's
// ros2idl parser and CDR reader.
//
//   node mcap_check.mjs FILE.mcap [--stream-only]
//
// Prints one JSON object: {"profile", "indexed": messages the indexed reader read (or its
// error), "stream": {"messages", "complete"}, "topics": {topic: {"type", "count", "decoded",
// "first"}}}, "first" being the first message decoded (numbers and strings; byte arrays by
// length). Exits 1 when a message cannot be decoded or the two readers disagree.
import fs from "node:fs";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";
import ros2idl from "@foxglove/ros2idl-parser";
import rosmsg2 from "@foxglove/rosmsg2-serialization";

const [file, option] = process.argv.slice(2);
const streamOnly = option === "--stream-only";
await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (buffer, size) => new Uint8Array(zstd.decompress(buffer, Number(size))),
  lz4: (buffer, size) => new Uint8Array(lz4(buffer, Number(size))),
};
const bytes = new Uint8Array(fs.readFileSync(file));

// What JSON can show of a decoded message: byte arrays by their length.
function shown(value) {
  if (value instanceof Uint8Array || ArrayBuffer.isView(value)) return `${value.length} bytes`;
  if (Array.isArray(value)) return value.slice(0, 8).map(shown);
  if (typeof value === "bigint") return Number(value);
  if (value && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, shown(v)]));
  }
  return value;
}

const result = { profile: null, indexed: null, stream: null, topics: {} };
const readers = new Map();  // schema id -> MessageReader
let failed = false;

function decode(channel, schema, data) {
  const topic = (result.topics[channel.topic] ??= {
    type: schema ? schema.name : null,
    count: 0,
    decoded: 0,
  });
  topic.count += 1;
  if (!schema || schema.encoding !== "ros2idl") return;
  let reader = readers.get(schema.id);
  if (!reader) {
    reader = new rosmsg2.MessageReader(
      ros2idl.parseRos2idl(new TextDecoder().decode(schema.data)),
    );
    readers.set(schema.id, reader);
  }
  try {
    const message = reader.readMessage(data);
    topic.decoded += 1;
    if (topic.first === undefined) topic.first = shown(message);
  } catch (error) {
    failed = true;
    topic.error ??= String(error);
  }
}

// The stream reader: every record, as a reader of a killed file sees them.
{
  const reader = new McapStreamReader({ decompressHandlers });
  reader.append(bytes);
  const schemas = new Map();
  const channels = new Map();
  let messages = 0;
  try {
    for (let record; (record = reader.nextRecord()); ) {
      if (record.type === "Header") result.profile = record.profile;
      if (record.type === "Schema") schemas.set(record.id, record);
      if (record.type === "Channel") channels.set(record.id, record);
      if (record.type === "Message") {
        messages += 1;
        const channel = channels.get(record.channelId);
        decode(channel, schemas.get(channel.schemaId), record.data);
      }
    }
    result.stream = { messages, complete: reader.done() };
  } catch (error) {
    result.stream = { messages, error: String(error) };
    failed = true;
  }
}

// The indexed reader: the summary, the chunk indexes and the message indexes.
if (!streamOnly) {
  try {
    const readable = {
      size: async () => BigInt(bytes.length),
      read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
    };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    let messages = 0;
    let previous = -1n;
    for await (const message of reader.readMessages()) {
      messages += 1;
      if (message.logTime < previous) throw new Error("messages out of log-time order");
      previous = message.logTime;
    }
    result.indexed = {
      messages,
      statistics: reader.statistics ? Number(reader.statistics.messageCount) : null,
      chunks: reader.chunkIndexes.length,
      compression: [...new Set(reader.chunkIndexes.map((c) => c.compression))],
    };
    if (messages !== result.stream.messages) failed = true;
  } catch (error) {
    result.indexed = { error: String(error) };
    failed = true;
  }
}

console.log(JSON.stringify(result));
process.exit(failed ? 1 : 0);
