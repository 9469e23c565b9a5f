# ctest sdk.out_of_tree (rt-core/template/CMakeLists.txt), run with cmake -P:
#   BUILD_DIR   the superbuild's build tree, installed into WORK/prefix with cmake --install
#   WORK        a directory under BUILD_DIR; removed and made again, nothing is written elsewhere
#   TEMPLATE    rt-core/template: bundle/{CMakeLists.txt,pi-velocity.xml,MANIFEST.MF} and
#               ported/pi_velocity.c are copied to WORK/pi-velocity, as GUIDE.md tells a user
#   SAFETY_SRC  a small project using arflex::safety, arflex::rt_shared and
#               arflex::host_contract (which needs expat, found by the package config)
#   LIBDIR, INCLUDEDIR  the superbuild's CMAKE_INSTALL_LIBDIR and CMAKE_INSTALL_INCLUDEDIR
#   GENERATOR, C_COMPILER, C_FLAGS, LINK_FLAGS  passed on (the sanitizer build's flags)
#   JAR         the JDK's jar (empty: the test fails)
# Each project finds the SDK by CMAKE_PREFIX_PATH only (no package registries, no system
# packages), and the test checks that arflex_DIR is the one in WORK/prefix.
cmake_minimum_required(VERSION 3.25)

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}")
  endif()
  set(RUN_OUT "${out}" PARENT_SCOPE)
endfunction()

string(FIND "${WORK}" "${BUILD_DIR}/" under)
if(NOT under EQUAL 0)
  message(FATAL_ERROR "WORK (${WORK}) must be under the build dir ${BUILD_DIR}")
endif()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(prefix ${WORK}/prefix)

# 1. The SDK, installed from this build tree.
run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(f ${INCLUDEDIR}/arflex/component.h ${INCLUDEDIR}/arflex/safety_gate.h
          ${INCLUDEDIR}/arflex/host_contract.h ${LIBDIR}/libarflex_host_contract.a
          ${INCLUDEDIR}/arflex_types/sample.h ${LIBDIR}/libarflex_rt.a ${LIBDIR}/libarflex_rt.so
          ${LIBDIR}/libarflex_safety.a ${LIBDIR}/cmake/arflex/arflexConfig.cmake
          ${LIBDIR}/cmake/arflex/arflexConfigVersion.cmake ${LIBDIR}/cmake/arflex/arflexTargets.cmake)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${prefix}/${f}")
  endif()
endforeach()
if(EXISTS ${prefix}/${INCLUDEDIR}/arflex/beat.h)
  message(FATAL_ERROR "beat.h is the DRCR's, not the SDK's, and was installed")
endif()

set(configure_args -G ${GENERATOR} -DCMAKE_C_COMPILER=${C_COMPILER}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON
    "-DCMAKE_C_FLAGS=${C_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINK_FLAGS}")

function(build_project src bin)
  run("configure ${src}" ${CMAKE_COMMAND} -S ${src} -B ${bin} ${configure_args})
  file(STRINGS ${bin}/CMakeCache.txt dir REGEX "^arflex_DIR:")
  if(NOT dir STREQUAL "arflex_DIR:PATH=${prefix}/${LIBDIR}/cmake/arflex")
    message(FATAL_ERROR "found the SDK elsewhere: ${dir}")
  endif()
  run("build ${src}" ${CMAKE_COMMAND} --build ${bin})
endfunction()

# 2. The GUIDE's component, out of tree: its sources copied out, as a user would.
set(src ${WORK}/pi-velocity)
file(COPY ${TEMPLATE}/bundle/CMakeLists.txt ${TEMPLATE}/bundle/pi-velocity.xml
          ${TEMPLATE}/bundle/MANIFEST.MF ${TEMPLATE}/ported/pi_velocity.c DESTINATION ${src})
build_project(${src} ${src}/build)
run("pi-velocity --version" ${src}/build/pi-velocity --version)
if(NOT RUN_OUT MATCHES "^pi-velocity: arflex rt-core ABI [0-9]+\\.[0-9]+\n$")
  message(FATAL_ERROR "pi-velocity --version printed: ${RUN_OUT}")
endif()
message(STATUS "out of tree: ${RUN_OUT}")
# Linked statically: the executable a bundle carries needs no libarflex_rt.so on the cell.
run("readelf" readelf -d ${src}/build/pi-velocity)
if(RUN_OUT MATCHES "libarflex_rt")
  message(FATAL_ERROR "pi-velocity needs libarflex_rt.so:\n${RUN_OUT}")
endif()

# 3. arflex::safety, arflex::rt_shared and arflex::host_contract (reading the guide's contract).
build_project(${SAFETY_SRC} ${WORK}/safety)
run("safety-check" ${WORK}/safety/safety-check)
message(STATUS "safety: ${RUN_OUT}")
run("shared-check" ${WORK}/safety/shared-check)
message(STATUS "shared: ${RUN_OUT}")
run("contract-check" ${WORK}/safety/contract-check ${src}/pi-velocity.xml)
if(NOT RUN_OUT MATCHES "^pi-velocity: 2 outputs, 3 parameters, period 1000000 ns\n$")
  message(FATAL_ERROR "contract-check printed: ${RUN_OUT}")
endif()
message(STATUS "contract: ${RUN_OUT}")

# 4. The bundle, with the GUIDE's commands.
if(JAR)
  file(MAKE_DIRECTORY ${src}/jar/native/linux-x86_64 ${src}/jar/OSGI-INF/arflex)
  file(COPY ${src}/build/pi-velocity DESTINATION ${src}/jar/native/linux-x86_64)
  file(COPY ${src}/pi-velocity.xml DESTINATION ${src}/jar/OSGI-INF/arflex)
  # -XX:-UsePerfData: the JVM writes no /tmp/hsperfdata_<user>.
  run("jar --create" ${JAR} -J-XX:-UsePerfData --create --file ${src}/pi-velocity.jar
      --manifest ${src}/MANIFEST.MF -C ${src}/jar .)
  run("jar --list" ${JAR} -J-XX:-UsePerfData --list --file ${src}/pi-velocity.jar)
  foreach(e META-INF/MANIFEST.MF native/linux-x86_64/pi-velocity OSGI-INF/arflex/pi-velocity.xml)
    string(FIND "${RUN_OUT}" "${e}\n" at)
    if(at LESS 0)
      message(FATAL_ERROR "pi-velocity.jar has no ${e}:\n${RUN_OUT}")
    endif()
  endforeach()
  message(STATUS "bundle: ${src}/pi-velocity.jar")
else()
  # the suite's machines have the JDK (Maven needs it): a missing jar tool fails, it is not a
  # step quietly left out (D82)
  message(FATAL_ERROR "bundle: no jar tool found (the JDK's jar; scripts/setup.sh installs the JDK)")
endif()
