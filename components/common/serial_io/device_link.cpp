#include "common/serial_io/device_link.hpp"

#include <unistd.h>

#include <stdexcept>
#include <system_error>

namespace mocap::serial {

namespace fs = std::filesystem;

DeviceLink::DeviceLink(fs::path link, std::string target)
    : link_(std::move(link)), target_(std::move(target)) {
  std::error_code error;
  const fs::file_status status = fs::symlink_status(link_, error);
  if (fs::exists(status) && !fs::is_symlink(status)) {
    throw std::invalid_argument("device_link " + link_.string() +
                                " exists and is not a symbolic link; not replacing it");
  }
  fs::path temporary = link_;
  temporary += ".new" + std::to_string(::getpid());
  fs::remove(temporary, error);
  try {
    fs::create_symlink(target_, temporary);
    fs::rename(temporary, link_);
  } catch (const fs::filesystem_error& e) {
    fs::remove(temporary, error);
    throw std::runtime_error("device_link " + link_.string() + ": " + e.code().message());
  }
}

DeviceLink::~DeviceLink() {
  std::error_code error;
  if (fs::read_symlink(link_, error) == fs::path(target_)) fs::remove(link_, error);
}

}  // namespace mocap::serial
