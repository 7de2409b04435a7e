// metadata.yaml of a bag from anywhere (ROS 2 Humble to Jazzy, a killed recorder, a hand
// edit): parse_metadata_yaml returns metadata or throws BagError naming the file, nothing else.
// What parses formats in rosbag2's layout and reads back the same.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_metadata.hpp>

namespace {

using mocap::bag::BagFile;
using mocap::bag::BagMetadata;
using mocap::bag::BagTopic;

bool same(const BagTopic& a, const BagTopic& b) {
  return a.name == b.name && a.type == b.type && a.serialization_format == b.serialization_format &&
         a.offered_qos == b.offered_qos && a.message_count == b.message_count;
}

bool same(const BagFile& a, const BagFile& b) {
  return a.path == b.path && a.start_ns == b.start_ns && a.duration_ns == b.duration_ns &&
         a.message_count == b.message_count;
}

template <typename T>
bool same(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!same(a[i], b[i])) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string source = "fuzz/metadata.yaml";
  BagMetadata metadata;
  try {
    metadata = mocap::bag::parse_metadata_yaml(text, source);
  } catch (const mocap::bag::BagError& error) {
    // "fuzz/metadata.yaml:LINE: ..." or, for what has no line, "fuzz/metadata.yaml: ...".
    if (!std::string_view(error.what()).starts_with(source + ":")) std::abort();
    return 0;
  }
  // Both file lists are written and the paths win; a repeated path reads back as its first
  // entry, as it does from any metadata.yaml that has both lists.
  BagMetadata expected = metadata;
  for (BagFile& file : expected.files) {
    for (const BagFile& first : metadata.files) {
      if (first.path == file.path) {
        file = first;
        break;
      }
    }
  }
  const BagMetadata back =
      mocap::bag::parse_metadata_yaml(mocap::bag::format_metadata_yaml(metadata), "formatted");
  if (back.start_ns != expected.start_ns || back.duration_ns != expected.duration_ns ||
      back.message_count != expected.message_count || !same(back.topics, expected.topics) ||
      !same(back.files, expected.files)) {
    std::abort();
  }
  return 0;
}
