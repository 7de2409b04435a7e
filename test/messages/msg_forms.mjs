// The .msg forms of messages, read by Foxglove's own parsers: @foxglove/rosmsg reads each .msg
// file, @foxglove/omgidl-parser reads what mocap_msg_to_idl makes of it and the shipped .idl
// file beside it. All three must give the same fields (type, array, bounds, defaults) and
// constants; any difference is printed and the exit code is 1.
//
//   node msg_forms.mjs <mocap_msg_to_idl> <source dir>
import { parse as parseMsg } from "@foxglove/rosmsg";
import { parseIDL } from "@foxglove/omgidl-parser";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";

const [converter, sourceDir] = process.argv.slice(2);
const idlDir = path.join(sourceDir, "idl");
const testPackageDir = path.join(sourceDir, "test", "messages", "msg");

// IDL without preprocessor lines: omgidl-parser reads one text with every definition in it.
const withoutDirectives = (text) =>
  text.split("\n").filter((line) => !line.startsWith("#")).join("\n");

const messages = []; // { pkg, name, msg, converted, shipped? }
for (const pkg of fs.readdirSync(idlDir).sort()) {
  const dir = path.join(idlDir, pkg, "msg");
  if (!fs.existsSync(dir)) continue;
  for (const file of fs.readdirSync(dir).sort()) {
    if (!file.endsWith(".msg")) continue;
    const name = file.slice(0, -4);
    messages.push({ pkg, name, file: path.join(dir, file), shipped: path.join(dir, `${name}.idl`) });
  }
}
const testKnown = fs.readdirSync(testPackageDir).map((file) => file.replace(/\.(msg|idl)$/, ""));
for (const file of fs.readdirSync(testPackageDir).sort()) {
  if (file.endsWith(".msg"))
    messages.push({ pkg: "mocap_test_msgs", name: file.slice(0, -4), file: path.join(testPackageDir, file) });
}
for (const message of messages) {
  const known = message.pkg === "mocap_test_msgs" ? testKnown.flatMap((type) => ["--known", type]) : [];
  message.msg = fs.readFileSync(message.file, "utf8");
  message.converted = execFileSync(
    converter, ["--package", message.pkg, ...known, "-I", idlDir, message.file, "-"], { encoding: "utf8" });
}

const extraIdl = fs.readFileSync(path.join(testPackageDir, "Corner.idl"), "utf8");
const byName = (definitions) => new Map(definitions.map((definition) => [definition.name, definition]));
const converted = byName(parseIDL(withoutDirectives([...messages.map((m) => m.converted), extraIdl].join("\n"))));
const shipped = byName(parseIDL(withoutDirectives(
  messages.filter((m) => m.shipped).map((m) => fs.readFileSync(m.shipped, "utf8")).join("\n"))));

// rosmsg says "time" for builtin_interfaces/Time, as ROS 1 did.
const primitive = {
  double: "float64", float: "float32", boolean: "bool", octet: "uint8", byte: "uint8", char: "uint8",
  time: "builtin_interfaces/msg/Time", duration: "builtin_interfaces/msg/Duration",
};
function typeName(type, pkg) {
  if (type.includes("::")) return type.replaceAll("::", "/");
  if (type.includes("/")) return type.replace(/^([^/]+)\/([^/]+)$/, "$1/msg/$2");
  if (/^[A-Z]/.test(type)) return `${pkg}/msg/${type}`;
  return primitive[type] ?? type;
}

// Python's tuple repr, as rosidl writes an array's default in IDL: "(1.0, 'a', True)".
function tupleValues(text) {
  const inner = text.trim().replace(/^\(/, "").replace(/,?\)$/, "");
  if (inner === "") return [];
  return inner.match(/'[^']*'|"[^"]*"|[^,\s][^,]*/g).map((item) => {
    item = item.trim();
    if (/^['"]/.test(item)) return item.slice(1, -1);
    if (item === "True" || item === "False") return item === "True";
    return Number(item);
  });
}

