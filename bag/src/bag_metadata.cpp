#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_metadata.hpp>

#include <algorithm>
#include <initializer_list>
#include <optional>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <mocap/config_reader.hpp>

namespace mocap::bag {
namespace {

// rmw's enum numbers (rmw/types.h), as rosbag2 writes them.
enum RmwHistory { kHistorySystemDefault = 0, kHistoryKeepLast = 1, kHistoryKeepAll = 2 };
enum RmwReliability { kReliabilitySystemDefault = 0, kReliable = 1, kBestEffort = 2 };
enum RmwDurability { kDurabilitySystemDefault = 0, kTransientLocal = 1, kVolatile = 2 };
constexpr int kLivelinessAutomatic = 1;

// The "infinite" duration rmw reports for an unset deadline, lifespan and lease: Humble's
// rosbag2 writes RMW_DURATION_INFINITE (INT64_MAX nanoseconds) split into seconds and
// nanoseconds.
constexpr std::string_view kInfiniteDuration = "sec: 9223372036\n    nsec: 854775807";

// A scalar as yaml-cpp would leave it plain when it is safely plain; anything else double
// quoted, so that a topic name like "/a: b" cannot change the document's structure.
std::string yaml_scalar(std::string_view text) {
  auto plain_char = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '/' || c == '.' || c == '-';
  };
  bool plain = !text.empty() && text.front() != '-' && text.front() != '.' && text != "null" &&
               text != "Null" && text != "NULL" &&
               std::all_of(text.begin(), text.end(), plain_char);
  if (plain) return std::string(text);
  std::string out = "\"";
  for (char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
        } else {
          out += c;
        }
    }
  }
  out += '"';
  return out;
}

// Walks a parsed metadata.yaml, naming the line and the key's path in every error
// ("metadata.yaml:3: rosbag2_bagfile_information.version: 10 is not supported"). Keys it does
// not know are left alone: rosbag2 adds keys from version to version.
class Reader : public ConfigReader<BagError> {
 public:
  using ConfigReader::ConfigReader;

  // `path` at `node` is wrong: `why`.
  [[noreturn]] void fail(const YAML::Node& node, const std::string& path,
                         std::string_view why) const {
    ConfigReader::fail(node, fmt::format("{}: {}", path, why));
  }

  YAML::Node required(const YAML::Node& map, const std::string& key,
                      const std::string& path) const {
    YAML::Node node = optional(map, key, path);
    if (!node) fail(map, path + "." + key, "missing");
    return node;
  }

  YAML::Node optional(const YAML::Node& map, const std::string& key,
                      const std::string& path) const {
    if (!map.IsMap()) fail(map, path, "not a map");
    return map[key];
  }

  template <typename T>
  T value(const YAML::Node& node, const std::string& path, std::string_view expected) const {
    if (!node.IsScalar()) fail(node, path, fmt::format("not {}", expected));
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail(node, path, fmt::format("\"{}\" is not {}", node.Scalar(), expected));
    }
  }

  // `map.key.subkey` as an integer, or `fallback` when `map.key` is absent.
  int64_t nested_int(const YAML::Node& map, const std::string& key, const std::string& subkey,
                     const std::string& path, int64_t fallback) const {
    YAML::Node outer = optional(map, key, path);
    if (!outer) return fallback;
    const std::string outer_path = path + "." + key;
    return value<int64_t>(required(outer, subkey, outer_path), outer_path + "." + subkey,
                          "an integer");
  }

  YAML::Node sequence(const YAML::Node& map, const std::string& key,
                      const std::string& path) const {
    YAML::Node node = optional(map, key, path);
    if (node && !node.IsNull() && !node.IsSequence()) fail(node, path + "." + key, "not a list");
    return node;
  }
};

std::optional<int64_t> int_at(const YAML::Node& map, const char* key) {
  try {
    YAML::Node node = map[key];
    if (node && node.IsScalar()) return node.as<int64_t>();
  } catch (const YAML::Exception&) {
  }
  return std::nullopt;
}

