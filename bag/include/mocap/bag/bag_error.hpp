// The one error type of the bag library: a message that names the bag file and what failed.
#pragma once

#include <stdexcept>

namespace mocap::bag {

class BagError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace mocap::bag
