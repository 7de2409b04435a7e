#include "dds/fastdds/fastdds_shared_memory.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace mocap {
namespace {

// A folder of files named as Fast DDS names its shared memory, removed with the test.
class SharedMemoryFolder {
 public:
  SharedMemoryFolder() { std::filesystem::create_directories(path_); }
  ~SharedMemoryFolder() {
    for (int fd : held_) close(fd);
    std::filesystem::remove_all(path_);
  }
  const std::filesystem::path& path() const { return path_; }
  void make(const std::string& name, std::chrono::hours age = std::chrono::hours(1)) {
    std::ofstream(path_ / name) << std::string(100, 'x');
    std::filesystem::last_write_time(path_ / name,
                                     std::filesystem::file_time_type::clock::now() - age);
  }
  // Holds the lock on `name` as a live participant does, until the folder goes.
  void hold(const std::string& name) {
    held_.push_back(open((path_ / name).c_str(), O_RDWR));
    ASSERT_EQ(flock(held_.back(), LOCK_EX), 0);
  }
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(path_)) {
      names.insert(entry.path().filename());
    }
    return names;
  }

 private:
  std::filesystem::path path_ =
      std::filesystem::temp_directory_path() / ("mocap_shm_" + std::to_string(getpid()));
  std::vector<int> held_;
};

TEST(SharedMemoryCleanup, RemovesOnlyOldSegmentsNobodyHolds) {
  SharedMemoryFolder dir;
  dir.make("fastrtps_0123456789abcdef");  // a dead participant's segment
  dir.make("fastrtps_0123456789abcdef_el");
  dir.make("fastrtps_port7411");  // a dead participant's port: kept (unused_participant_id)
  dir.make("fastrtps_port7411_el");
  dir.make("sem.fastrtps_port7411_mutex");
  dir.make("fastrtps_fedcba9876543210");  // alive: its lock is held
  dir.make("fastrtps_fedcba9876543210_el");
  dir.make("fastrtps_00000000000000aa", std::chrono::hours(0));  // too young to judge
  dir.make("fastrtps_00000000000000aa_el", std::chrono::hours(0));
  dir.make("unrelated_el");
  dir.hold("fastrtps_fedcba9876543210_el");

  SharedMemoryCleanup done = remove_orphaned_shared_memory(dir.path());
  EXPECT_EQ(done.files, 2);
  EXPECT_EQ(done.bytes, 200u);
  EXPECT_EQ(dir.files(),
            (std::set<std::string>{"fastrtps_port7411", "fastrtps_port7411_el",
                                   "sem.fastrtps_port7411_mutex", "fastrtps_fedcba9876543210",
                                   "fastrtps_fedcba9876543210_el", "fastrtps_00000000000000aa",
                                   "fastrtps_00000000000000aa_el", "unrelated_el"}));
}

// Domain 1: participant id N reads on ports 7660 + 2N and 7661 + 2N.
TEST(SharedMemoryCleanup, ANewParticipantTakesNoPortADeadOneLeft) {
  SharedMemoryFolder dir;
  EXPECT_EQ(unused_participant_id(1, dir.path()), 0);
  dir.make("fastrtps_port7660_el", std::chrono::hours(3));  // id 0: dead
  dir.make("fastrtps_port7661_el", std::chrono::hours(3));
  dir.make("fastrtps_port7662_el");  // id 1: live
  dir.make("fastrtps_port7663_el");
  dir.hold("fastrtps_port7662_el");
  dir.make("fastrtps_port7665_el", std::chrono::hours(5));  // id 2: dead, one port left
  dir.make("fastrtps_port7510_el");                         // domain 0's id 50: no matter
  EXPECT_EQ(unused_participant_id(1, dir.path()), 3);
  // Ids go up to 119, the last whose ports stay below the next domain's.
  for (int id = 3; id < 120; ++id) dir.make(fmt::format("fastrtps_port{}_el", 7661 + 2 * id));
  // With every id's ports used, the dead participant that opened them longest ago gives way.
  EXPECT_EQ(unused_participant_id(1, dir.path()), 2);
  // With all live, Fast DDS chooses.
  for (int id = 0; id < 120; ++id) {
    if (id != 1) dir.hold(fmt::format("fastrtps_port{}_el", 7661 + 2 * id));
  }
  EXPECT_EQ(unused_participant_id(1, dir.path()), std::nullopt);
}

}  // namespace
}  // namespace mocap
