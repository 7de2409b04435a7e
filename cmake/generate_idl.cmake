# Runs fastddsgen on one IDL file and keeps only that file's own outputs.
#
# fastddsgen also regenerates every included file, and when given several files at once it
# skips some type supports; so each file is generated alone into a scratch folder and its
# four files are copied to OUT/<pkg>/msg/. The fixed_size_string include is dropped from the
# type header of a message without bounded strings, so that components include no Fast DDS
# header. The IDL text itself goes to OUT/<pkg>/msg/<Type>.idl.inc as a C++ raw string, for the
# runtime's type support (the schema mocap_topic, bags and the Foxglove bridge use).
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
  if(suffix STREQUAL ".h" AND NOT text MATCHES "fixed_string<")
    string(REPLACE "#include <fastrtps/utils/fixed_size_string.hpp>" "" text "${text}")
  endif()
  # fastddsgen 2.3 writes an empty string constant as "= ;", and a fixed array's default value
  # (rosidl's "(1.0, 2.0)") as memset(&m_x, "(1.0, 2.0)", size); both are mended here.
  if(suffix STREQUAL ".h")
    string(REGEX REPLACE "(const std::string [A-Za-z0-9_]+ = );" "\\1\"\";" text "${text}")
  endif()
  if(suffix STREQUAL ".cxx")
    set(memset "memset\\(&(m_[A-Za-z0-9_]+), \"\\(([^\"]*)\\)\", [^;]*\\)")
    string(REGEX MATCHALL "${memset}" defaults "${text}")
    foreach(statement IN LISTS defaults)
      string(REGEX REPLACE "${memset}" "\\1 = {{\\2}}" assignment "${statement}")
      string(REPLACE "True" "true" assignment "${assignment}")
      string(REPLACE "False" "false" assignment "${assignment}")
      string(REPLACE "${statement}" "${assignment}" text "${text}")
    endforeach()
  endif()
  file(WRITE "${OUT}/${dir}/${type}${suffix}" "${text}")
endforeach()
file(REMOVE_RECURSE "${scratch}")
file(READ "${IDL_ROOT}/${IDL}" idl_text)
file(WRITE "${OUT}/${dir}/${type}.idl.inc" "R\"mocap_idl(${idl_text})mocap_idl\"\n")
