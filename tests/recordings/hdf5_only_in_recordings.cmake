# HDF5 is private to recordings/ (recordings/README.md): every other module, tests included,
# reaches traces through recordings' public headers, so a change of file layout or HDF5 version
# touches one module. A test that inspects a file independently of the module's own reader uses
# the schema-free view graspsim/recordings/h5_inspect.hpp. Fails, naming each file, when a source
# outside recordings/ includes an HDF5 header or one of recordings' private headers (src/, which
# include HDF5), or a CMakeLists.txt or .cmake file outside it links HDF5.
# Usage: cmake -DSOURCE_DIR=<project root> -P hdf5_only_in_recordings.cmake
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "pass -DSOURCE_DIR=<project root>")
endif()
set(include_regex "#[ \t]*include[ \t]*[<\"]((hdf5[A-Za-z_]*|H5[A-Za-z_]*)\\.h|recordings/src/[^<>\"]*)[>\"]")
set(offenders "")
file(GLOB top_level RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/*)
foreach(dir IN LISTS top_level)
  # Not recordings/ (its home), hidden directories or a build tree inside the source.
  if(NOT IS_DIRECTORY ${SOURCE_DIR}/${dir} OR dir STREQUAL "recordings"
     OR dir MATCHES "^\\." OR EXISTS ${SOURCE_DIR}/${dir}/CMakeCache.txt)
    continue()
  endif()
  file(GLOB_RECURSE sources ${SOURCE_DIR}/${dir}/*.c ${SOURCE_DIR}/${dir}/*.cc ${SOURCE_DIR}/${dir}/*.cpp
       ${SOURCE_DIR}/${dir}/*.h ${SOURCE_DIR}/${dir}/*.hpp)
  foreach(source IN LISTS sources)
    file(STRINGS ${source} hits REGEX "${include_regex}")
    if(hits)
      list(APPEND offenders "${source}: ${hits}")
    endif()
  endforeach()
  file(GLOB_RECURSE lists ${SOURCE_DIR}/${dir}/CMakeLists.txt ${SOURCE_DIR}/${dir}/*.cmake)
  foreach(list_file IN LISTS lists)
    if(list_file STREQUAL CMAKE_CURRENT_LIST_FILE)   # this script names what it looks for
      continue()
    endif()
    file(STRINGS ${list_file} hits REGEX "HDF5::|HDF5_LIBRARIES|HDF5_INCLUDE")
    if(hits)
      list(APPEND offenders "${list_file}: ${hits}")
    endif()
  endforeach()
endforeach()
if(offenders)
  list(JOIN offenders "\n  " text)
  message(FATAL_ERROR "HDF5 outside recordings/ (move the code into recordings/ behind a public "
                      "function):\n  ${text}")
endif()
message(STATUS "HDF5 is used only in recordings/")
