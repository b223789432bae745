# Run by ctest (tests/install/CMakeLists.txt gives the -D values). Each step that fails stops the
# test with its output. Everything is written under WORK_DIR (the build's test-tmp), which each
# run starts afresh.
cmake_minimum_required(VERSION 3.20)
foreach(var BUILD_DIR CONSUMER_DIR WORK_DIR GENERATOR CXX_COMPILER BUILD_TYPE)
  if(NOT ${var})
    message(FATAL_ERROR "consumer_test.cmake needs -D${var}=...")
  endif()
endforeach()

function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    string(JOIN " " command ${ARGN})
    message(FATAL_ERROR "${what} failed (exit ${rc}):\n  ${command}\n${out}")
  endif()
  message(STATUS "${what}: ok")
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
step("cmake --install into ${prefix}"
  ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --config ${BUILD_TYPE})

# The consumer, as a user would build it, with this build's compiler and flags. The usage
# requirements of graspsim::app alone must bring the flags that keep the trace bit for bit.
set(configure ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/consumer -G ${GENERATOR}
  -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=${BUILD_TYPE}
  -DCMAKE_CXX_COMPILER=${CXX_COMPILER} "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
  "-DCMAKE_EXE_LINKER_FLAGS=${LINK_FLAGS}")
if(C_COMPILER)
  list(APPEND configure -DCMAKE_C_COMPILER=${C_COMPILER})
endif()
if(LAUNCHER)
  list(APPEND configure -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
step("configure examples/consumer against ${prefix}" ${configure})
step("build examples/consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/consumer --config ${BUILD_TYPE})

# The installed app/ headers an embedding program includes on their own compile alone with
# graspsim::app's usage requirements (a file each that includes only it): a header that leans on
# another's includes fails here. session.hpp is checked by the consumer (its first include);
# run.hpp's family by the consumer too. About 1.3 s of compiling a header.
set(alone ${WORK_DIR}/headers-alone)
set(app_headers program_finger.hpp devices.hpp)
set(alone_sources "")
foreach(header ${app_headers})
  string(REPLACE ".hpp" ".cpp" source ${header})
  file(WRITE ${alone}/${source} "#include <graspsim/app/${header}>\n")
  list(APPEND alone_sources ${source})
endforeach()
file(WRITE ${alone}/CMakeLists.txt "cmake_minimum_required(VERSION 3.20)
project(graspsim_headers_alone LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(graspsim REQUIRED)
add_library(headers_alone OBJECT ${alone_sources})
target_link_libraries(headers_alone PRIVATE graspsim::app)
")
set(configure_alone ${configure})
list(TRANSFORM configure_alone REPLACE "^${CONSUMER_DIR}$" "${alone}")
list(TRANSFORM configure_alone REPLACE "^${WORK_DIR}/consumer$" "${alone}/build")
step("configure: every installed app/ header alone" ${configure_alone})
step("build: every installed app/ header alone" ${CMAKE_COMMAND} --build ${alone}/build --config ${BUILD_TYPE})

set(scenario ${prefix}/share/graspsim/scenarios/two_finger_lift.lua)
set(consumer ${WORK_DIR}/consumer/graspsim_consumer)
if(NOT EXISTS ${consumer})   # a multi-config generator puts it under the configuration's name
  set(consumer ${WORK_DIR}/consumer/${BUILD_TYPE}/graspsim_consumer)
endif()
step("graspsim_consumer two_finger_lift.lua" ${consumer} ${scenario} ${WORK_DIR}/consumer.h5)
step("graspsim run two_finger_lift.lua (installed CLI)"
  ${prefix}/bin/graspsim run ${scenario} --out ${WORK_DIR}/cli.h5 --quiet)
step("graspsim compare --bitwise cli.h5 consumer.h5 (0: every stored bit equal)"
  ${prefix}/bin/graspsim compare ${WORK_DIR}/cli.h5 ${WORK_DIR}/consumer.h5 --bitwise)
