#include "shared_memory_cleanup.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

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
  // Segments: fastrtps_<16 hex>, ports: fastrtps_port<number> with a semaphore
  // sem.fastrtps_port<number>_mutex; each with a lock file named <file>_el.
  static const std::regex lock_name(R"(fastrtps_([0-9a-f]{16}|port[0-9]{1,5})_el)");
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
    remove_counting(directory / ("sem." + guarded + "_mutex"), done);
    remove_counting(lock, done);
  }
  return done;
}

}  // namespace mocap
