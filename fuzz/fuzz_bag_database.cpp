// A bag's .db3 from anywhere, truncated or corrupt: BagReader reads what is readable and reports
// the rest in problems(); only a bag with nothing readable throws, and only BagError. Reading
// never throws. The input is the database of a bag directory whose metadata.yaml lists it, with
// the input's last byte as its message count (salvage estimates what is lost from it).
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_metadata.hpp>
#include <mocap/bag/bag_reader.hpp>

#include "fuzz/scratch_files.hpp"

namespace {

namespace fs = std::filesystem;
using mocap::bag::BagMessage;
using mocap::bag::BagMetadata;

void write_file(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

bool is_listed(const BagMetadata& metadata, const mocap::bag::BagTopic* topic) {
  for (const auto& listed : metadata.topics) {
    if (&listed == topic) return true;
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A fresh directory each time: SQLite may leave -shm or -journal files that would change how
  // the next input opens.
  const fs::path& bag = fuzz::fresh_scratch_folder("fuzz_bag_database");
  write_file(bag / "bag_0.db3", std::string_view(reinterpret_cast<const char*>(data), size));
  BagMetadata listed;
  listed.files = {{"bag_0.db3", 0, 0, size > 0 ? data[size - 1] : 0u}};
  write_file(bag / "metadata.yaml", mocap::bag::format_metadata_yaml(listed));

  std::optional<mocap::bag::BagReader> reader;
  try {
    reader.emplace(bag.string());
  } catch (const mocap::bag::BagError&) {
    return 0;
  }
  // Counted once per file and per topic, whatever was damaged.
  const BagMetadata& metadata = reader->metadata();
  uint64_t per_topic = 0, per_file = 0;
  for (const auto& topic : metadata.topics) per_topic += topic.message_count;
  for (const auto& file : metadata.files) per_file += file.message_count;
  if (per_topic != metadata.message_count || per_file != metadata.message_count) std::abort();

  // Half way, a filter to the first message's topic; then everything again from the start.
  BagMessage message;
  std::optional<std::string> only;
  while (reader->next(message)) {
    if (!is_listed(metadata, message.topic)) std::abort();
    if (only && message.topic->name != *only) std::abort();
    if (!only) {
      only = message.topic->name;
      reader->set_topic_filter({*only});
    }
  }
  reader->rewind();
  reader->set_topic_filter({});
  while (reader->next(message)) {
    if (!is_listed(metadata, message.topic)) std::abort();
  }
  for (const std::string& problem : reader->problems()) {
    if (problem.empty()) std::abort();
  }
  return 0;
}
