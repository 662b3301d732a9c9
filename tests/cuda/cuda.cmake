# Compiles the runtime sampling path (env-map view, distributions, BSDFs, frame, RNG)
# as CUDA device code when nvcc is found (on PATH, in $CUDA_HOME/bin or
# /usr/local/cuda/bin). Compile-only: no GPU is needed. Then a table sampled on a GPU
# against the CPU, run where a device is. Warnings are errors, so a
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

  # A table sampled on the GPU against the CPU (table_on_gpu.cu): built where the CUDA
  # runtime is found too, run by ctest, skipped (exit 77) where there is no device.
  get_filename_component(envmis_cuda_root ${ENVMIS_NVCC} DIRECTORY)
  find_library(ENVMIS_CUDART cudart HINTS ${envmis_cuda_root}/../lib64 $ENV{CUDA_HOME}/lib64)
  if(ENVMIS_CUDART AND TARGET envmis)
    set(table_object ${CMAKE_CURRENT_BINARY_DIR}/table_on_gpu.o)
    add_custom_command(
      OUTPUT ${table_object}
      COMMAND ${ENVMIS_NVCC} -std=c++20 -O2 -Werror all-warnings -ccbin ${CMAKE_CXX_COMPILER}
              -I${PROJECT_SOURCE_DIR}/lib/core/include -I${PROJECT_BINARY_DIR}/lib/core/include
              -c ${CMAKE_CURRENT_LIST_DIR}/table_on_gpu.cu -o ${table_object}
      DEPENDS ${CMAKE_CURRENT_LIST_DIR}/table_on_gpu.cu ${envmis_device_headers}
      COMMENT "Compiling the GPU table check (nvcc)")
    add_executable(envmis_cuda_table_check ${table_object})
    set_target_properties(envmis_cuda_table_check PROPERTIES LINKER_LANGUAGE CXX)
    target_link_libraries(envmis_cuda_table_check PRIVATE envmis::core ${ENVMIS_CUDART})
    set(envmis_cuda_table ${CMAKE_CURRENT_BINARY_DIR}/cuda_check.envmis)
    add_test(NAME cuda.table-on-gpu.table
      COMMAND envmis precompute ${PROJECT_SOURCE_DIR}/data/envmaps/rooitou_park_1k.hdr -o ${envmis_cuda_table})
    add_test(NAME cuda.table-on-gpu COMMAND envmis_cuda_table_check ${envmis_cuda_table})
    set_tests_properties(cuda.table-on-gpu.table PROPERTIES FIXTURES_SETUP envmis_cuda_table LABELS cuda)
    set_tests_properties(cuda.table-on-gpu PROPERTIES FIXTURES_REQUIRED envmis_cuda_table SKIP_RETURN_CODE 77
      LABELS cuda)
  endif()
else()
  message(STATUS "envmis: nvcc not found, CUDA compile check skipped")
endif()
