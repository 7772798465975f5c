// An independent MCAP writer for rigcal's reader test: Foxglove's @mcap/core and
// @foxglove/rosmsg2-serialization serialise the clouds given as JSON into sensor_msgs/PointCloud2
// messages, one topic per field layout the common drivers publish:
//   /velodyne/points  x y z intensity f32, ring u16, time f32 s after the stamp (velodyne_pointcloud)
//   /ouster/points    x y z intensity f32, t u32 ns after the stamp, reflectivity ring u16 (ouster-ros)
//   /hesai/points     x y z intensity f32, timestamp f64 absolute s, ring u16 (hesai ROS driver)
//   /livox/points     x y z intensity f32, offset_time u32 ns after the stamp (livox)
// Usage: node write_clouds.mjs clouds.json out.mcap
// clouds.json: {"scans": [{"stamp_ns": "<int as text>", "frame_id": "...",
//                          "x": [...], "y": [...], "z": [...], "intensity": [...], "ring": [...], "offset_ns": [...]}]}
import { readFileSync, writeFileSync } from "node:fs";
import { McapWriter } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";

// sensor_msgs/msg/PointCloud2 and its dependencies, as rosbag2 stores them in an MCAP schema.
const definition = `std_msgs/Header header
uint32 height
uint32 width
PointField[] fields
bool is_bigendian
uint32 point_step
uint32 row_step
uint8[] data
bool is_dense
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
================================================================================
MSG: sensor_msgs/PointField
uint8 INT8    = 1
uint8 UINT8   = 2
uint8 INT16   = 3
uint8 UINT16  = 4
uint8 INT32   = 5
uint8 UINT32  = 6
uint8 FLOAT32 = 7
uint8 FLOAT64 = 8
string name
uint32 offset
uint8 datatype
uint32 count
`;

const F32 = 7, F64 = 8, U16 = 4, U32 = 6;
// [name, offset, datatype, value(scan, i, stampNs)]
const xyzi = [
  ["x", 0, F32, (s, i) => s.x[i]],
  ["y", 4, F32, (s, i) => s.y[i]],
  ["z", 8, F32, (s, i) => s.z[i]],
];
const layouts = {
  "/velodyne/points": { step: 32, fields: [...xyzi, ["intensity", 16, F32, (s, i) => s.intensity[i]],
    ["ring", 20, U16, (s, i) => s.ring[i]], ["time", 24, F32, (s, i) => s.offset_ns[i] / 1e9]] },
  "/ouster/points": { step: 48, fields: [...xyzi, ["intensity", 16, F32, (s, i) => s.intensity[i]],
    ["t", 20, U32, (s, i) => s.offset_ns[i]], ["reflectivity", 24, U16, () => 0], ["ring", 26, U16, (s, i) => s.ring[i]]] },
  "/hesai/points": { step: 48, fields: [...xyzi, ["intensity", 16, F32, (s, i) => s.intensity[i]],
    ["timestamp", 24, F64, (s, i, stamp) => Number(stamp + BigInt(s.offset_ns[i])) / 1e9],
    ["ring", 32, U16, (s, i) => s.ring[i]]] },
  "/livox/points": { step: 20, fields: [...xyzi, ["intensity", 12, F32, (s, i) => s.intensity[i]],
    ["offset_time", 16, U32, (s, i) => s.offset_ns[i]]] },
};

function pack(scan, layout, stamp) {
  const n = scan.x.length;
  const data = new Uint8Array(n * layout.step);
  const view = new DataView(data.buffer);
  for (let i = 0; i < n; ++i) {
    const base = i * layout.step;
    for (const [, offset, type, value] of layout.fields) {
      const v = value(scan, i, stamp);
      if (type === F32) view.setFloat32(base + offset, v, true);
      else if (type === F64) view.setFloat64(base + offset, v, true);
      else if (type === U16) view.setUint16(base + offset, v, true);
      else view.setUint32(base + offset, v, true);
    }
  }
  return data;
}

const [input, output] = process.argv.slice(2);
if (!input || !output) {
  console.error("usage: node write_clouds.mjs clouds.json out.mcap");
  process.exit(2);
}
const { scans } = JSON.parse(readFileSync(input, "utf8"));
const cdr = new MessageWriter(parse(definition, { ros2: true }));

const parts = [];
let size = 0n;
const writable = {
  position: () => size,
  write: async (buffer) => {
    parts.push(buffer.slice());
    size += BigInt(buffer.byteLength);
  },
};
const writer = new McapWriter({ writable, chunkSize: 256 * 1024 });
await writer.start({ profile: "ros2", library: "rigcal npm interop test" });
const schemaId = await writer.registerSchema({
  name: "sensor_msgs/msg/PointCloud2",
  encoding: "ros2msg",
  data: new TextEncoder().encode(definition),
});
const channels = {};
for (const topic of Object.keys(layouts))
  channels[topic] = await writer.registerChannel({ topic, schemaId, messageEncoding: "cdr", metadata: new Map() });

let sequence = 0;
for (const scan of scans) {
  const stamp = BigInt(scan.stamp_ns);
  const end = stamp + BigInt(Math.max(0, ...scan.offset_ns));
  for (const [topic, layout] of Object.entries(layouts)) {
    const message = {
      header: { stamp: { sec: Number(stamp / 1000000000n), nanosec: Number(stamp % 1000000000n) }, frame_id: scan.frame_id },
      height: 1,
      width: scan.x.length,
      fields: layout.fields.map(([name, offset, datatype]) => ({ name, offset, datatype, count: 1 })),
      is_bigendian: false,
      point_step: layout.step,
      row_step: layout.step * scan.x.length,
      data: pack(scan, layout, stamp),
      is_dense: true,
    };
    await writer.addMessage({ channelId: channels[topic], sequence: sequence++, logTime: end, publishTime: end,
                              data: cdr.writeMessage(message) });
  }
}
await writer.end();
writeFileSync(output, Buffer.concat(parts));
console.log(`wrote ${output}: ${scans.length} clouds x ${Object.keys(layouts).length} layouts`);