const show = (value) => (typeof value === "bigint" ? `${value}` : JSON.stringify(value));
// omgidl-parser hands a string literal over as written; rosmsg reads its escapes.
const unescapeIdl = (text) =>
  text.replace(/\\(u[0-9a-fA-F]{4}|.)/g, (_, c) =>
    c === "n" ? "\n" : c === "r" ? "\r" : c[0] === "u" ? String.fromCharCode(parseInt(c.slice(1), 16)) : c);
function normalizedField(field, pkg, fromIdl) {
  let defaultValue = field.defaultValue;
  if (fromIdl && typeof defaultValue === "string")
    defaultValue = field.isArray ? tupleValues(unescapeIdl(defaultValue)) : unescapeIdl(defaultValue);
  return {
    name: field.name,
    type: typeName(field.type, pkg),
    isArray: Boolean(field.isArray),
    arrayLength: field.arrayLength ?? field.arrayLengths?.[0],
    arrayUpperBound: field.arrayUpperBound,
    upperBound: field.upperBound,
    default: defaultValue === undefined ? undefined : show(defaultValue),
  };
}
function normalizedConstant(constant, pkg, fromIdl) {
  const type = typeName(constant.type, pkg);
  let value = constant.value;
  if (/int|byte/.test(type)) {
    // omgidl-parser reads an integer constant as a JavaScript number: past 2^53, compare the
    // double both round to.
    const exact = BigInt(value);
    value = exact > 2n ** 53n || exact < -(2n ** 53n) ? `${Number(exact)} (as a double)` : `${exact}`;
  }
  else if (type === "string" && fromIdl) value = unescapeIdl(value);
  return { name: constant.name, type, value };
}

let failures = 0;
function same(what, a, b) {
  const left = JSON.stringify(a, null, 1);
  const right = JSON.stringify(b, null, 1);
  if (left !== right) {
    failures += 1;
    console.log(`DIFFER ${what}\n  ${left.replaceAll("\n", "")}\n  ${right.replaceAll("\n", "")}`);
  }
}

for (const message of messages) {
  const id = `${message.pkg}/msg/${message.name}`;
  const [root] = parseMsg(message.msg, { ros2: true, skipTypeFixup: true });
  const fromMsg = root.definitions.filter((d) => !d.isConstant).map((f) => normalizedField(f, message.pkg, false));
  const msgConstants = root.definitions.filter((d) => d.isConstant).map((c) => normalizedConstant(c, message.pkg, false));
  const idlStruct = converted.get(`${message.pkg}::msg::${message.name}`);
  if (!idlStruct) {
    failures += 1;
    console.log(`MISSING ${id} in the converted IDL`);
    continue;
  }
  let fromIdl = idlStruct.definitions.map((f) => normalizedField(f, message.pkg, true));
  if (fromMsg.length === 0) // rosidl's placeholder member of an empty message
    fromIdl = fromIdl.filter((f) => f.name !== "structure_needs_at_least_one_member");
  same(`${id}: fields of the .msg (rosmsg) and of its IDL (omgidl-parser)`, fromMsg, fromIdl);
  const idlConstants = (converted.get(`${message.pkg}::msg::${message.name}_Constants`)?.definitions ?? [])
    .map((c) => normalizedConstant(c, message.pkg, true));
  same(`${id}: constants of the .msg and of its IDL`, msgConstants, idlConstants);
  if (message.shipped) {
    const shippedStruct = shipped.get(`${message.pkg}::msg::${message.name}`);
    same(`${id}: fields of the converted .msg and of the shipped .idl`, fromIdl,
         shippedStruct?.definitions.map((f) => normalizedField(f, message.pkg, true)));
  }
}
console.log(`${failures === 0 ? "agree" : "differ"}: ${messages.length} messages, ${failures} differences`);
process.exit(failures === 0 ? 0 : 1);
