# The Python package's tests (included from tests/CMakeLists.txt): each
# tests/python/test_*.py runs under pytest as one ctest test, python.<name>, against the
# package in the build tree; python.installed imports it from the install prefix.
if(NOT ENVMIS_PYTHON_FOUND)
  return()
endif()

file(GLOB envmis_python_tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/test_*.py)
set(envmis_python_environment
  PYTHONPATH=${PROJECT_BINARY_DIR}/python
  PYTHONDONTWRITEBYTECODE=1
  MPLBACKEND=Agg
  ENVMIS_CLI=$<$<TARGET_EXISTS:envmis>:$<TARGET_FILE:envmis>>
  ENVMIS_SOURCE_DIR=${PROJECT_SOURCE_DIR}
  ENVMIS_SHARED_MAPS=${ENVMIS_SHARED_MAPS})
foreach(test ${envmis_python_tests})
  get_filename_component(name ${test} NAME_WE)
  string(REGEX REPLACE "^test_" "" name ${name})
  add_test(NAME python.${name}
    COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider ${test}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
  set_tests_properties(python.${name} PROPERTIES ENVIRONMENT "${envmis_python_environment}" LABELS python TIMEOUT 600)
endforeach()

# The installed package imports with nothing of the build tree on the path (after
# consumer.install, tests/consumer/consumer.cmake).
if(TEST consumer.install)
  set(envmis_python_prefix ${CMAKE_CURRENT_BINARY_DIR}/consumer/prefix)
  add_test(NAME python.installed
    COMMAND ${Python3_EXECUTABLE} -c
      "import envmis, sys; assert envmis.__file__.startswith(sys.argv[1]), envmis.__file__; print(envmis.__file__)"
      ${envmis_python_prefix}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
  set_tests_properties(python.installed PROPERTIES FIXTURES_REQUIRED envmis_installed LABELS "python;consumer"
    ENVIRONMENT "PYTHONPATH=${envmis_python_prefix}/${ENVMIS_PYTHON_INSTALL_DIR};PYTHONDONTWRITEBYTECODE=1")
endif()
