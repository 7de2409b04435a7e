#include <mocap/message_type.hpp>

#include <algorithm>
#include <map>
#include <mutex>
#include <regex>
#include <set>

namespace mocap {
namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, const MessageType*, std::less<>> by_name;
};

Registry& registry() {
  static Registry instance;
  return instance;
}

}  // namespace

MessageType::MessageType(std::string name, std::string definition)
    : name_(std::move(name)), dds_name_(dds_type_name(name_)), definition_(std::move(definition)) {}

void register_message_type(const MessageType& type) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.by_name[type.name()] = &type;
  r.by_name[type.dds_name()] = &type;
}

const MessageType* find_message_type(std::string_view name) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  auto it = r.by_name.find(name);
  return it == r.by_name.end() ? nullptr : it->second;
}

std::vector<const MessageType*> registered_message_types() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  std::set<const MessageType*> unique;
  for (const auto& [name, type] : r.by_name) unique.insert(type);
  std::vector<const MessageType*> types(unique.begin(), unique.end());
  std::sort(types.begin(), types.end(),
            [](const MessageType* a, const MessageType* b) { return a->name() < b->name(); });
  return types;
}

std::string full_definition(const MessageType& type) {
  static const std::regex include_line(
      R"re(#include\s+"([A-Za-z0-9_]+/msg/[A-Za-z0-9_]+)\.idl")re");
  std::string text = type.definition();
  std::set<std::string> done{type.name()};
  std::vector<std::string> pending;
  auto collect = [&](const std::string& definition) {
    for (std::sregex_iterator it(definition.begin(), definition.end(), include_line), end;
         it != end; ++it) {
      std::string name = (*it)[1];
      if (done.insert(name).second) pending.push_back(name);
    }
  };
  collect(type.definition());
  while (!pending.empty()) {
    std::string name = pending.front();
    pending.erase(pending.begin());
    const MessageType* included = find_message_type(name);
    if (included == nullptr) continue;  // the reader then reports the type as unknown
    text += "\n================================================================================\n";
    text += "IDL: " + name + "\n" + included->definition();
    collect(included->definition());
  }
  return text;
}

std::string ros2idl_schema(std::string_view root_type, std::string_view full_definition) {
  std::string out = std::string(80, '=') + "\nIDL: " + std::string(root_type) + "\n";
  size_t start = 0;
  while (start < full_definition.size()) {
    size_t end = full_definition.find('\n', start);
    if (end == std::string_view::npos) end = full_definition.size();
    std::string_view line = full_definition.substr(start, end - start);
    if (!line.starts_with("#ifndef") && !line.starts_with("#define") &&
        !line.starts_with("#endif")) {
      out.append(line);
      out.push_back('\n');
    }
    start = end + 1;
  }
  return out;
}

std::string dds_type_name(std::string_view ros_name) {
  // pkg/msg/Type -> pkg::msg::dds_::Type_ (also srv and action interfaces).
  size_t first = ros_name.find('/');
  size_t last = ros_name.rfind('/');
  if (first == std::string_view::npos || first == last) return std::string(ros_name);
  std::string name(ros_name.substr(0, last));
  std::string::size_type at = 0;
  while ((at = name.find('/', at)) != std::string::npos) name.replace(at, 1, "::");
  return name + "::dds_::" + std::string(ros_name.substr(last + 1)) + "_";
}

std::string ros_type_name(std::string_view dds_name) {
  constexpr std::string_view marker = "::dds_::";
  size_t at = dds_name.rfind(marker);
  if (at == std::string_view::npos || !dds_name.ends_with('_')) return std::string(dds_name);
  std::string name(dds_name.substr(0, at));
  std::string::size_type pos = 0;
  while ((pos = name.find("::", pos)) != std::string::npos) name.replace(pos, 2, "/");
  std::string_view type = dds_name.substr(at + marker.size());
  type.remove_suffix(1);
  return name + "/" + std::string(type);
}

std::string dds_topic_name(std::string_view ros_topic) {
  if (ros_topic.starts_with('/')) return "rt" + std::string(ros_topic);
  return std::string(ros_topic);
}

std::string ros_topic_name(std::string_view dds_topic) {
  if (dds_topic.starts_with("rt/")) return std::string(dds_topic.substr(2));
  return std::string(dds_topic);
}

}  // namespace mocap
