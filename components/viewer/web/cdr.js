// Messages from their "ros2idl" schema and XCDR1 bytes, in the browser (and in Node for the
// tests): parseSchema() reads the IDL the bridge advertises; decode() reads one message.
// Covers what idl/ and ROS 2's common messages use: modules, structs, constants (skipped),
// primitive types, strings, sequences, fixed arrays. uint8/int8 sequences come back as
// Uint8Array/Int8Array views (an image's pixels are not copied).

const PRIMITIVES = {
  boolean: [1, (v, o) => v.getUint8(o) !== 0],
  bool: [1, (v, o) => v.getUint8(o) !== 0],
  char: [1, (v, o) => v.getUint8(o)],
  octet: [1, (v, o) => v.getUint8(o)],
  int8: [1, (v, o) => v.getInt8(o)],
  uint8: [1, (v, o) => v.getUint8(o)],
  int16: [2, (v, o) => v.getInt16(o, true)],
  uint16: [2, (v, o) => v.getUint16(o, true)],
  int32: [4, (v, o) => v.getInt32(o, true)],
  uint32: [4, (v, o) => v.getUint32(o, true)],
  int64: [8, (v, o) => Number(v.getBigInt64(o, true))],
  uint64: [8, (v, o) => Number(v.getBigUint64(o, true))],
  float: [4, (v, o) => v.getFloat32(o, true)],
  double: [8, (v, o) => v.getFloat64(o, true)],
};

