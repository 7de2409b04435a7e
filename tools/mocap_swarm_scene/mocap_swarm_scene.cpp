// mocap_swarm_scene: what a swarm scene file holds, and the robots file the volume's fusion
// reads for it (each robot with its layout and where it starts).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim/swarm_scene/swarm_scene_file.hpp"

namespace {

constexpr const char* kUsage = R"(usage:
  mocap_swarm_scene robots SCENE [--top-speed MPS]
  mocap_swarm_scene summary SCENE

  robots   the robots file of the scene for volume_fusion's `robots`: its layouts, and each
           robot where the scene has it at time 0 (layouts' top_speed_mps: --top-speed,
           default 3)
  summary  the robots of each layout, the scene's duration
)";

[[noreturn]] void usage_error(const std::string& message) {
  fmt::print(stderr, "mocap_swarm_scene: {}\n\n{}", message, kUsage);
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    fmt::print("{}", kUsage);
    return 0;
  }
  if (args.size() < 2) usage_error("a command and a SCENE");
  double top_speed_mps = 3;
  for (size_t i = 2; i < args.size(); ++i) {
    if (args[i] == "--top-speed" && i + 1 < args.size() && args[0] == "robots") {
      char* end = nullptr;
      top_speed_mps = std::strtod(args[++i].c_str(), &end);
      if (*end != '\0' || !(top_speed_mps > 0)) usage_error("--top-speed: a speed above 0");
    } else {
      usage_error(fmt::format("unexpected argument {}", args[i]));
    }
  }
  try {
    const mocap::synthetic::SwarmScene scene = mocap::synthetic::load_swarm_scene(args[1]);
    if (args[0] == "robots") {
      fmt::print("# The robots of {} where it starts them (made by mocap_swarm_scene robots).\n{}",
                 args[1], mocap::synthetic::robots_file_of(scene, top_speed_mps));
      return 0;
    }
    if (args[0] == "summary") {
      std::vector<std::pair<std::string, int>> layouts;
      for (const auto& robot : scene.robots) {
        auto it = std::find_if(layouts.begin(), layouts.end(),
                               [&](const auto& l) { return l.first == robot.layout; });
        if (it == layouts.end()) {
          layouts.emplace_back(robot.layout, 1);
        } else {
          ++it->second;
        }
      }
      fmt::print("{}: {} robots over {} s\n", args[1], scene.robots.size(), scene.duration_s);
      for (const auto& [layout, count] : layouts) fmt::print("  {}: {}\n", layout, count);
      return 0;
    }
  } catch (const mocap::synthetic::SwarmSceneError& e) {
    fmt::print(stderr, "mocap_swarm_scene: {}\n", e.what());
    return 1;
  }
  usage_error(fmt::format("unknown command {}", args[0]));
}
