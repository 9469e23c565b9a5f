# ctest tools.new_component (rt-core/template/CMakeLists.txt), run with cmake -P: runs the
# generator (scripts/new-component.sh, `./arflex new component`) into WORK, never into bundles/,
# and checks its result:
#   - a bad name and an existing folder are refused, and change nothing;
#   - the generated folder has every file, with no template token left;
#   - <module> lines and dependencies are added to a copy of bundles/pom.xml once each, in front
#     of </modules> and </dependencies> (the one list of components, docs/DECISIONS.md D34),
#     every entry already there kept;
#   - the generated RT half and its unit test build against rt-core (this build tree) with the
#     project's warnings as errors, and the unit test passes.
#   SRC_ROOT  the repository;  BUILD_DIR  the superbuild's build tree;  WORK  a dir under it
#   GENERATOR, C_COMPILER, C_FLAGS, LINK_FLAGS  passed on (the sanitizer build's flags)
cmake_minimum_required(VERSION 3.25)

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}")
  endif()
  set(RUN_OUT "${out}" PARENT_SCOPE)
endfunction()
function(refused what expect_rc)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "${what}: exit ${rc}, expected ${expect_rc}:\n${out}")
  endif()
  message(STATUS "${what}: refused: ${out}")
endfunction()

string(FIND "${WORK}" "${BUILD_DIR}/" under)
if(NOT under EQUAL 0)
  message(FATAL_ERROR "WORK (${WORK}) must be under the build dir ${BUILD_DIR}")
endif()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/bundles)
file(COPY ${SRC_ROOT}/bundles/pom.xml DESTINATION ${WORK}/bundles)
set(gen ${SRC_ROOT}/scripts/new-component.sh)
set(name gen-probe)

# 1. Refusals.
refused("bad name" 2 ${gen} Gen_Probe --dest ${WORK}/bundles)
refused("name too long" 2 ${gen} a1234567890123456789012345678901234567890 --dest ${WORK}/bundles)
file(MAKE_DIRECTORY ${WORK}/bundles/taken)
refused("existing folder" 1 ${gen} taken --dest ${WORK}/bundles)
file(GLOB left LIST_DIRECTORIES true ${WORK}/bundles/taken/* ${WORK}/bundles/.new-*)
if(left)
  message(FATAL_ERROR "a refused run left files: ${left}")
endif()

# 2. Generate (through the front script, as a user would), and a second one.
run("arflex new component ${name}" ${SRC_ROOT}/arflex new component ${name} --dest ${WORK}/bundles)
run("arflex new component second" ${gen} second --dest ${WORK}/bundles)
set(b ${WORK}/bundles/${name})
foreach(f pom.xml README.md src/main/resources/OSGI-INF/arflex/${name}.xml
          native/CMakeLists.txt native/gen_probe.c native/test_gen_probe.c)
  if(NOT EXISTS ${b}/${f})
    message(FATAL_ERROR "not generated: ${b}/${f}")
  endif()
  file(READ ${b}/${f} text)
  if(text MATCHES "@NAME@|@C_NAME@")
    message(FATAL_ERROR "template token left in ${b}/${f}")
  endif()
endforeach()
file(READ ${b}/src/main/resources/OSGI-INF/arflex/${name}.xml text)
if(NOT text MATCHES "name=\"${name}\"" OR NOT text MATCHES "executable=\"${name}\"")
  message(FATAL_ERROR "contract does not name ${name}:\n${text}")
endif()

# 3. The module lines: once each, in order, inside <modules>.
file(READ ${WORK}/bundles/pom.xml pom)
string(REGEX MATCHALL "<module>${name}</module>" m "${pom}")
list(LENGTH m n)
if(NOT n EQUAL 1 OR NOT pom MATCHES "<module>${name}</module>\n    <module>second</module>\n  </modules>")
  message(FATAL_ERROR "bundles/pom.xml copy not as expected:\n${pom}")
endif()
set(dep_gen "<dependency><groupId>org.arflex</groupId><artifactId>org.arflex.cell.${name}</artifactId><version>\\\${project.version}</version>")
set(dep_second "<dependency><groupId>org.arflex</groupId><artifactId>org.arflex.cell.second</artifactId><version>\\\${project.version}</version>")
string(REGEX MATCHALL "<artifactId>org.arflex.cell.${name}</artifactId>" d "${pom}")
list(LENGTH d n)
if(NOT n EQUAL 1 OR NOT pom MATCHES "${dep_gen}\n      <exclusions><exclusion><groupId>\\*</groupId><artifactId>\\*</artifactId></exclusion></exclusions></dependency>\n    ${dep_second}\n[^\n]*\n  </dependencies>")
  message(FATAL_ERROR "bundles/pom.xml copy: the dependencies are not as expected:\n${pom}")
endif()
# the module and the dependency of every component already there are kept, in order
file(READ ${SRC_ROOT}/bundles/pom.xml orig)
string(REGEX MATCHALL "<(module|artifactId)>[^<]+</(module|artifactId)>" before "${orig}")
string(REGEX MATCHALL "<(module|artifactId)>[^<]+</(module|artifactId)>" after "${pom}")
foreach(x IN LISTS before)
  list(FIND after "${x}" i)
  if(i LESS 0)
    message(FATAL_ERROR "bundles/pom.xml copy lost ${x}")
  endif()
endforeach()

# 4. Build the generated RT half and its test against this build tree, run the test.
set(bin ${WORK}/build)
run("configure" ${CMAKE_COMMAND} -S ${SRC_ROOT}/rt-core/tests/new_component -B ${bin}
    -G ${GENERATOR} -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_BUILD_TYPE=RelWithDebInfo
    "-DCMAKE_C_FLAGS=${C_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINK_FLAGS}"
    -DSRC_ROOT=${SRC_ROOT} -DBUILD_DIR=${BUILD_DIR} -DBUNDLE_NATIVE=${b}/native)
run("build" ${CMAKE_COMMAND} --build ${bin})
run("ctest" ${CMAKE_CTEST_COMMAND} --test-dir ${bin} --output-on-failure -R "^rt\\.${name}\\.cycle$")
if(NOT RUN_OUT MATCHES "100% tests passed, 0 tests failed out of 1")
  message(FATAL_ERROR "the generated test did not run:\n${RUN_OUT}")
endif()
message(STATUS "generated ${name}: built, rt.${name}.cycle passed")
