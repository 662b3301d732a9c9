# Every name in tests/CMakeLists.txt's slow list is a test of this build: ctest lists
# COUNT tests labelled slow (a renamed test would silently lose its label).
# Usage: cmake -DBUILD=<build folder> -DCOUNT=<list length> -P slow_tests_exist.cmake
execute_process(COMMAND ${CMAKE_CTEST_COMMAND} --test-dir ${BUILD} -N -L "^slow$"
  OUTPUT_VARIABLE listing RESULT_VARIABLE rc)
string(REGEX MATCH "Total Tests: ([0-9]+)" _ "${listing}")
if(NOT rc EQUAL 0 OR NOT CMAKE_MATCH_1 EQUAL COUNT)
  message(FATAL_ERROR "ctest lists ${CMAKE_MATCH_1} tests labelled slow, the list names ${COUNT}:\n${listing}")
endif()
