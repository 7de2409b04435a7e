// Turret files (turret_model.hpp, config/turret.yaml), as the turret and drive followers and
// the simulated base read them: parse_turret() returns a model or throws TurretError starting
// with the file's name, nothing else. A model that loads has unit axes, ordered limits and
// rigid origins, which the followers' aiming takes for granted.
// The parser takes text (load_turret() only reads the file), so no file is involved.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "follower/turret_kinematics/turret_model.hpp"
#include "fuzz/rigid_transform.hpp"

namespace {

using namespace mocap::turret;

using fuzz::is_rigid;

bool is_usable(const Joint& joint) {
  return std::abs(joint.axis.norm() - 1) < 1e-9 && joint.min_rad < joint.max_rad &&
         is_rigid(joint.origin) && std::abs(joint.servo.direction) == 1;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  TurretModel turret;
  try {
    turret = parse_turret(std::string(reinterpret_cast<const char*>(data), size), "turret.yaml");
  } catch (const TurretError& error) {
    if (!std::string_view(error.what()).starts_with("turret.yaml")) std::abort();
    return 0;
  }
  if (!is_usable(turret.pan()) || !is_usable(turret.tilt()) ||
      !is_rigid(turret.tilt_from_camera())) {
    std::abort();
  }
  return 0;
}
