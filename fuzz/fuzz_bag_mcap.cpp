// An MCAP file from anywhere, cut short or garbled: FileReader scans what is readable and says
// the rest in problems(); only a file that is not MCAP at all throws, and only BagError. Every
// message it places is on a channel it knows, and reading it never crashes (a BagError at most,
// for a chunk that no longer reads). Then the same file as a bag directory's through BagReader.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string_view>

#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_reader.hpp>

#include "fuzz/scratch_files.hpp"
#include "mcap_reader.hpp"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path& bag = fuzz::fresh_scratch_folder("fuzz_bag_mcap");
  {
    std::ofstream out(bag / "bag_0.mcap", std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  std::optional<mocap::bag::mcap::FileReader> reader;
  try {
    reader.emplace((bag / "bag_0.mcap").string());
  } catch (const mocap::bag::BagError&) {
    return 0;
  }
  for (const mocap::bag::mcap::MessagePlace& place : reader->messages()) {
    if (reader->channels().count(place.channel_id) == 0) std::abort();
    try {
      reader->data(place);
    } catch (const mocap::bag::BagError&) {
    }
  }
  for (const std::string& problem : reader->problems()) {
    if (problem.empty()) std::abort();
  }

  try {
    mocap::bag::BagReader bag_reader(bag.string());
    mocap::bag::BagMessage message;
    uint64_t read = 0;
    while (bag_reader.next(message)) ++read;
    if (read > bag_reader.metadata().message_count) std::abort();
  } catch (const mocap::bag::BagError&) {
  }
  return 0;
}
