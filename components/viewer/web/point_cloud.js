// sensor_msgs/PointCloud2's packed points. Each field is read where the message's `fields` put
// it (offset, datatype, endianness), so any publisher's layout reads, not only the volume's
// marker cloud (/mocap/markers: x y z body marker id residual cameras, 32 bytes a point).

// PointField's datatypes: DataView's reader for each.
const READERS = {
  1: "getInt8",
  2: "getUint8",
  3: "getInt16",
  4: "getUint16",
  5: "getInt32",
  6: "getUint32",
  7: "getFloat32",
  8: "getFloat64",
};

// The cloud's points as objects with the fields `names` asks for (a field the cloud lacks is
// undefined in each point). Throws on a cloud whose data is shorter than its points.
export function points(cloud, names) {
  const count = cloud.width * cloud.height;
  const { data } = cloud;
  if (data.length < count * cloud.point_step) {
    throw new Error(`PointCloud2: ${data.length} bytes of data for ${count} points of ${cloud.point_step} bytes`);
  }
  const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const little = !cloud.is_bigendian;
  const readers = names.map((name) => {
    const field = cloud.fields.find((f) => f.name === name);
    const reader = field && READERS[field.datatype];
    return reader ? (offset) => view[reader](offset + field.offset, little) : () => undefined;
  });
  const out = new Array(count);
  for (let i = 0; i < count; i++) {
    const point = {};
    names.forEach((name, k) => (point[name] = readers[k](i * cloud.point_step)));
    out[i] = point;
  }
  return out;
}
