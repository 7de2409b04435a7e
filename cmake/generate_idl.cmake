# Runs fastddsgen on one IDL file and keeps only that file's own outputs.
#
# fastddsgen also regenerates every included file, and when given several files at once it
# skips some type supports; so each file is generated alone into a scratch folder and its
# four files are copied to OUT/<pkg>/msg/. The fixed_size_string include is dropped from the
# type header of a message without bounded strings, so that components include no Fast DDS
# header. The IDL text itself goes to OUT/<pkg>/msg/<Type>.idl.inc as a C++ raw string, for the
# runtime's type support (the schema mocap_topic, bags and the Foxglove bridge use).
#
# fastddsgen starts a Java VM for every file (most of a second to several seconds of a build's
# time each); its outputs depend only on the IDL files it reads and on itself. So the final
# four files are kept in a cache outside the build tree, under a hash of every IDL file on the
# include path, fastddsgen's version and this script: the sanitizer trees and later builds on
# the machine copy them. The cache is MOCAP_CACHE_DIR/fastddsgen (default
# /var/cache/mocap-graph), none when that cannot be made.
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

set(outputs ".h" ".cxx" "PubSubTypes.h" "PubSubTypes.cxx")
set(cache_root "$ENV{MOCAP_CACHE_DIR}")
if(NOT cache_root)
  set(cache_root /var/cache/mocap-graph)
endif()
set(cached "")
execute_process(COMMAND ${CMAKE_COMMAND} -E make_directory "${cache_root}/fastddsgen"
                OUTPUT_QUIET ERROR_QUIET)
execute_process(COMMAND ${CMAKE_COMMAND} -E touch "${cache_root}/fastddsgen/.writable"
                RESULT_VARIABLE unwritable OUTPUT_QUIET ERROR_QUIET)
if(unwritable EQUAL 0)
  # By content, not by path: every clone on the machine shares the entries.
  execute_process(COMMAND dpkg-query -W -f=\${Version} fastddsgen OUTPUT_VARIABLE version
                  ERROR_QUIET)
  file(SHA256 "${CMAKE_CURRENT_LIST_FILE}" key)
  string(APPEND key "${version}|${IDL}|")
  file(READ "${IDL_ROOT}/${IDL}" text)
  string(APPEND key "${text}")
  foreach(include_dir IN LISTS INCLUDE_DIRS)
    file(GLOB_RECURSE included RELATIVE "${include_dir}" "${include_dir}/*.idl")
    list(SORT included)
    string(APPEND key "|dir|")
    foreach(file IN LISTS included)
      file(SHA256 "${include_dir}/${file}" file_hash)
      string(APPEND key "${file}:${file_hash}|")
    endforeach()
  endforeach()
  string(SHA256 key "${key}")
  set(cached "${cache_root}/fastddsgen/${key}")
endif()
if(cached AND EXISTS "${cached}/done")
  foreach(suffix IN LISTS outputs)
    file(COPY_FILE "${cached}/${type}${suffix}" "${OUT}/${dir}/${type}${suffix}")
  endforeach()
  file(REMOVE_RECURSE "${scratch}")
else()
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

  foreach(suffix IN LISTS outputs)
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
  # Into the cache by a rename, so that a build beside this one sees all four files or none.
  if(cached)
    string(RANDOM LENGTH 12 nonce)
    set(staging "${cached}.${nonce}")
    file(MAKE_DIRECTORY "${staging}")
    foreach(suffix IN LISTS outputs)
      file(COPY_FILE "${OUT}/${dir}/${type}${suffix}" "${staging}/${type}${suffix}")
    endforeach()
    file(TOUCH "${staging}/done")
    file(RENAME "${staging}" "${cached}" RESULT renamed)
    if(NOT renamed EQUAL 0)
      file(REMOVE_RECURSE "${staging}")
    endif()
  endif()
endif()
file(READ "${IDL_ROOT}/${IDL}" idl_text)
file(WRITE "${OUT}/${dir}/${type}.idl.inc" "R\"mocap_idl(${idl_text})mocap_idl\"\n")