// A QoS policy as rosbag2 writes it: a number up to metadata version 8, its name from
// version 9 on ("keep_last", "reliable", "transient_local"). Names map to the same numbers.
std::optional<int64_t> policy_at(const YAML::Node& map, const char* key,
                                 std::initializer_list<std::pair<std::string_view, int>> names) {
  if (auto number = int_at(map, key)) return number;
  const YAML::Node node = map[key];
  if (!node || !node.IsScalar()) return std::nullopt;
  for (const auto& [name, value] : names) {
    if (node.Scalar() == name) return value;
  }
  return std::nullopt;
}

// rosbag2_bagfile_information.topics_with_message_count.
std::vector<BagTopic> read_topics(const Reader& reader, const YAML::Node& root,
                                  const std::string& root_path) {
  std::vector<BagTopic> topics_read;
  const std::string topics_path = root_path + ".topics_with_message_count";
  if (YAML::Node topics = reader.sequence(root, "topics_with_message_count", root_path);
      topics && topics.IsSequence()) {
    for (size_t i = 0; i < topics.size(); ++i) {
      const std::string entry_path = fmt::format("{}[{}]", topics_path, i);
      const YAML::Node entry = topics[i];
      const std::string topic_path = entry_path + ".topic_metadata";
      YAML::Node topic_node = reader.required(entry, "topic_metadata", entry_path);
      BagTopic topic;
      topic.name = reader.value<std::string>(reader.required(topic_node, "name", topic_path),
                                             topic_path + ".name", "a string");
      topic.type = reader.value<std::string>(reader.required(topic_node, "type", topic_path),
                                             topic_path + ".type", "a string");
      if (YAML::Node format = reader.optional(topic_node, "serialization_format", topic_path)) {
        topic.serialization_format =
            reader.value<std::string>(format, topic_path + ".serialization_format", "a string");
      }
      if (YAML::Node qos = reader.optional(topic_node, "offered_qos_profiles", topic_path)) {
        // Jazzy writes the profiles as a YAML list rather than a string holding one.
        topic.offered_qos = qos.IsScalar() ? parse_offered_qos_profiles(qos.Scalar())
                                           : parse_offered_qos_profiles(YAML::Dump(qos));
      }
      if (YAML::Node count = reader.optional(entry, "message_count", entry_path)) {
        topic.message_count =
            reader.value<uint64_t>(count, entry_path + ".message_count", "a count");
      }
      topics_read.push_back(std::move(topic));
    }
  }

  return topics_read;
}

// rosbag2_bagfile_information.files.
std::vector<BagFile> read_files(const Reader& reader, const YAML::Node& root,
                                const std::string& root_path) {
  std::vector<BagFile> files_read;
  const std::string files_path = root_path + ".files";
  if (YAML::Node files = reader.sequence(root, "files", root_path); files && files.IsSequence()) {
    for (size_t i = 0; i < files.size(); ++i) {
      const std::string entry_path = fmt::format("{}[{}]", files_path, i);
      const YAML::Node entry = files[i];
      BagFile file;
      file.path = reader.value<std::string>(reader.required(entry, "path", entry_path),
                                            entry_path + ".path", "a string");
      file.start_ns =
          reader.nested_int(entry, "starting_time", "nanoseconds_since_epoch", entry_path, 0);
      file.duration_ns = reader.nested_int(entry, "duration", "nanoseconds", entry_path, 0);
      if (YAML::Node count = reader.optional(entry, "message_count", entry_path)) {
        file.message_count =
            reader.value<uint64_t>(count, entry_path + ".message_count", "a count");
      }
      files_read.push_back(std::move(file));
    }
  }
  return files_read;
}

}  // namespace

std::string format_offered_qos_profiles(const std::vector<Qos>& offered) {
  std::string out;
  for (const Qos& qos : offered) {
    // rmw has no depth for keep_all (rosbag2 itself writes 0 there), so Qos's keep-all depth,
    // a flow-control bound of this runtime, is not recorded.
    const bool keep_last = qos.history == History::KeepLast;
    if (!out.empty()) out += '\n';
    out += fmt::format(
        "- history: {}\n"
        "  depth: {}\n"
        "  reliability: {}\n"
        "  durability: {}\n"
        "  deadline:\n"
        "    {}\n"
        "  lifespan:\n"
        "    {}\n"
        "  liveliness: {}\n"
        "  liveliness_lease_duration:\n"
        "    {}\n"
        "  avoid_ros_namespace_conventions: false",
        keep_last ? kHistoryKeepLast : kHistoryKeepAll, keep_last ? qos.depth : 0,
        qos.reliability == Reliability::Reliable ? kReliable : kBestEffort,
        qos.durability == Durability::TransientLocal ? kTransientLocal : kVolatile,
        kInfiniteDuration, kInfiniteDuration, kLivelinessAutomatic, kInfiniteDuration);
  }
  return out;
}

