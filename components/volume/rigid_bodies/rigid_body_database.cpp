#include "rigid_body_database.hpp"

#include <fmt/format.h>

#include "rigid_body_identification.hpp"
#include "yaml_reader.hpp"

namespace mocap::volume {
namespace {

using Reader = YamlReader<RigidBodyError>;

RigidBody read_body(const Reader& reader, const YAML::Node& node,
                    const std::vector<RigidBody>& earlier) {
  reader.check_keys(node, {"name", "markers"}, "a body");
  RigidBody body;
  body.name = reader.text(reader.required(node, "name", "a body"), "name");
  for (const RigidBody& other : earlier) {
    if (other.name == body.name) {
      reader.fail(node["name"], fmt::format("body '{}' is declared twice", body.name));
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

// Whether `seen`'s markers, measured with errors up to the tolerance, could be taken for
// `min_markers` or more of `taken_for`'s: their distances differ by up to twice the tolerance.
bool could_be_taken_for(const RigidBody& seen, const RigidBody& taken_for, double tolerance,
                        int min_markers) {
  RigidBodyIdentificationOptions options;
  options.tolerance = 2 * tolerance;
  options.min_markers = min_markers;
  return !identify_rigid_bodies({{taken_for}}, seen.markers, options).empty();
}

RigidBodyDatabase read_bodies(const Reader& reader, const YAML::Node& root, double tolerance,
                              int min_markers) {
  reader.check_keys(root, {"bodies"}, "the file");
  RigidBodyDatabase database;
  for (const YAML::Node& node : reader.list(root, "bodies")) {
    database.bodies.push_back(read_body(reader, node, database.bodies));
  }
  const YAML::Node nodes = root["bodies"];
  for (size_t later = 1; later < database.bodies.size(); ++later) {
    for (size_t earlier = 0; earlier < later; ++earlier) {
      const RigidBody& a = database.bodies[earlier];
      const RigidBody& b = database.bodies[later];
      if (could_be_taken_for(a, b, tolerance, min_markers) ||
          could_be_taken_for(b, a, tolerance, min_markers)) {
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
