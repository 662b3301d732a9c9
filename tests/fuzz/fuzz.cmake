# libFuzzer target for the table reader (included from tests/CMakeLists.txt).
#
# libFuzzer ships with clang only, so this is a separate clang build, e.g.:
#   CC=clang CXX=clang++ cmake -S . -B build-fuzz -DENVMIS_FUZZ=ON -DENVMIS_BUILD_IO=OFF \
#     -DENVMIS_BUILD_APPS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo
#   cmake --build build-fuzz --target envmis_table_fuzz envmis_make_fuzz_seed
#   ctest --test-dir build-fuzz -L fuzz
option(ENVMIS_FUZZ "Build the libFuzzer table-reader target (clang only)" OFF)
if(NOT ENVMIS_FUZZ)
  return()
endif()
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "ENVMIS_FUZZ needs clang (libFuzzer); configure with CXX=clang++")
endif()

# The reader lives in envmis_core, so that is where coverage feedback and the sanitizers
# must be compiled in; the fuzzer would be blind and the checks absent otherwise.
set(envmis_fuzz_sanitizers -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
target_compile_options(envmis_core PRIVATE -fsanitize=fuzzer-no-link ${envmis_fuzz_sanitizers})
target_link_options(envmis_core INTERFACE -fsanitize=address,undefined)

add_executable(envmis_table_fuzz ${CMAKE_CURRENT_LIST_DIR}/table_fuzz.cpp)
target_compile_options(envmis_table_fuzz PRIVATE -fsanitize=fuzzer ${envmis_fuzz_sanitizers})
target_link_options(envmis_table_fuzz PRIVATE -fsanitize=fuzzer)
target_link_libraries(envmis_table_fuzz PRIVATE envmis::core)

add_executable(envmis_make_fuzz_seed ${CMAKE_CURRENT_LIST_DIR}/make_fuzz_seed.cpp)
target_link_libraries(envmis_make_fuzz_seed PRIVATE envmis::core)

# A short run from fresh seeds, so that a fuzz build is testable like any other. New
# inputs go to corpus/, crashes to artifacts/ (the file name printed on failure).
set(envmis_fuzz_dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz)
file(MAKE_DIRECTORY ${envmis_fuzz_dir}/corpus ${envmis_fuzz_dir}/artifacts)
add_test(NAME fuzz.seed COMMAND envmis_make_fuzz_seed ${envmis_fuzz_dir}/seeds)
add_test(NAME fuzz.table_reader COMMAND envmis_table_fuzz -max_total_time=10
  -artifact_prefix=${envmis_fuzz_dir}/artifacts/ ${envmis_fuzz_dir}/corpus ${envmis_fuzz_dir}/seeds)
set_tests_properties(fuzz.seed PROPERTIES FIXTURES_SETUP envmis_fuzz_seeds LABELS fuzz)
set_tests_properties(fuzz.table_reader PROPERTIES FIXTURES_REQUIRED envmis_fuzz_seeds LABELS fuzz TIMEOUT 120)
