// A Foxglove client the twin's code has no part in: Foxglove's own WebSocket client
// (@foxglove/ws-protocol) subscribes to every channel the server advertises, and Foxglove's own
// ROS 2 decoders (@foxglove/rosmsg parses the advertised ros2msg schema, and
// @foxglove/rosmsg2-serialization decodes the cdr messages with it).
//
// node client.mjs URL SECONDS [--stall]
//
// Reads until the server closes or SECONDS pass, then prints one JSON object: the channels as
// advertised, and per topic the message count, how many decodes left bytes over (a schema
// that does not match its messages), the stamps, the first and last messages decoded (byte
// arrays as their lengths) and, for a PointCloud2, its points read by their fields.
// With --stall it subscribes, then pauses its socket and never reads again: a stalled viewer.
// It prints {"stalled": ...} once paused, and its counts when SECONDS pass.

// Foxglove's packages are CommonJS: their exports come through the default import.
import wsProtocol from "@foxglove/ws-protocol";
import rosmsg from "@foxglove/rosmsg";
import rosmsg2 from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;
const { parse } = rosmsg;
const { MessageReader } = rosmsg2;

const [url, secondsArg, mode] = process.argv.slice(2);
const stall = mode === "--stall";
// The Foxglove SDK's server names the protocol's first version `foxglove.sdk.v1` (the same
// messages as the client's `foxglove.websocket.v1`, schemas inline) and accepts no other name.
const ws = new WebSocket(url, ["foxglove.sdk.v1"]);
const client = new FoxgloveClient({ ws });
const channels = [];
const bySubscription = new Map();
const topics = {};

client.on("advertise", (advertised) => {
  for (const ch of advertised) {
    channels.push(ch);
    const reader = ch.schemaEncoding === "ros2msg" && ch.encoding === "cdr"
      ? new MessageReader(parse(ch.schema, { ros2: true }))
      : undefined;
    bySubscription.set(client.subscribe(ch.id), { ch, reader });
  }
  if (stall) {
    // The subscriptions are sent; from here on nothing is read, and the kernel's buffers
    // fill with what the server sends.
    setTimeout(() => {
      ws.pause();
      console.log(JSON.stringify({ stalled: counts() }));
    }, 200);
  }
});

client.on("message", ({ subscriptionId, data }) => {
  const sub = bySubscription.get(subscriptionId);
  if (!sub) return;
  const t = (topics[sub.ch.topic] ??= { count: 0, trailing: 0, stamps: [], first: null, last: null });
  t.count += 1;
  if (!sub.reader || stall) return;
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  const msg = sub.reader.readMessage(bytes);
  if (sub.reader.lastReadHadTrailingBytes()) t.trailing += 1;
  const stamp = msg.header?.stamp ?? msg.clock;
  if (stamp) t.stamps.push(stamp.sec + stamp.nanosec * 1e-9);
  const shown = sub.ch.schemaName === "sensor_msgs/msg/PointCloud2" ? cloud(msg) : summary(msg);
  t.first ??= shown;
  t.last = shown;
});

// A message with its byte arrays (and long number arrays) replaced by their lengths.
function summary(value) {
  if (ArrayBuffer.isView(value)) return { length: value.length };
  if (Array.isArray(value)) return value.map(summary);
  if (value && typeof value === "object") {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, summary(v)]));
  }
  if (typeof value === "bigint") return Number(value);
  // JSON has no NaN: a ROS "no value" shows as null.
  return value;
}

// A PointCloud2 by its fields: the layout, the points' x, y, z read at their offsets (how many
// are finite, their bounds) and the phases present.
function cloud(msg) {
  const field = (name) => msg.fields.find((f) => f.name === name);
  const view = new DataView(msg.data.buffer, msg.data.byteOffset, msg.data.byteLength);
  const n = msg.width * msg.height;
  let finite = 0;
  const phases = new Set();
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < n; i++) {
    const xyz = ["x", "y", "z"].map((f) =>
      view.getFloat32(i * msg.point_step + field(f).offset, !msg.is_bigendian));
    phases.add(view.getUint8(i * msg.point_step + field("phase").offset));
    if (xyz.every(Number.isFinite)) {
      finite += 1;
      xyz.forEach((v, k) => { lo[k] = Math.min(lo[k], v); hi[k] = Math.max(hi[k], v); });
    }
  }
  return {
    points: n,
    point_step: msg.point_step,
    bytes: msg.data.length,
    fields: msg.fields.map((f) => [f.name, f.offset, f.datatype, f.count]),
    finite,
    phases: [...phases].sort(),
    lo,
    hi,
  };
}

function counts() {
  return Object.fromEntries(Object.entries(topics).map(([k, t]) => [k, t.count]));
}

let done = false;
function finish() {
  if (done) return;
  done = true;
  if (stall) {
    console.log(JSON.stringify({ counts: counts() }));
  } else {
    const advertised = channels.map(({ topic, encoding, schemaName, schemaEncoding }) =>
      ({ topic, encoding, schemaName, schemaEncoding }));
    console.log(JSON.stringify({ channels: advertised, topics }));
  }
  process.exit(0);
}

client.on("close", finish);
client.on("error", (e) => console.error(`client error: ${e?.message ?? e}`));
setTimeout(finish, Number(secondsArg) * 1000);