std::vector<Qos> parse_offered_qos_profiles(const std::string& yaml) {
  std::vector<Qos> profiles;
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception&) {
    return profiles;
  }
  if (!root.IsSequence()) return profiles;
  for (const YAML::Node& entry : root) {
    if (!entry.IsMap()) continue;
    Qos qos;
    auto history = policy_at(entry, "history",
                             {{"keep_last", kHistoryKeepLast}, {"keep_all", kHistoryKeepAll}});
    auto depth = int_at(entry, "depth");
    if (history == kHistoryKeepLast) {
      qos.history = History::KeepLast;
      if (depth && *depth > 0) qos.depth = static_cast<int>(std::min<int64_t>(*depth, 1 << 30));
    } else if (history == kHistoryKeepAll) {
      qos.history = History::KeepAll;
    }
    auto reliability =
        policy_at(entry, "reliability", {{"reliable", kReliable}, {"best_effort", kBestEffort}});
    if (reliability == kReliable) qos.reliability = Reliability::Reliable;
    if (reliability == kBestEffort) qos.reliability = Reliability::BestEffort;
    auto durability = policy_at(entry, "durability",
                                {{"transient_local", kTransientLocal}, {"volatile", kVolatile}});
    if (durability == kTransientLocal) qos.durability = Durability::TransientLocal;
    if (durability == kVolatile) qos.durability = Durability::Volatile;
    profiles.push_back(qos);
  }
  return profiles;
}

Qos playback_qos(const std::vector<Qos>& offered) {
  if (offered.empty()) return Qos{};
  Qos qos;
  auto all = [&](auto predicate) { return std::all_of(offered.begin(), offered.end(), predicate); };
  qos.reliability = all([](const Qos& q) { return q.reliability == Reliability::Reliable; })
                        ? Reliability::Reliable
                        : Reliability::BestEffort;
  qos.durability = all([](const Qos& q) { return q.durability == Durability::TransientLocal; })
                       ? Durability::TransientLocal
                       : Durability::Volatile;
  // The deepest history any publisher kept, so that a late subscriber of a transient local
  // topic gets back as much as it got from the recorded publishers.
  qos.history = all([](const Qos& q) { return q.history == History::KeepLast; }) ? History::KeepLast
                                                                                 : History::KeepAll;
  qos.depth = 0;
  for (const Qos& q : offered) {
    if (q.history == qos.history) qos.depth = std::max(qos.depth, q.depth);
  }
  if (qos.depth <= 0) qos.depth = Qos{}.depth;
  return qos;
}

