# CTest cellmodel.no_mujoco (included from the top-level CMakeLists.txt after every bundle and
# the simulator): the RT halves of the bundles must not link MuJoCo; only the simulator's own
# components (sim-robot, sim-camera) may. The executables are the ones the bundles' component
# descriptors name (bundles/*/src/main/resources/OSGI-INF/arflex/*.xml, <implementation
# executable="...">); the check runs `ldd` on the built files (check_no_mujoco.cmake), so a
# dependency that comes in through another library is found too.
set(_arflex_sim_own sim-robot sim-camera)
file(GLOB _arflex_descriptors ${CMAKE_SOURCE_DIR}/bundles/*/src/main/resources/OSGI-INF/arflex/*.xml)
set(_arflex_rt_exes)
foreach(d IN LISTS _arflex_descriptors)
  file(READ ${d} _xml)
  if(_xml MATCHES "<implementation[^>]* executable=\"([^\"]+)\"")
    list(APPEND _arflex_rt_exes ${CMAKE_MATCH_1})
  endif()
endforeach()
list(REMOVE_DUPLICATES _arflex_rt_exes)
set(_forbidden)
set(_required)
foreach(exe IN LISTS _arflex_rt_exes)
  if(NOT TARGET ${exe})
    message(STATUS "cellmodel.no_mujoco: ${exe} is not built in this configuration")
  elseif(exe IN_LIST _arflex_sim_own)
    list(APPEND _required "$<TARGET_FILE:${exe}>")
  else()
    list(APPEND _forbidden "$<TARGET_FILE:${exe}>")
  endif()
endforeach()
string(REPLACE ";" "|" _forbidden "${_forbidden}")
string(REPLACE ";" "|" _required "${_required}")
add_test(NAME cellmodel.no_mujoco
         COMMAND ${CMAKE_COMMAND} "-DFORBIDDEN=${_forbidden}" "-DREQUIRED=${_required}"
                 -P ${CMAKE_CURRENT_LIST_DIR}/check_no_mujoco.cmake)
set_tests_properties(cellmodel.no_mujoco PROPERTIES TIMEOUT 60)
