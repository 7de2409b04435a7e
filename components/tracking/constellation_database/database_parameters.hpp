// The constellation database's files as a component's parameters, for the plugins that load it
// (ParameterList::include): the same names, defaults and descriptions in each.
#pragma once

#include <string>

#include <mocap/config_files.hpp>
#include <mocap/parameter_list.hpp>

#include "tracking/constellation_database/constellation_database.hpp"

namespace mocap::constellations {

struct DatabaseFiles {
  std::string database = mocap::config_file("constellations.yaml");
  std::string sub_constellations;  // empty: none

  ConstellationDatabase load() const { return load_database(database, sub_constellations); }
};

inline const ParameterList<DatabaseFiles>& database_parameters() {
  static const ParameterList<DatabaseFiles> list =
      ParameterList<DatabaseFiles>()
          .add("database", "constellation database: YAML, or the seed's constellation CSV",
               &DatabaseFiles::database)
          .path()
          .add("sub_constellations",
               "the seed's sub-constellation CSV (line types) for a CSV database, optional",
               &DatabaseFiles::sub_constellations)
          .path();
  return list;
}

}  // namespace mocap::constellations