std::string format_metadata_yaml(const BagMetadata& metadata) {
  // Written by hand rather than with YAML::Emitter so that the layout is exactly rosbag2's
  // (yaml-cpp's emitter output in Humble), key order and indentation included.
  std::string out = fmt::format(
      "rosbag2_bagfile_information:\n"
      "  version: 5\n"
      "  storage_identifier: {}\n"
      "  duration:\n"
      "    nanoseconds: {}\n"
      "  starting_time:\n"
      "    nanoseconds_since_epoch: {}\n"
      "  message_count: {}\n",
      yaml_scalar(metadata.storage_identifier), metadata.duration_ns, metadata.start_ns,
      metadata.message_count);
  out += "  topics_with_message_count:";
  if (metadata.topics.empty()) out += " []";
  out += '\n';
  for (const BagTopic& topic : metadata.topics) {
    out += fmt::format(
        "    - topic_metadata:\n"
        "        name: {}\n"
        "        type: {}\n"
        "        serialization_format: {}\n"
        "        offered_qos_profiles: {}\n"
        "      message_count: {}\n",
        yaml_scalar(topic.name), yaml_scalar(topic.type), yaml_scalar(topic.serialization_format),
        // Always quoted, as rosbag2 writes it: an empty list is "" and never plain.
        topic.offered_qos.empty() ? std::string("\"\"")
                                  : yaml_scalar(format_offered_qos_profiles(topic.offered_qos)),
        topic.message_count);
  }
  out +=
      "  compression_format: \"\"\n"
      "  compression_mode: \"\"\n"
      "  relative_file_paths:";
  if (metadata.files.empty()) out += " []";
  out += '\n';
  for (const BagFile& file : metadata.files)
    out += fmt::format("    - {}\n", yaml_scalar(file.path));
  out += "  files:";
  if (metadata.files.empty()) out += " []";
  out += '\n';
  for (const BagFile& file : metadata.files) {
    out += fmt::format(
        "    - path: {}\n"
        "      starting_time:\n"
        "        nanoseconds_since_epoch: {}\n"
        "      duration:\n"
        "        nanoseconds: {}\n"
        "      message_count: {}\n",
        yaml_scalar(file.path), file.start_ns, file.duration_ns, file.message_count);
  }
  return out;
}

BagMetadata parse_metadata_yaml(const std::string& text, const std::string& source) {
  Reader reader(source);
  YAML::Node document = reader.parse(text);
  const std::string root_path = "rosbag2_bagfile_information";
  if (!document.IsMap()) reader.fail(document, root_path, "missing");
  YAML::Node root = reader.required(document, root_path, "");
  if (!root.IsMap()) reader.fail(root, root_path, "not a map");

  const auto version = reader.value<int64_t>(reader.required(root, "version", root_path),
                                             root_path + ".version", "an integer");
  if (version < 4 || version > 9) {
    reader.fail(root["version"], root_path + ".version",
                fmt::format("{} is not supported (rosbag2 versions 4 to 9 are)", version));
  }
  std::string identifier = "sqlite3";
  if (YAML::Node storage = reader.optional(root, "storage_identifier", root_path)) {
    identifier = reader.value<std::string>(storage, root_path + ".storage_identifier", "a string");
    if (identifier != "sqlite3" && identifier != "mcap") {
      reader.fail(storage, root_path + ".storage_identifier",
                  fmt::format("\"{}\" is not supported (sqlite3 and mcap are)", identifier));
    }
  }
  if (YAML::Node compression = reader.optional(root, "compression_format", root_path)) {
    auto format =
        reader.value<std::string>(compression, root_path + ".compression_format", "a string");
    if (!format.empty()) {
      reader.fail(compression, root_path + ".compression_format",
                  fmt::format("\"{}\": compressed bags are not supported", format));
    }
  }

  BagMetadata metadata;
  metadata.storage_identifier = identifier;
  metadata.duration_ns = reader.nested_int(root, "duration", "nanoseconds", root_path, 0);
  metadata.start_ns =
      reader.nested_int(root, "starting_time", "nanoseconds_since_epoch", root_path, 0);
  if (YAML::Node count = reader.optional(root, "message_count", root_path)) {
    metadata.message_count = reader.value<uint64_t>(count, root_path + ".message_count", "a count");
  }

  metadata.topics = read_topics(reader, root, root_path);
  metadata.files = read_files(reader, root, root_path);
  // Version 4 has only the paths; later versions have both, and the paths are what rosbag2
  // opens.
  const std::string paths_path = root_path + ".relative_file_paths";
  if (YAML::Node paths = reader.sequence(root, "relative_file_paths", root_path);
      paths && paths.IsSequence()) {
    std::vector<BagFile> listed;
    for (size_t i = 0; i < paths.size(); ++i) {
      BagFile file;
      file.path =
          reader.value<std::string>(paths[i], fmt::format("{}[{}]", paths_path, i), "a string");
      auto known = std::find_if(metadata.files.begin(), metadata.files.end(),
                                [&](const BagFile& f) { return f.path == file.path; });
      listed.push_back(known != metadata.files.end() ? *known : file);
    }
    metadata.files = std::move(listed);
  }
  return metadata;
}

}  // namespace mocap::bag
