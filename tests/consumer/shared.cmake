# The runtime as shared libraries, as a renderer would take it (ctest: consumer.shared):
# builds this source tree with BUILD_SHARED_LIBS=ON and nothing but envmis::core and
# envmis::build, installs those two components alone, then builds and runs the build and
# core consumers against them with the third-party packages hidden, and checks that the
# renderer's binary loads libenvmis_core's shared object and no other of envmis's, which
# exports its API and hides its private helpers.
# Usage: cmake -DSOURCE=<repo> -DWORK=<folder> -DCONSUMER=<tests/consumer> -DCXX=<compiler>
#        -DGENERATOR=<generator> -DCONFIG=<Release> -DREADELF=<readelf> -P shared.cmake
foreach(variable SOURCE WORK CONSUMER CXX GENERATOR READELF)
  if(NOT ${variable})
    message(FATAL_ERROR "shared.cmake needs -D${variable}=...")
  endif()
endforeach()
if(NOT CONFIG)
  set(CONFIG Release)
endif()
file(REMOVE_RECURSE ${WORK})
set(hidden -DCMAKE_DISABLE_FIND_PACKAGE_PkgConfig=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON)

execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE} -B ${WORK}/envmis -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${CONFIG}
    -DCMAKE_CXX_COMPILER=${CXX} -DBUILD_SHARED_LIBS=ON -DENVMIS_BUILD_IO=OFF -DENVMIS_BUILD_TESTS=OFF
    -DENVMIS_BUILD_PYTHON=OFF ${hidden}
  COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK}/envmis --target envmis_core envmis_build --parallel 2
  COMMAND_ERROR_IS_FATAL ANY)
foreach(component core build)
  execute_process(COMMAND ${CMAKE_COMMAND} --install ${WORK}/envmis --prefix ${WORK}/prefix --component ${component}
    COMMAND_ERROR_IS_FATAL ANY)
endforeach()

set(table ${WORK}/build/work/sky.envmis)
foreach(kind build core)
  set(arguments ${WORK}/${kind}/work)
  if(kind STREQUAL "core")
    list(APPEND arguments ${table})
  endif()
  execute_process(COMMAND ${CMAKE_CTEST_COMMAND} --build-and-test ${CONSUMER} ${WORK}/${kind}
      --build-generator ${GENERATOR} --build-project envmis_consumer --build-target consumer_${kind}
      --build-options -DCMAKE_PREFIX_PATH=${WORK}/prefix -DCMAKE_BUILD_TYPE=${CONFIG} -DCMAKE_CXX_COMPILER=${CXX}
        -DENVMIS_CONSUMER_COMPONENTS=${kind} ${hidden}
      --test-command consumer_${kind} ${arguments}
    COMMAND_ERROR_IS_FATAL ANY)
endforeach()

execute_process(COMMAND ${READELF} -d ${WORK}/core/consumer_core OUTPUT_VARIABLE dynamic COMMAND_ERROR_IS_FATAL ANY)
string(REGEX MATCHALL "libenvmis_[a-z]+\\.so[.0-9]*" needed "${dynamic}")
if(NOT needed MATCHES "^libenvmis_core\\.so\\.[0-9]+\\.[0-9]+$")
  message(FATAL_ERROR "consumer_core needs [${needed}], expected libenvmis_core's shared object alone")
endif()
message(STATUS "consumer_core runs on ${needed}")

# The runtime's shared object exports its API (envmis/core_export.h; the bins' cells of
# envmis/sampling/bin_cells.h, which envmis::build's choice shares, among it) and none of
# its private helpers (lib/core/src): the mapped file.
file(GLOB core_object ${WORK}/prefix/lib*/libenvmis_core.so)
execute_process(COMMAND ${READELF} --dyn-syms -W ${core_object} OUTPUT_VARIABLE symbols COMMAND_ERROR_IS_FATAL ANY)
if(NOT symbols MATCHES "_ZN6envmis6EnvMapC[12]E")
  message(FATAL_ERROR "${core_object} does not export EnvMap's constructors")
endif()
string(REGEX MATCHALL "6detail10MappedFile|11choose_bins|10build_bins" private "${symbols}")
if(private)
  message(FATAL_ERROR "${core_object} exports private helpers: ${private}")
endif()
message(STATUS "${core_object} exports EnvMap and no private helper")
