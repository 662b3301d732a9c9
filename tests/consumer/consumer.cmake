# Install tests (included from tests/CMakeLists.txt): install this build into a fresh
# prefix, then configure, build and run tests/consumer against it with
# find_package(envmis), as a downstream project would. Catches headers, data files and
# dependencies missing from the install, which the in-tree tests never notice.
# Skipped without envmis::io (the consumer uses it) and for sanitizer or fuzz builds,
# whose instrumented libraries nobody installs.
if(NOT ENVMIS_BUILD_IO OR ENVMIS_SANITIZE OR ENVMIS_FUZZ)
  return()
endif()

set(envmis_consumer_dir ${CMAKE_CURRENT_BINARY_DIR}/consumer)
set(envmis_consumer_prefix ${envmis_consumer_dir}/prefix)

# Emptied first, so that a file dropped from the install rules cannot linger from an
# earlier run.
add_test(NAME consumer.clean COMMAND ${CMAKE_COMMAND} -E rm -rf ${envmis_consumer_prefix})
add_test(NAME consumer.install
  COMMAND ${CMAKE_COMMAND} --install ${CMAKE_BINARY_DIR} --prefix ${envmis_consumer_prefix} --config $<CONFIG>)
set_tests_properties(consumer.clean PROPERTIES FIXTURES_SETUP envmis_consumer_clean)
set_tests_properties(consumer.install PROPERTIES
  FIXTURES_REQUIRED envmis_consumer_clean FIXTURES_SETUP envmis_installed)

# The installed runtime holds nothing but lib/core: no study, I/O or picture code.
add_test(NAME consumer.core-contents
  COMMAND ${CMAKE_COMMAND} -DARCHIVE=${envmis_consumer_prefix}/${CMAKE_INSTALL_LIBDIR}/libenvmis_core.a
    -DSOURCES=${PROJECT_SOURCE_DIR}/lib/core/src -DNM=${CMAKE_NM} -DAR=${CMAKE_AR}
    -P ${CMAKE_CURRENT_LIST_DIR}/core_contents.cmake)
set_tests_properties(consumer.core-contents PROPERTIES FIXTURES_REQUIRED envmis_installed LABELS consumer)

# Each consumer asks for its own component alone. The core, build and study consumers
# also hide the third-party packages the other components need (OpenImageIO and
# OpenColorIO through pkg-config, nlohmann_json): their configuration must not look for
# them. The core consumer (a renderer) reads the table the build consumer wrote.
set(envmis_hidden_packages -DCMAKE_DISABLE_FIND_PACKAGE_PkgConfig=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON)
set(envmis_consumer_table ${envmis_consumer_dir}/build-build/work/sky.envmis)
foreach(kind build core study io)
  set(build ${envmis_consumer_dir}/build-${kind})
  set(hidden ${envmis_hidden_packages})
  if(kind STREQUAL "io")
    set(hidden)
  endif()
  set(table)
  if(kind STREQUAL "core")
    set(table ${envmis_consumer_table})
  endif()
  add_test(NAME consumer.${kind}
    COMMAND ${CMAKE_CTEST_COMMAND} --build-and-test ${CMAKE_CURRENT_LIST_DIR} ${build}
      --build-generator ${CMAKE_GENERATOR}
      --build-makeprogram ${CMAKE_MAKE_PROGRAM}
      --build-project envmis_consumer
      --build-target consumer_${kind}
      --build-options -DCMAKE_PREFIX_PATH=${envmis_consumer_prefix} -DCMAKE_BUILD_TYPE=$<CONFIG>
        -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER} -DENVMIS_CONSUMER_COMPONENTS=${kind} ${hidden}
      --test-command consumer_${kind} ${build}/work ${table})
  # $OCIO points at the installed config: the library would otherwise find the one in
  # this source tree first.
  set_tests_properties(consumer.${kind} PROPERTIES FIXTURES_REQUIRED envmis_installed LABELS consumer TIMEOUT 600
    ENVIRONMENT OCIO=${envmis_consumer_prefix}/${CMAKE_INSTALL_DATADIR}/envmis/ocio/config.ocio)
endforeach()
set_tests_properties(consumer.build PROPERTIES FIXTURES_SETUP envmis_consumer_table)
set_tests_properties(consumer.core PROPERTIES FIXTURES_REQUIRED "envmis_installed;envmis_consumer_table")
# The runtime through pkg-config alone, as a Makefile would build it (--define-prefix:
# the test installs into a prefix other than the configured one).
find_program(envmis_pkg_config pkg-config)
if(envmis_pkg_config)
  set(build ${envmis_consumer_dir}/build-pkgconfig)
  add_test(NAME consumer.core-pkgconfig
    COMMAND sh -c "mkdir -p '${build}/work' && \"$0\" -std=c++20 '${CMAKE_CURRENT_LIST_DIR}/main.cpp' \
      $(PKG_CONFIG_PATH='${envmis_consumer_prefix}/${CMAKE_INSTALL_LIBDIR}/pkgconfig' \"$1\" --define-prefix \
      --cflags --libs --static envmis-core) -o '${build}/consumer_core' && '${build}/consumer_core' '${build}/work' '${envmis_consumer_table}'"
      ${CMAKE_CXX_COMPILER} ${envmis_pkg_config})
  set_tests_properties(consumer.core-pkgconfig PROPERTIES FIXTURES_REQUIRED "envmis_installed;envmis_consumer_table" LABELS consumer
    TIMEOUT 300)
endif()
# The runtime as shared libraries, installed by component (tests/consumer/shared.cmake).
find_program(envmis_readelf NAMES readelf ${CMAKE_READELF})
if(envmis_readelf)
  add_test(NAME consumer.shared
    COMMAND ${CMAKE_COMMAND} -DSOURCE=${PROJECT_SOURCE_DIR} -DWORK=${envmis_consumer_dir}/shared
      -DCONSUMER=${CMAKE_CURRENT_LIST_DIR} -DCXX=${CMAKE_CXX_COMPILER} -DGENERATOR=${CMAKE_GENERATOR}
      -DCONFIG=$<CONFIG> -DREADELF=${envmis_readelf} -P ${CMAKE_CURRENT_LIST_DIR}/shared.cmake)
  # COST: ctest -j starts costlier tests first; on a fresh clone (no CTestCostData.txt yet)
  # this, the longest test, would otherwise start late and run alone at the end.
  set_tests_properties(consumer.shared PROPERTIES LABELS consumer TIMEOUT 900 COST 100)
endif()
# Early (COST): the examples' and consumers' chains of fixtures start from the install.
set_tests_properties(consumer.clean consumer.install PROPERTIES LABELS consumer COST 90)
