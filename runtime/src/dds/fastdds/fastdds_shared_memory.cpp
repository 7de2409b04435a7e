#include "dds/fastdds/fastdds_shared_memory.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <regex>
#include <string>
#include <vector>

namespace mocap {
namespace fs = std::filesystem;

namespace {

// True when nobody holds the lock: we could take it (and let it go at once).
bool unlocked(const fs::path& lock_file) {
  int fd = ::open(lock_file.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);
  return free;
}

void remove_counting(const fs::path& file, SharedMemoryCleanup& done) {
  std::error_code error;
  uintmax_t size = fs::file_size(file, error);
  if (fs::remove(file, error)) {
    ++done.files;
    done.bytes += error ? 0 : size;
  }
}

}  // namespace

SharedMemoryCleanup remove_orphaned_shared_memory(const fs::path& directory,
                                                  std::chrono::seconds min_age) {
  static const std::regex lock_name(R"(fastrtps_[0-9a-f]{16}_el)");
  SharedMemoryCleanup done;
  std::error_code error;
  auto now = fs::file_time_type::clock::now();
  std::vector<fs::path> orphans;
  for (const auto& entry : fs::directory_iterator(directory, error)) {
    std::string name = entry.path().filename().string();
    if (!std::regex_match(name, lock_name)) continue;
    auto written = fs::last_write_time(entry.path(), error);
    if (error || now - written < min_age) continue;
    if (unlocked(entry.path())) orphans.push_back(entry.path());
  }
  for (const fs::path& lock : orphans) {
    std::string guarded = lock.filename().string();
    guarded.resize(guarded.size() - 3);  // without "_el"
    remove_counting(directory / guarded, done);
    remove_counting(lock, done);
  }
  return done;
}

std::optional<int> unused_participant_id(int domain_id, const fs::path& directory) {
  // Fast DDS's default port parameters (RTPS 2.2, 9.6.1.1): a participant reads metatraffic on
  // port 7400 + 250 * domain + 10 + 2 * id and user data on the next one; from id 120 on they
  // would be the next domain's.
  constexpr int kParticipantIds = 120;
  auto first_port = [domain_id](int id) { return 7400 + 250 * domain_id + 10 + 2 * id; };
  std::optional<int> oldest_dead;
  fs::file_time_type oldest_dead_time = fs::file_time_type::max();
  for (int id = 0; id < kParticipantIds && first_port(id) + 1 <= 65535; ++id) {
    bool used = false;
    bool live = false;
    fs::file_time_type opened = fs::file_time_type::max();
    for (int port : {first_port(id), first_port(id) + 1}) {
      fs::path lock = directory / ("fastrtps_port" + std::to_string(port) + "_el");
      std::error_code error;
      auto written = fs::last_write_time(lock, error);
      if (error) continue;  // no lock file
      used = true;
      live = live || !unlocked(lock);
      opened = std::min(opened, written);
    }
    if (!used) return id;
    if (!live && opened < oldest_dead_time) {
      oldest_dead = id;
      oldest_dead_time = opened;
    }
  }
  return oldest_dead;
}

}  // namespace mocap
