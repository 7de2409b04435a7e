#include "tracking/constellation_database/constellation_database.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <Eigen/SVD>
#include <mocap/config_reader.hpp>

#include "tracking/constellation_database/cross_ratio.hpp"

namespace mocap::constellations {
namespace {

// Markers closer than this are one marker written twice (a shared corner).
constexpr double kSamePointM = 0.5e-3;
// Markers further than this from their plane make the constellation non-planar.
constexpr double kPlanarityM = 2e-3;

std::string trim(std::string_view text) {
  size_t begin = text.find_first_not_of(" \t\r\"");
  if (begin == std::string_view::npos) return {};
  size_t end = text.find_last_not_of(" \t\r\"");
  return std::string(text.substr(begin, end - begin + 1));
}

// One CSV row, cells trimmed, trailing empty cells (spreadsheet padding) dropped.
std::vector<std::string> split_row(std::string_view line) {
  std::vector<std::string> cells;
  size_t start = 0;
  while (true) {
    size_t comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  while (!cells.empty() && cells.back().empty()) cells.pop_back();
  return cells;
}

struct CsvRow {
  int line = 0;
  std::vector<std::string> cells;
};

std::vector<CsvRow> read_rows(std::string_view text) {
  std::vector<CsvRow> rows;
  int number = 0;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    std::string_view line = text.substr(start, end == std::string_view::npos ? end : end - start);
    ++number;
    if (number == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // BOM
    std::vector<std::string> cells = split_row(line);
    if (!cells.empty()) rows.push_back({number, std::move(cells)});
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return rows;
}

[[noreturn]] void fail(const std::string& source, int line, const std::string& what) {
  throw DatabaseError(line > 0 ? fmt::format("{}:{}: {}", source, line, what)
                               : fmt::format("{}: {}", source, what));
}

double number(const std::string& cell, const std::string& source, int line, const char* what) {
  double value = 0;
  auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (cell.empty() || error != std::errc() || end != cell.data() + cell.size() ||
      !std::isfinite(value)) {
    fail(source, line, fmt::format("{} '{}' is not a number", what, cell));
  }
  return value;
}

std::string read_text(const std::string& path, const char* what) {
  std::ifstream stream(path);
  if (!stream) {
    throw DatabaseError(
        fmt::format("{}: cannot read the {}: {}", path, what, std::strerror(errno)));
  }
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

std::array<double, 4> checked_positions(std::array<double, 4> positions, const std::string& source,
                                        int line, const std::string& name) {
  for (int i = 1; i < 4; ++i) {
    if (!(positions[i] > positions[i - 1])) {
      fail(source, line,
           fmt::format("line '{}': the four distances must increase strictly, got {}", name,
                       fmt::join(positions, ", ")));
    }
  }
  double first = positions[0];
  for (double& p : positions) p -= first;
  // Spacings too small or too large for double precision give no usable cross-ratio.
  if (!std::isfinite(cross_ratio(positions[0], positions[1], positions[2], positions[3]))) {
    fail(source, line,
         fmt::format("line '{}': the distances {} give no finite cross-ratio", name,
                     fmt::join(positions, ", ")));
  }
  return positions;
}

// A constellation line as read: four points in order, not yet merged with other lines.
ConstellationLine raw_line(ConstellationModel& model, std::string name,
                           const std::array<Eigen::Vector3d, 4>& points,
                           std::optional<Eigen::Vector3d> centroid) {
  ConstellationLine line;
  line.name = std::move(name);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    line.points[i] = static_cast<int>(model.points.size());
    model.points.push_back(points[i]);
    sum += points[i];
  }
  line.centroid = centroid.value_or(sum / 4);
  return line;
}

// Merges shared points, checks each line is straight and the whole is planar, and fills in
// the plane and the cross-ratios.
void complete(ConstellationModel& model, const std::vector<LinePattern>& patterns,
              const std::string& source) {
  std::string who = fmt::format("{}: constellation '{}'", source, model.name);
  if (model.lines.empty()) throw DatabaseError(who + " has no lines");
  std::vector<Eigen::Vector3d> raw = std::move(model.points);
  model.points.clear();
  std::set<std::string> names;
  for (ConstellationLine& line : model.lines) {
    if (!names.insert(line.name).second) {
      throw DatabaseError(fmt::format("{}: line '{}' appears twice", who, line.name));
    }
    std::array<Eigen::Vector3d, 4> p;
    for (int i = 0; i < 4; ++i) {
      p[i] = raw[line.points[i]];
      auto same = std::find_if(model.points.begin(), model.points.end(),
                               [&](const auto& q) { return (q - p[i]).norm() < kSamePointM; });
      if (same == model.points.end()) {
        line.points[i] = static_cast<int>(model.points.size());
        model.points.push_back(p[i]);
      } else {
        line.points[i] = static_cast<int>(same - model.points.begin());
      }
    }
    Eigen::Vector3d direction = (p[3] - p[0]).normalized();
    std::array<double, 4> along{};
    for (int i = 0; i < 4; ++i) {
      along[i] = direction.dot(p[i] - p[0]);
      double off = (p[i] - p[0] - along[i] * direction).norm();
      if (off > kPlanarityM) {
        throw DatabaseError(
            fmt::format("{}: line '{}' is not straight (point {} is {:.1f} mm "
                        "off the line)",
                        who, line.name, i + 1, off * 1e3));
      }
    }
    for (int i = 1; i < 4; ++i) {
      if (!(along[i] > along[i - 1] + kSamePointM)) {
        throw DatabaseError(
            fmt::format("{}: line '{}': its points must be listed in order along "
                        "the line, without repeats",
                        who, line.name));
      }
    }
    line.cross_ratio = cross_ratio(along[0], along[1], along[2], along[3]);
    auto pattern = std::find_if(patterns.begin(), patterns.end(),
                                [&](const LinePattern& lp) { return lp.name == line.name; });
    if (pattern != patterns.end()) line.cross_ratio = pattern->cross_ratio;
  }
  // The plane through the markers: the two main directions of their spread.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : model.points) mean += p;
  mean /= static_cast<double>(model.points.size());
  Eigen::MatrixXd centred(3, model.points.size());
  for (size_t i = 0; i < model.points.size(); ++i) centred.col(i) = model.points[i] - mean;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinU);
  if (svd.singularValues()(1) < 1e-6) {
    throw DatabaseError(who + " has all its markers on one line; it needs two directions");
  }
  model.plane_origin = mean;
  model.plane_axes = svd.matrixU().leftCols<2>();
  Eigen::Vector3d normal = svd.matrixU().col(2);
  model.plane_points.clear();
  model.size_m = 0;
  for (const auto& p : model.points) {
    double off = std::abs(normal.dot(p - mean));
    if (off > kPlanarityM) {
      throw DatabaseError(
          fmt::format("{} is not planar: a marker is {:.1f} mm off its plane", who, off * 1e3));
    }
    model.plane_points.push_back(model.plane_axes.transpose() * (p - mean));
    for (const auto& q : model.points) model.size_m = std::max(model.size_m, (p - q).norm());
  }
}

}  // namespace

std::vector<std::string> ConstellationModel::line_names() const {
  std::vector<std::string> names;
  for (const auto& line : lines) names.push_back(line.name);
  return names;
}

ConstellationDatabase::ConstellationDatabase(std::vector<LinePattern> patterns,
                                             std::vector<ConstellationModel> constellations,
                                             const std::string& source)
    : patterns_(std::move(patterns)), constellations_(std::move(constellations)) {
  if (constellations_.empty()) throw DatabaseError(source + ": the database has no constellations");
  std::set<std::string> names;
  for (ConstellationModel& model : constellations_) {
    if (!names.insert(model.name).second) {
      throw DatabaseError(fmt::format("{}: constellation '{}' appears twice", source, model.name));
    }
    complete(model, patterns_, source);
  }
}

const ConstellationModel* ConstellationDatabase::find(std::string_view name) const {
  for (const auto& model : constellations_) {
    if (model.name == name) return &model;
  }
  return nullptr;
}

const LinePattern* ConstellationDatabase::find_pattern(std::string_view name) const {
  for (const auto& pattern : patterns_) {
    if (pattern.name == name) return &pattern;
  }
  return nullptr;
}

std::vector<std::string> ConstellationDatabase::ambiguities(double tolerance) const {
  // Every line type once: a name with its cross-ratio, from the table or a constellation.
  std::vector<std::pair<std::string, double>> types;
  auto add = [&](const std::string& name, double value) {
    for (const auto& [known, _] : types) {
      if (known == name) return;
    }
    types.emplace_back(name, value);
  };
  for (const auto& model : constellations_) {
    for (const auto& line : model.lines) add(line.name, line.cross_ratio);
  }
  std::vector<std::string> problems;
  for (size_t i = 0; i < types.size(); ++i) {
    for (size_t j = i + 1; j < types.size(); ++j) {
      auto [a, ra] = types[i];
      auto [b, rb] = types[j];
      // Both measurements may be off by the tolerance, towards each other.
      if (std::abs(ra - rb) < tolerance * (ra + rb)) {
        problems.push_back(fmt::format(
            "lines '{}' and '{}' have cross-ratios {:.4f} and {:.4f} ({:.1f} % apart): at a "
            "tolerance of {:.1f} % one can be taken for the other",
            a, b, ra, rb, 100 * std::abs(ra - rb) / std::min(ra, rb), 100 * tolerance));
      }
    }
  }
  return problems;
}

std::vector<LinePattern> parse_sub_constellation_csv(std::string_view text,
                                                     const std::string& source) {
  std::vector<CsvRow> rows = read_rows(text);
  if (rows.empty()) fail(source, 0, "the sub-constellation table is empty");
  // The first row is the header (the seed's parser skips it), as long as it is not data.
  size_t first = 0;
  const auto& header = rows[0].cells;
  if (header.size() >= 2 && std::isalpha(static_cast<unsigned char>(header[1][0]))) first = 1;
  std::vector<LinePattern> patterns;
  for (size_t r = first; r < rows.size(); ++r) {
    const CsvRow& row = rows[r];
    if (row.cells.size() != 5) {
      fail(source, row.line,
           fmt::format("expected Name,pt_A,pt_B,pt_C,pt_D (5 cells), got {} cells",
                       row.cells.size()));
    }
    LinePattern pattern;
    pattern.name = row.cells[0];
    if (pattern.name.empty()) fail(source, row.line, "the line type needs a name");
    std::array<double, 4> mm{};
    for (int i = 0; i < 4; ++i) mm[i] = number(row.cells[i + 1], source, row.line, "distance");
    pattern.positions_m = checked_positions(mm, source, row.line, pattern.name);
    for (double& p : pattern.positions_m) p *= 1e-3;
    const auto& p = pattern.positions_m;
    pattern.cross_ratio = cross_ratio(p[0], p[1], p[2], p[3]);
    for (const auto& known : patterns) {
      if (known.name == pattern.name) {
        fail(source, row.line, fmt::format("line type '{}' appears twice", pattern.name));
      }
    }
    patterns.push_back(pattern);
  }
  if (patterns.empty()) fail(source, 0, "the sub-constellation table has no rows");
  return patterns;
}

std::vector<ConstellationModel> parse_constellation_csv(std::string_view text,
                                                        const std::string& source) {
  std::vector<CsvRow> rows = read_rows(text);
  std::vector<ConstellationModel> models;
  size_t r = 0;
  auto expect_label = [&](const char* label, const char* form) -> const CsvRow& {
    if (r >= rows.size())
      fail(source, 0, fmt::format("the file ends where '{}' was expected", form));
    const CsvRow& row = rows[r];
    if (row.cells[0] != label) {
      fail(source, row.line, fmt::format("expected '{}', got '{}'", form, row.cells[0]));
    }
    ++r;
    return row;
  };
  while (r < rows.size()) {
    ConstellationModel model;
    const CsvRow& id = expect_label("Const_ID", "Const_ID,<id>");
    if (id.cells.size() != 2) fail(source, id.line, "expected 'Const_ID,<id>'");
    model.name = id.cells[1];
    const CsvRow& pts = expect_label("Pts", "Pts,<line names...>");
    std::vector<std::string> line_names(pts.cells.begin() + 1, pts.cells.end());
    if (line_names.empty()) fail(source, pts.line, "'Pts' names no lines");
    expect_label("Name", "Name,X_coord,Y_coord,Z_coord");
    for (const std::string& name : line_names) {
      if (r >= rows.size() || rows[r].cells[0] != name) {
        fail(source, r < rows.size() ? rows[r].line : 0,
             fmt::format("constellation '{}': expected the row of line '{}' (from 'Pts' at line "
                         "{})",
                         model.name, name, pts.line));
      }
      auto vector = [&](const CsvRow& row) {
        if (row.cells.size() != 4) {
          fail(source, row.line,
               fmt::format("expected <name>,x,y,z (4 cells), got {} cells", row.cells.size()));
        }
        return Eigen::Vector3d(number(row.cells[1], source, row.line, "coordinate"),
                               number(row.cells[2], source, row.line, "coordinate"),
                               number(row.cells[3], source, row.line, "coordinate"));
      };
      Eigen::Vector3d centroid = vector(rows[r++]);
      std::array<Eigen::Vector3d, 4> points;
      for (int i = 0; i < 4; ++i) {
        if (r >= rows.size() || !rows[r].cells[0].empty()) {
          fail(source, r < rows.size() ? rows[r].line : 0,
               fmt::format("line '{}' needs 4 point rows ',x,y,z', found {}", name, i));
        }
        points[i] = vector(rows[r++]);
      }
      model.lines.push_back(raw_line(model, name, points, centroid));
    }
    models.push_back(std::move(model));
  }
  if (models.empty()) fail(source, 0, "the constellation file has no constellations");
  return models;
}

ConstellationDatabase parse_database_yaml(const std::string& text, const std::string& source,
                                          std::vector<LinePattern> more_patterns) {
  ConfigReader<DatabaseError> reader(source);
  YAML::Node root = reader.parse(text);
  if (!root.IsMap()) fail(source, 0, "a database is a map with 'constellations'");
  reader.check_keys(root, {"line_patterns", "constellations"}, "the database");
  std::vector<LinePattern> patterns;
  for (const YAML::Node& node : reader.list(root, "line_patterns")) {
    reader.check_keys(node, {"name", "positions"}, "a line pattern");
    LinePattern pattern;
    pattern.name = reader.text(reader.required(node, "name", "a line pattern"), "name");
    std::vector<double> p = reader.numbers(
        reader.required(node, "positions", fmt::format("line pattern '{}'", pattern.name)),
        "positions", 4);
    pattern.positions_m = checked_positions({p[0], p[1], p[2], p[3]}, source,
                                            ConfigReader<>::line_of(node), pattern.name);
    const auto& q = pattern.positions_m;
    pattern.cross_ratio = cross_ratio(q[0], q[1], q[2], q[3]);
    patterns.push_back(pattern);
  }
  std::vector<ConstellationModel> models;
  for (const YAML::Node& node : reader.list(root, "constellations")) {
    reader.check_keys(node, {"name", "lines"}, "a constellation");
    ConstellationModel model;
    model.name = reader.text(reader.required(node, "name", "a constellation"), "name");
    const std::string what = fmt::format("constellation '{}'", model.name);
    YAML::Node lines = reader.required(node, "lines", what);
    if (!lines.IsSequence() || lines.size() == 0) {
      reader.fail(lines, fmt::format("{} needs 'lines', a list of lines", what));
    }
    for (const YAML::Node& line_node : lines) {
      reader.check_keys(line_node, {"name", "points"}, "a line");
      std::string name = reader.text(reader.required(line_node, "name", "a line"), "name");
      YAML::Node points = reader.required(line_node, "points", fmt::format("line '{}'", name));
      if (!points.IsSequence() || points.size() != 4) {
        reader.fail(points,
                    fmt::format("line '{}' needs 'points': 4 points [x, y, z] in metres", name));
      }
      std::array<Eigen::Vector3d, 4> p;
      for (int i = 0; i < 4; ++i) {
        std::vector<double> xyz = reader.numbers(points[i], "a point [x, y, z]", 3);
        p[i] = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
      }
      model.lines.push_back(raw_line(model, name, p, std::nullopt));
    }
    models.push_back(std::move(model));
  }
  patterns.insert(patterns.end(), more_patterns.begin(), more_patterns.end());
  return ConstellationDatabase(std::move(patterns), std::move(models), source);
}

ConstellationDatabase load_database(const std::string& constellations_file,
                                    const std::string& sub_constellations_csv) {
  std::vector<LinePattern> patterns;
  if (!sub_constellations_csv.empty()) {
    patterns = parse_sub_constellation_csv(
        read_text(sub_constellations_csv, "sub-constellation table"), sub_constellations_csv);
  }
  std::string text = read_text(constellations_file, "constellation database");
  std::string extension = constellations_file.substr(constellations_file.find_last_of('.') + 1);
  if (extension == "yaml" || extension == "yml") {
    return parse_database_yaml(text, constellations_file, std::move(patterns));
  }
  return ConstellationDatabase(
      std::move(patterns), parse_constellation_csv(text, constellations_file), constellations_file);
}

}  // namespace mocap::constellations
