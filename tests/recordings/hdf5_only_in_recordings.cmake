# HDF5 is private to recordings/ (recordings/README.md): every other module reaches traces
# through recordings' public headers, so a change of file layout or HDF5 version touches one
# module. Fails, naming each file, when a source outside recordings/ includes an HDF5 header or
# a CMakeLists.txt outside it links HDF5. tests/ is exempt: a test inspects what recordings/
# wrote through the C API, independently of the module's own reader.
# Usage: cmake -DSOURCE_DIR=<project root> -P hdf5_only_in_recordings.cmake
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "pass -DSOURCE_DIR=<project root>")
endif()
set(include_regex "#[ \t]*include[ \t]*[<\"](hdf5[A-Za-z_]*|H5[A-Za-z_]*)\\.h[>\"]")
set(offenders "")
file(GLOB top_level RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/*)
foreach(dir IN LISTS top_level)
  # Not recordings/ (its home), tests/, hidden directories or a build tree inside the source.
  if(NOT IS_DIRECTORY ${SOURCE_DIR}/${dir} OR dir STREQUAL "recordings" OR dir STREQUAL "tests"
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
message(STATUS "HDF5 is used only in recordings/ (and tests/)")
