#include "recording/motion_export/motive_csv_writer.hpp"

#include <ctime>
#include <map>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <Eigen/Geometry>

#include "recording/motion_export/point_table.hpp"

namespace mocap::motion_export {
namespace {

// Motive's Y up: our (x, y, z) as (x, z, -y), a turn of -90 degrees about x.
const Eigen::Quaterniond kYUpFromOurs(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()));

// "2024-05-06 02.15.30.123 PM", as Motive writes a take's start.
std::string motive_time(int64_t stamp_ns) {
  const auto seconds = static_cast<std::time_t>(stamp_ns / 1'000'000'000);
  std::tm local{};
  localtime_r(&seconds, &local);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %I.%M.%S", &local);
  return fmt::format("{}.{:03d} {}", text, stamp_ns % 1'000'000'000 / 1'000'000,
                     local.tm_hour < 12 ? "AM" : "PM");
}

// A name as one CSV cell: quoted, its quotes doubled, when it holds a comma or a quote.
std::string csv_cell(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// The five header rows, a cell per column.
struct HeaderRows {
  std::string type = ",Type", name = ",Name", id = ",ID", category = ",",
              axis = "Frame,Time (Seconds)";
  void add(const std::string& type_cell, const std::string& name_cell, const std::string& id_cell,
           const std::string& category_cell, const char* axes) {
    for (const char* a = axes; *a != '\0'; ++a) {
      type += "," + type_cell;
      name += "," + csv_cell(name_cell);
      id += "," + csv_cell(id_cell);
      category += "," + category_cell;
      axis += std::string(",") + *a;
    }
  }
};

void cell(std::string& row, double value) {
  fmt::format_to(std::back_inserter(row), ",{:.6f}", value);
}

}  // namespace

size_t write_motive_csv(std::ostream& out, const std::string& take_name,
                        const std::vector<int64_t>& frames, const BodyTrajectories& trajectories,
                        const std::vector<std::string>& bodies, const MarkerTrajectories& markers) {
  PointTable table = make_point_table(frames);
  add_marker_points(table, markers);
  const size_t count = table.frames.size();
  const int64_t start = count > 0 ? table.frames.front() : 0;
  fmt::print(
      out,
      "Format Version,1.23,Take Name,{},Take Notes,,Capture Frame Rate,{:.6f},Export Frame "
      "Rate,{:.6f},Capture Start Time,{},Capture Start Frame,0,Total Frames in Take,{},Total "
      "Exported Frames,{},Rotation Type,Quaternion,Length Units,Meters,Coordinate "
      "Space,Global\r\n\r\n",
      csv_cell(take_name), table.rate_hz, table.rate_hz, motive_time(start), count, count);

  HeaderRows header;
  for (size_t b = 0; b < bodies.size(); ++b) {
    const std::string id = std::to_string(b + 1);
    header.add("Rigid Body", bodies[b], id, "Rotation", "XYZW");
    header.add("Rigid Body", bodies[b], id, "Position", "XYZ");
  }
  for (const auto& [key, samples] : markers.markers()) {
    header.add(
        "Marker",
        key.labeled() ? fmt::format("{}:Marker{}", key.body, key.number + 1)
                      : fmt::format("Unlabeled {}", key.number),
        key.labeled() ? fmt::format("{}:{}", key.body, key.number + 1) : std::to_string(key.number),
        "Position", "XYZ");
  }
  fmt::print(out, "{}\r\n{}\r\n{}\r\n{}\r\n{}\r\n", header.type, header.name, header.id,
             header.category, header.axis);

  std::vector<std::map<int64_t, const StampedPose*>> posed(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (const StampedPose& pose : trajectories.bodies().at(bodies[b])) {
      posed[b][pose.stamp_ns] = &pose;
    }
  }
  PointRows rows(table);
  std::string row;
  for (uint32_t f = 0; f < count; ++f) {
    rows.go_to(f);
    row = fmt::format("{},{:.6f}", f, (table.frames[f] - start) * 1e-9);
    for (size_t b = 0; b < bodies.size(); ++b) {
      const auto found = posed[b].find(table.frames[f]);
      if (found == posed[b].end()) {
        row += ",,,,,,,";  // lost: its seven cells empty
        continue;
      }
      const Eigen::Isometry3d& pose = found->second->world_from_body;
      Eigen::Quaterniond q = kYUpFromOurs * Eigen::Quaterniond(pose.linear());
      if (q.w() < 0) q.coeffs() *= -1;
      const Eigen::Vector3d p = kYUpFromOurs * pose.translation();
      for (double value : {q.x(), q.y(), q.z(), q.w(), p.x(), p.y(), p.z()}) cell(row, value);
    }
    for (size_t m = 0; m < table.points.size(); ++m) {
      if (const PointSample* sample = rows.at(m)) {
        const Eigen::Vector3d p = kYUpFromOurs * sample->position;
        for (double value : {p.x(), p.y(), p.z()}) cell(row, value);
      } else {
        row += ",,,";
      }
    }
    row += "\r\n";
    out << row;
  }
  return count;
}

}  // namespace mocap::motion_export
