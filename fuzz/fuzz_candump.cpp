// candump -L logs, which the bridge replays from anywhere: every line parses or throws
// CandumpError. What parses formats as candump writes it and reads back the same, the stamp
// truncated to microseconds (the log's resolution). CandumpReader, which the bridge uses, reads
// the same records from the file and fails at the first bad line, naming it.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/can_io/candump_log.hpp"
#include "fuzz/scratch_files.hpp"

namespace {

using mocap::can::CandumpError;
using mocap::can::CandumpRecord;

bool same(const CandumpRecord& a, const CandumpRecord& b) {
  return a.stamp_ns == b.stamp_ns && a.interface == b.interface && a.frame == b.frame;
}

std::string_view trim(std::string_view text) {
  constexpr std::string_view kBlanks = " \t\r\n";
  const size_t first = text.find_first_not_of(kBlanks);
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(kBlanks) - first + 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);

  // What the reader must give: the records before the first bad line (blank and '#' lines
  // skipped), then an error for that line.
  std::vector<CandumpRecord> records;
  size_t bad_line = 0;
  size_t line_number = 0;
  for (size_t start = 0; start < text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    CandumpRecord record;
    try {
      record = mocap::can::parse_candump_line(line);
    } catch (const CandumpError&) {
      const std::string_view trimmed = trim(line);
      if (bad_line == 0 && !trimmed.empty() && trimmed.front() != '#') bad_line = line_number;
      continue;
    }
    if (record.frame.stamp_ns != record.stamp_ns) std::abort();
    const std::string formatted = mocap::can::format_candump_line(record);  // must not throw
    CandumpRecord expected = record;
    expected.stamp_ns = record.stamp_ns / 1000 * 1000;
    expected.frame.stamp_ns = expected.stamp_ns;
    if (!same(mocap::can::parse_candump_line(formatted), expected)) std::abort();
    if (bad_line == 0) records.push_back(record);
  }

  const std::string path = (fuzz::fresh_scratch_folder("fuzz_candump") / "can.log").string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
  mocap::can::CandumpReader reader(path);
  size_t read = 0;
  try {
    while (std::optional<CandumpRecord> record = reader.next()) {
      if (read >= records.size() || !same(*record, records[read])) std::abort();
      ++read;
    }
  } catch (const CandumpError& error) {
    const std::string where = path + ":" + std::to_string(bad_line) + ": ";
    if (bad_line == 0 || reader.line_number() != bad_line ||
        std::string_view(error.what()).substr(0, where.size()) != where) {
      std::abort();
    }
    return 0;
  }
  if (bad_line != 0 || read != records.size()) std::abort();
  return 0;
}
