#include "recording/motion_export/marker_trajectories.hpp"

#include <tuple>

#include <fmt/format.h>

namespace mocap::motion_export {

std::string MarkerKey::name() const {
  return labeled() ? fmt::format("{}_{}", body, number + 1) : fmt::format("unlabeled_{}", number);
}

std::string MarkerKey::description() const {
  return labeled() ? fmt::format("marker {} of {}", number + 1, body)
                   : fmt::format("unlabeled, track {}", number);
}

bool MarkerKey::operator<(const MarkerKey& other) const {
  return std::tuple(!labeled(), body, number) <
         std::tuple(!other.labeled(), other.body, other.number);
}

}  // namespace mocap::motion_export
