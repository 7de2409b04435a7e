#include "volume/rigid_bodies/rigid_body_database.hpp"

#include <cmath>
#include <functional>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/yaml_reader/yaml_reader.hpp"
#include "volume/rigid_bodies/rigid_body_identification.hpp"

namespace mocap::volume {
namespace {

using Reader = YamlReader<RigidBodyError>;

RigidBody read_body(const Reader& reader, const YAML::Node& node,
                    const std::vector<RigidBody>& earlier) {
  reader.check_keys(node, {"name", "markers", "streaming_id"}, "a body");
  RigidBody body;
  body.name = reader.text(reader.required(node, "name", "a body"), "name");
  if (node["streaming_id"]) {
    body.streaming_id = static_cast<int32_t>(
        reader.to_integer(node["streaming_id"], "streaming_id", 1, kMaxStreamingId));
  }
  for (const RigidBody& other : earlier) {
    if (other.name == body.name) {
      reader.fail(node["name"], fmt::format("body '{}' is declared twice", body.name));
    }
    if (body.streaming_id && other.streaming_id == body.streaming_id) {
      reader.fail(node["streaming_id"], fmt::format("bodies '{}' and '{}' have streaming_id {}",
                                                    other.name, body.name, *body.streaming_id));
    }
  }
  const YAML::Node markers = reader.required(node, "markers", fmt::format("body '{}'", body.name));
  if (!markers.IsSequence() || markers.size() < 3) {
    reader.fail(markers, fmt::format("body '{}' needs 3 or more markers, not {}", body.name,
                                     Reader::describe(markers)));
  }
  for (const YAML::Node& marker : markers) {
    const Eigen::Vector3d position = reader.vector<3>(marker, "markers", -100, 100);
    for (size_t i = 0; i < body.markers.size(); ++i) {
      if ((body.markers[i] - position).norm() < kMinMarkerSeparation) {
        reader.fail(marker, fmt::format("body '{}': marker {} is within {} m of marker {}",
                                        body.name, body.markers.size(), kMinMarkerSeparation, i));
      }
    }
    body.markers.push_back(position);
  }
  return body;
}

std::string listed(const std::vector<int>& markers) {
  return fmt::format("{}", fmt::join(markers, ", "));
}

RigidBodyDatabase read_bodies(const Reader& reader, const YAML::Node& root, double tolerance,
                              int min_markers) {
  reader.check_keys(root, {"bodies"}, "the file");
  RigidBodyDatabase database;
  for (const YAML::Node& node : reader.list(root, "bodies")) {
    database.bodies.push_back(read_body(reader, node, database.bodies));
  }
  const YAML::Node nodes = root["bodies"];
  const size_t count = static_cast<size_t>(min_markers);
  for (size_t later = 0; later < database.bodies.size(); ++later) {
    const RigidBody& b = database.bodies[later];
    if (auto self = marker_confusion(b, b, count, tolerance, true)) {
      reader.fail(nodes[later],
                  fmt::format("body '{}': its markers {} could be taken for its markers {} "
                              "(distances within {} m), so its pose is ambiguous when only {} "
                              "are seen; move a marker, or identify bodies from more markers "
                              "(min_markers)",
                              b.name, listed(self->first), listed(self->second), 2 * tolerance,
                              min_markers));
    }
    for (size_t earlier = 0; earlier < later; ++earlier) {
      const RigidBody& a = database.bodies[earlier];
      if (marker_confusion(a, b, count, tolerance, false)) {
        reader.fail(nodes[later],
                    fmt::format("body '{}' cannot be told apart from '{}' (line {}): {} or more "
                                "markers of one match the other's distances within {} m; move "
                                "a marker",
                                b.name, a.name, Reader::line_of(nodes[earlier]), min_markers,
                                2 * tolerance));
      }
    }
  }
  return database;
}

}  // namespace

std::optional<std::pair<std::vector<int>, std::vector<int>>> marker_confusion(
    const RigidBody& seen, const RigidBody& taken_for, size_t count, double tolerance, bool same) {
  const double within = 2 * tolerance;
  std::vector<int> from(count), to(count);
  std::vector<bool> used(taken_for.markers.size());
  // Ordered choices on `taken_for`'s side against increasing index sets on `seen`'s.
  std::function<std::optional<std::pair<std::vector<int>, std::vector<int>>>(size_t)> place =
      [&](size_t k) -> std::optional<std::pair<std::vector<int>, std::vector<int>>> {
    if (k == count) {
      if (same && from == to) return std::nullopt;
      std::vector<Eigen::Vector3d> a, b;
      for (size_t i = 0; i < count; ++i) {
        a.push_back(seen.markers[from[i]]);
        b.push_back(taken_for.markers[to[i]]);
      }
      if (best_fit_rms(a, b) > within) return std::nullopt;
      return std::make_pair(from, to);
    }
    for (int f = k == 0 ? 0 : from[k - 1] + 1; f < static_cast<int>(seen.markers.size()); ++f) {
      from[k] = f;
      for (int t = 0; t < static_cast<int>(taken_for.markers.size()); ++t) {
        if (used[t]) continue;
        bool matches = true;
        for (size_t j = 0; j < k && matches; ++j) {
          const double a = (seen.markers[f] - seen.markers[from[j]]).norm();
          const double b = (taken_for.markers[t] - taken_for.markers[to[j]]).norm();
          matches = std::abs(a - b) <= within;
        }
        if (!matches) continue;
        to[k] = t;
        used[t] = true;
        auto found = place(k + 1);
        used[t] = false;
        if (found) return found;
      }
    }
    return std::nullopt;
  };
  if (seen.markers.size() < count || taken_for.markers.size() < count) return std::nullopt;
  return place(0);
}

RigidBodyDatabase parse_rigid_bodies(const std::string& text, const std::string& source,
                                     double tolerance, int min_markers) {
  const Reader reader(source);
  return read_bodies(reader, reader.parse(text), tolerance, min_markers);
}

RigidBodyDatabase load_rigid_bodies(const std::string& path, double tolerance, int min_markers) {
  const Reader reader(path);
  return read_bodies(reader, reader.load(), tolerance, min_markers);
}

}  // namespace mocap::volume
