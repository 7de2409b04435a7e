// For the harnesses whose parser opens the files an input names (calibration data files, a
// rig's camera files): the input is several files separated by NUL bytes, written into a
// folder of this process under the temporary directory. The folder is emptied for every input,
// so that an input sees only the files it brings, and removed at exit (not when libFuzzer is
// stopped by SIGUSR1, which skips exit handlers: scripts/fuzz.sh removes its TMPDIR then).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace fuzz {

// The input's files: the text up to the first NUL, then each part between further NULs.
inline std::vector<std::string_view> split_at_nul(std::string_view input) {
  std::vector<std::string_view> parts;
  for (size_t start = 0;;) {
    const size_t end = input.find('\0', start);
    parts.push_back(input.substr(start, end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

// Without '/' and '\' no string of a JSON or YAML text can be a path (an escaped '/' needs a
// backslash), so what such a text names relative to the scratch folder stays in it: a file the
// input brought, a missing one, or the folder itself or its parent ("." and ".."), which read
// as empty. Texts that could name other files, "/dev/zero" or "../../etc", are skipped.
inline bool could_name_a_path(std::string_view text) {
  return text.find_first_of("/\\") != std::string_view::npos;
}

inline std::filesystem::path& scratch_folder() {
  static std::filesystem::path folder;
  return folder;
}

// The folder `harness`.PID, empty.
inline const std::filesystem::path& fresh_scratch_folder(std::string_view harness) {
  std::filesystem::path& folder = scratch_folder();
  if (folder.empty()) {
    folder = std::filesystem::temp_directory_path() /
             (std::string(harness) + "." + std::to_string(getpid()));
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratch_folder(), ignored);
    });
  }
  std::filesystem::remove_all(folder);
  std::filesystem::create_directory(folder);
  return folder;
}

// The values written after `key` (`key: value`, `"key": "value"`), found by eye rather than by
// the grammar: they only decide which files to create, not what the parser may open.
inline std::vector<std::string> values_after(std::string_view text, std::string_view key) {
  std::vector<std::string> values;
  for (size_t at = text.find(key); at != std::string_view::npos; at = text.find(key, at + 1)) {
    size_t i = at + key.size();
    auto skip = [&](std::string_view chars) {
      while (i < text.size() && chars.find(text[i]) != std::string_view::npos) ++i;
    };
    skip("\"' \t");
    if (i >= text.size() || text[i] != ':') continue;
    ++i;
    skip("\"' \t");
    const size_t end = text.find_first_of("\"',}]# \t\r\n", i);
    values.emplace_back(text.substr(i, end == std::string_view::npos ? end : end - i));
  }
  return values;
}

// Writes `contents[i]` as `names[i]` in `folder` (the last of `contents` for the names beyond),
// skipping names that are not one file's name.
inline void write_files(const std::filesystem::path& folder, const std::vector<std::string>& names,
                        const std::vector<std::string_view>& contents) {
  if (contents.empty()) return;
  for (size_t i = 0; i < names.size() && i < 16; ++i) {
    const std::string& name = names[i];
    if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) {
      continue;
    }
    const std::string_view text = contents[std::min(i, contents.size() - 1)];
    std::ofstream out(folder / name, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
}

}  // namespace fuzz
