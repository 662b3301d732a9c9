# The Python package (python/): built when ENVMIS_BUILD_PYTHON is on and Python 3 with
# NumPy and pybind11 are found; otherwise skipped with a message, so a machine without
# them still builds everything else. Not with sanitizers (the interpreter would need
# their runtime preloaded), fuzz builds, nor without envmis::io.
#
# Debian's packages (python3-numpy, python3-pytest, pybind11-dev) belong to
# /usr/bin/python3, which is preferred to another `python3` earlier on PATH; pass
# -DPython3_EXECUTABLE=... to choose another.
set(ENVMIS_PYTHON_FOUND OFF)
if(NOT ENVMIS_BUILD_PYTHON OR NOT ENVMIS_BUILD_IO OR ENVMIS_SANITIZE OR ENVMIS_FUZZ)
  return()
endif()
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter of the envmis package")
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module NumPy)
if(Python3_FOUND)
  find_package(pybind11 2.10 CONFIG)
endif()
if(NOT Python3_FOUND OR NOT pybind11_FOUND)
  message(STATUS "envmis: Python package skipped (needs Python 3 with NumPy and pybind11; scripts/setup.sh installs them)")
  return()
endif()
set(ENVMIS_PYTHON_INSTALL_DIR
  "${CMAKE_INSTALL_LIBDIR}/python${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}/site-packages"
  CACHE STRING "Where the envmis Python package is installed, relative to the prefix")
set(ENVMIS_PYTHON_FOUND ON)
add_subdirectory(python)
