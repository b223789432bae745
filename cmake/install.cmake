# `cmake --install <build> --prefix P`: what a project needs to build on graspsim (README.md,
# "Use graspsim as a library"), in the GNU layout:
#   include/graspsim/{engine,hw,recordings,scripting,app}/  the public headers
#   lib/libgraspsim_*.a                                      the libraries (static)
#   bin/graspsim                                             the CLI
#   share/graspsim/scenarios/                                the library scenarios and their meshes
#   lib/cmake/graspsim/                                      find_package(graspsim): the Config
#                                                            file, its version, the exported targets
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The exported targets, graspsim::<name>; the same names work inside this build.
set(graspsim_exported
  graspsim_determinism:determinism   # the flags that keep traces bit for bit (CMakeLists.txt)
  graspsim_engine:engine
  graspsim_hw:hw
  graspsim_recordings:recordings
  graspsim_scripting:scripting
  graspsim_app:app)                  # the runtime: load a scenario, run it with a trace
set(graspsim_export_targets "")
foreach(pair IN LISTS graspsim_exported)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 target)
  list(GET pair 1 name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  add_library(graspsim::${name} ALIAS ${target})
  list(APPEND graspsim_export_targets ${target})
endforeach()

install(TARGETS ${graspsim_export_targets} EXPORT graspsimTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS graspsim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# Public headers: every header of the four modules' include/ (what their own public headers use),
# except the schema-free HDF5 inspector (h5_inspect.hpp: its library, graspsim_recordings_inspect,
# is for tests and tools in this tree). Of app/, what a program needs to run a scenario the way
# the CLI does: run.hpp (and the three it includes), devices (--device), run_budget (the size check
# before a run) and replay; session.hpp, a run stepped one tick at a time by the program that holds
# it, and program_finger.hpp, a finger that program moves as a device would. The rest of app/ is
# the run's inside and the CLI's report.
foreach(module engine hw recordings scripting)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/include/
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.hpp" PATTERN "h5_inspect.hpp" EXCLUDE)
endforeach()
set(graspsim_app_public_headers run.hpp output_file.hpp pacer.hpp live_channel.hpp devices.hpp run_budget.hpp
  replay.hpp session.hpp program_finger.hpp)
list(TRANSFORM graspsim_app_public_headers PREPEND ${PROJECT_SOURCE_DIR}/app/)
install(FILES ${graspsim_app_public_headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/graspsim/app)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenarios/ DESTINATION ${CMAKE_INSTALL_DATADIR}/graspsim/scenarios)

set(graspsim_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/graspsim)
install(EXPORT graspsimTargets NAMESPACE graspsim:: DESTINATION ${graspsim_cmake_dir})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/graspsimConfig.cmake.in
  ${CMAKE_BINARY_DIR}/graspsimConfig.cmake INSTALL_DESTINATION ${graspsim_cmake_dir}
  PATH_VARS CMAKE_INSTALL_DATADIR)
# Before 1.0 a minor version may change the API, so only the same major.minor is compatible.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/graspsimConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/graspsimConfig.cmake ${CMAKE_BINARY_DIR}/graspsimConfigVersion.cmake
        DESTINATION ${graspsim_cmake_dir})
