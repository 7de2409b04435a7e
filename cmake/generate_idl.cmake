# Runs fastddsgen on one IDL file and keeps only that file's own outputs.
#
# fastddsgen also regenerates every included file, and when given several files at once it
# skips some type supports; so each file is generated alone into a scratch folder and its
# four files are copied to OUT/<pkg>/msg/. The fixed_size_string include is dropped from the
# type header: no message uses bounded strings, and it would make every component include a
# Fast DDS header.
#
# Inputs: FASTDDSGEN, IDL_ROOT, IDL (relative to IDL_ROOT, e.g. std_msgs/msg/Header.idl), OUT,
# INCLUDE_DIRS (where included IDL files are, separated by '|').
get_filename_component(type "${IDL}" NAME_WE)
get_filename_component(dir "${IDL}" DIRECTORY)
string(REPLACE "/" "_" scratch_name "${dir}_${type}")
set(scratch "${OUT}/.fastddsgen/${scratch_name}")
file(REMOVE_RECURSE "${scratch}")
file(MAKE_DIRECTORY "${scratch}/tmp" "${OUT}/${dir}")

set(include_flags)
string(REPLACE "|" ";" INCLUDE_DIRS "${INCLUDE_DIRS}")
foreach(dir IN LISTS INCLUDE_DIRS)
  list(APPEND include_flags -I "${dir}")
endforeach()
execute_process(
  # -t: fastddsgen's preprocessed copies of the IDL files go to a temporary directory under
  # fixed names (/tmp by default); two runs at once, in one build or two, would overwrite
  # each other's (seen: an included file read back empty).
  COMMAND "${FASTDDSGEN}" -cs -typeros2 -replace -t "${scratch}/tmp" ${include_flags} -d "${scratch}"
          "${IDL_ROOT}/${IDL}"
  RESULT_VARIABLE result
  OUTPUT_VARIABLE output
  ERROR_VARIABLE output)
if(NOT result EQUAL 0 OR output MATCHES "error")
  message(FATAL_ERROR "fastddsgen failed on ${IDL}:\n${output}")
endif()

foreach(suffix ".h" ".cxx" "PubSubTypes.h" "PubSubTypes.cxx")
  set(generated "${scratch}/${type}${suffix}")
  if(NOT EXISTS "${generated}")
    message(FATAL_ERROR "fastddsgen did not write ${type}${suffix} for ${IDL}:\n${output}")
  endif()
  file(READ "${generated}" text)
  if(suffix STREQUAL ".h")
    string(REPLACE "#include <fastrtps/utils/fixed_size_string.hpp>" "" text "${text}")
  endif()
  file(WRITE "${OUT}/${dir}/${type}${suffix}" "${text}")
endforeach()
file(REMOVE_RECURSE "${scratch}")
