// Constellation databases (constellation_database.hpp), as the identifier, the pose estimator
// and the synthetic camera load them. The text up to the first NUL is the constellation file,
// read both as YAML and as the seed's constellation CSV; the rest, if any, is the seed's
// sub-constellation CSV. Each parser returns its data or throws DatabaseError starting with
// the file's name, nothing else; a database that loads has a usable geometry.
// The parsers take text, so no file is involved: load_database() reads the files and calls
// them as this does.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tracking/constellation_database/constellation_database.hpp"

namespace {

using namespace mocap::constellations;

// `parse()`, or nothing when it throws DatabaseError, which must name `source`.
template <class Parse>
auto attempt(std::string_view source, Parse parse) -> std::optional<decltype(parse())> {
  try {
    return parse();
  } catch (const DatabaseError& error) {
    if (!std::string_view(error.what()).starts_with(source)) std::abort();
    return std::nullopt;
  }
}

// A cross-ratio names a line type: finite, and above 1 for distinct points in order.
bool is_cross_ratio(double value) { return std::isfinite(value) && value >= 1; }

void check(const ConstellationDatabase& database) {
  for (const LinePattern& pattern : database.line_patterns()) {
    if (!is_cross_ratio(pattern.cross_ratio)) std::abort();
  }
  for (const ConstellationModel& model : database.constellations()) {
    if (model.plane_points.size() != model.points.size() || !std::isfinite(model.size_m)) {
      std::abort();
    }
    for (const ConstellationLine& line : model.lines) {
      if (!is_cross_ratio(line.cross_ratio)) std::abort();
      for (int point : line.points) {
        if (point < 0 || static_cast<size_t>(point) >= model.points.size()) std::abort();
      }
    }
  }
  database.ambiguities(0.05);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const size_t split = input.find('\0');
  const std::string text(input.substr(0, split));
  std::vector<LinePattern> patterns;
  if (split != std::string_view::npos) {
    const auto table = attempt(
        "sub.csv", [&] { return parse_sub_constellation_csv(input.substr(split + 1), "sub.csv"); });
    if (table) patterns = *table;
  }
  const auto alone = attempt("db.yaml", [&] { return parse_database_yaml(text, "db.yaml"); });
  if (alone) check(*alone);
  // load_database() with a table: the table's patterns join before the models are completed,
  // so a file that loads alone loads with a table, with the same points.
  const auto joined =
      attempt("db.yaml", [&] { return parse_database_yaml(text, "db.yaml", patterns); });
  if (joined) check(*joined);
  if (alone && !patterns.empty()) {
    if (!joined) std::abort();
    for (size_t i = 0; i < alone->constellations().size(); ++i) {
      if (joined->constellations()[i].points != alone->constellations()[i].points) std::abort();
    }
  }
  if (const auto models =
          attempt("db.csv", [&] { return parse_constellation_csv(text, "db.csv"); })) {
    const auto database =
        attempt("db.csv", [&] { return ConstellationDatabase(patterns, *models, "db.csv"); });
    if (database) check(*database);
  }
  return 0;
}