function tokenize(text) {
  const source = text
    .replace(/\/\*[\s\S]*?\*\//g, " ")
    .replace(/\/\/[^\n]*/g, " ")
    .split("\n")
    .filter((line) => !/^\s*(#|={10,}|IDL:)/.test(line))
    .join("\n");
  return source.match(/::|[A-Za-z_][A-Za-z0-9_]*|-?[0-9][0-9.eE+-]*|"(?:[^"\\]|\\.)*"|[{}<>;,[\]=()@]/g) ?? [];
}

// The schema's structs by fully qualified name ("geometry_msgs::msg::Pose"): arrays of
// {name, type, dims}; a type is {prim}, {string}, {sequence: type} or {struct: name}.
export function parseSchema(text) {
  const tokens = tokenize(text);
  const structs = new Map();
  let i = 0;
  const expect = (t) => {
    if (tokens[i] !== t) throw new Error(`schema: expected '${t}' at '${tokens.slice(i, i + 5).join(" ")}'`);
    i++;
  };
  const skipStatement = () => {
    let depth = 0;
    while (i < tokens.length) {
      const t = tokens[i++];
      if (t === "{" || t === "(") depth++;
      else if (t === "}" || t === ")") depth--;
      else if (t === ";" && depth <= 0) return;
    }
  };
  const scopedName = () => {
    let name = tokens[i++];
    while (tokens[i] === "::") {
      i++;
      name += "::" + tokens[i++];
    }
    return name;
  };
  const typeSpec = () => {
    if (tokens[i] === "sequence") {
      i++;
      expect("<");
      const element = typeSpec();
      if (tokens[i] === ",") i += 2;
      expect(">");
      return { sequence: element };
    }
    if (tokens[i] === "string" || tokens[i] === "wstring") {
      i++;
      if (tokens[i] === "<") i += 3;
      return { string: true };
    }
    if (tokens[i] === "unsigned") {
      i++;
      const base = tokens[i++];
      const size = { short: "uint16", long: "uint32" }[base];
      if (base === "long" && tokens[i] === "long") {
        i++;
        return { prim: "uint64" };
      }
      return { prim: size };
    }
    if (tokens[i] === "long" && tokens[i + 1] === "long") {
      i += 2;
      return { prim: "int64" };
    }
    const alias = { short: "int16", long: "int32" }[tokens[i]];
    if (alias) {
      i++;
      return { prim: alias };
    }
    const name = scopedName();
    return name in PRIMITIVES ? { prim: name } : { struct: name };
  };
  const annotations = () => {
    while (tokens[i] === "@") {
      i += 2;
      if (tokens[i] === "(") skipStatementParens();
    }
  };
  const skipStatementParens = () => {
    let depth = 0;
    do {
      if (tokens[i] === "(") depth++;
      if (tokens[i] === ")") depth--;
      i++;
    } while (depth > 0 && i < tokens.length);
  };
  const definitions = (scope) => {
    while (i < tokens.length && tokens[i] !== "}") {
      annotations();
      const keyword = tokens[i];
      if (keyword === "module") {
        i++;
        const name = tokens[i++];
        expect("{");
        definitions([...scope, name]);
        expect("}");
        expect(";");
      } else if (keyword === "struct") {
        i++;
        const name = [...scope, tokens[i++]].join("::");
        expect("{");
        const members = [];
        while (tokens[i] !== "}") {
          annotations();
          const type = typeSpec();
          for (;;) {
            const member = { name: tokens[i++], type, dims: [] };
            while (tokens[i] === "[") {
              member.dims.push(Number(tokens[i + 1]));
              i += 3;
            }
            members.push(member);
            if (tokens[i] === ",") i++;
            else break;
          }
          expect(";");
        }
        expect("}");
        expect(";");
        structs.set(name, { scope, members });
      } else {
        skipStatement();  // const, typedef-free enums and the like: not in our messages
      }
    }
  };
  definitions([]);
  // Names used without their module resolve in the scope they were written in.
  for (const [, { scope, members }] of structs) {
    const resolve = (type) => {
      if (type.sequence) resolve(type.sequence);
      if (type.struct && !structs.has(type.struct)) {
        for (let n = scope.length; n >= 0; n--) {
          const candidate = [...scope.slice(0, n), type.struct].join("::");
          if (structs.has(candidate)) {
            type.struct = candidate;
            break;
          }
        }
        if (!structs.has(type.struct)) throw new Error(`schema: unknown type ${type.struct}`);
      }
    };
    members.forEach((m) => resolve(m.type));
  }
  return structs;
}

// Reads one message of type `root` ("pkg/msg/Type" or "pkg::msg::Type") from `bytes` (a
// Uint8Array holding the 4-byte encapsulation header and little-endian XCDR1 data).
export function decode(structs, root, bytes) {
  if (bytes.length < 4 || bytes[1] !== 0x01) {
    throw new Error("not little-endian plain CDR (encapsulation 00 01)");
  }
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let offset = 4;
  const align = (n) => {
    offset += (n - ((offset - 4) % n)) % n;
  };
  const count = () => {
    align(4);
    const n = view.getUint32(offset, true);
    offset += 4;
    if (n > bytes.length) throw new Error("length beyond the message");
    return n;
  };
  const read = (type) => {
    if (type.prim) {
      const [size, get] = PRIMITIVES[type.prim];
      align(size);
      const value = get(view, offset);
      offset += size;
      return value;
    }
    if (type.string) {
      const n = count();
      const text = new TextDecoder().decode(bytes.subarray(offset, offset + Math.max(0, n - 1)));
      offset += n;
      return text;
    }
    if (type.sequence) {
      const n = count();
      const element = type.sequence;
      if (element.prim === "uint8" || element.prim === "octet" || element.prim === "int8") {
        const data = bytes.subarray(offset, offset + n);
        offset += n;
        return element.prim === "int8" ? new Int8Array(data.buffer, data.byteOffset, n) : data;
      }
      const out = new Array(n);
      for (let k = 0; k < n; k++) out[k] = read(element);
      return out;
    }
    const struct = structs.get(type.struct);
    const out = {};
    for (const member of struct.members) {
      if (member.dims.length === 0) {
        out[member.name] = read(member.type);
      } else {
        const total = member.dims.reduce((a, b) => a * b, 1);
        const values = new Array(total);
        for (let k = 0; k < total; k++) values[k] = read(member.type);
        out[member.name] = values;
      }
    }
    return out;
  };
  const name = root.replaceAll("/", "::");
  if (!structs.has(name)) throw new Error(`schema has no ${name}`);
  return read({ struct: name });
}
