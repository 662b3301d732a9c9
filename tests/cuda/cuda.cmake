# Compiles the runtime sampling path (env-map view, distributions, BSDFs, frame, RNG)
# as CUDA device code when nvcc is found (on PATH, in $CUDA_HOME/bin or
# /usr/local/cuda/bin). Compile-only: no GPU is needed. Warnings are errors, so a
# host-only call slipping into a __host__ __device__ function fails the build.
#
# nvcc is called directly rather than through enable_language(CUDA): CMake 3.25 cannot
# map C++20 to recent nvcc versions, and this check needs nothing else from CMake.
find_program(ENVMIS_NVCC nvcc HINTS $ENV{CUDA_HOME}/bin /usr/local/cuda/bin)
if(ENVMIS_NVCC)
  file(GLOB_RECURSE envmis_device_headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/lib/core/include/*.h
    ${PROJECT_SOURCE_DIR}/lib/study/include/*.h)
  set(object ${CMAKE_CURRENT_BINARY_DIR}/device_compile.o)
  add_custom_command(
    OUTPUT ${object}
    COMMAND ${ENVMIS_NVCC} -std=c++20 -Werror all-warnings -ccbin ${CMAKE_CXX_COMPILER}
            -I${PROJECT_SOURCE_DIR}/lib/core/include -I${PROJECT_BINARY_DIR}/lib/core/include
            -I${PROJECT_SOURCE_DIR}/lib/study/include -c ${CMAKE_CURRENT_LIST_DIR}/device_compile.cu -o ${object}
    DEPENDS ${CMAKE_CURRENT_LIST_DIR}/device_compile.cu ${envmis_device_headers}
    COMMENT "Compiling the sampling path as CUDA device code (nvcc)")
  add_custom_target(envmis_cuda_compile_check ALL DEPENDS ${object})
  message(STATUS "envmis: CUDA compile check enabled (${ENVMIS_NVCC})")
else()
  message(STATUS "envmis: nvcc not found, CUDA compile check skipped")
endif()
