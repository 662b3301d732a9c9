# libFuzzer targets (included from tests/CMakeLists.txt): the table reader on bytes in
# memory, the mapped loading path, and (with ENVMIS_BUILD_IO) the image reader and the
# report's JSON reader and writer.
#
# libFuzzer ships with clang only, so this is a separate clang build, e.g.:
#   CC=clang CXX=clang++ cmake -S . -B build-fuzz -DENVMIS_FUZZ=ON -DENVMIS_BUILD_APPS=OFF \
#     -DCMAKE_BUILD_TYPE=RelWithDebInfo
#   cmake --build build-fuzz --target envmis_fuzzers
#   ctest --test-dir build-fuzz -L fuzz
option(ENVMIS_FUZZ "Build the libFuzzer targets (clang only)" OFF)
if(NOT ENVMIS_FUZZ)
  return()
endif()
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "ENVMIS_FUZZ needs clang (libFuzzer); configure with CXX=clang++")
endif()

# The readers live in envmis_core and envmis_io, so that is where coverage feedback and the
# sanitizers must be compiled in; the fuzzer would be blind and the checks absent otherwise.
set(envmis_fuzz_sanitizers -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
set(envmis_fuzzed_libraries envmis_core)
if(TARGET envmis_io)
  list(APPEND envmis_fuzzed_libraries envmis_io envmis_report)
endif()
foreach(library ${envmis_fuzzed_libraries})
  target_compile_options(${library} PRIVATE -fsanitize=fuzzer-no-link ${envmis_fuzz_sanitizers})
  target_link_options(${library} INTERFACE -fsanitize=address,undefined)
endforeach()

add_custom_target(envmis_fuzzers)
set(envmis_fuzz_dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz)

# A fuzz target NAME from NAME.cpp, its seed maker, and a short ctest run from fresh
# seeds so that a fuzz build is testable like any other: new inputs go to
# fuzz/NAME/corpus, crashes to fuzz/NAME/artifacts (the file name printed on failure).
# Further arguments are libFuzzer flags for that target (.ci/run passes the same).
function(envmis_fuzz_target name seed_maker library)
  add_executable(envmis_${name} ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/${name}.cpp)
  target_compile_options(envmis_${name} PRIVATE -fsanitize=fuzzer ${envmis_fuzz_sanitizers})
  target_link_options(envmis_${name} PRIVATE -fsanitize=fuzzer)
  target_link_libraries(envmis_${name} PRIVATE ${library})
  add_dependencies(envmis_fuzzers envmis_${name} ${seed_maker})
  set(dir ${envmis_fuzz_dir}/${name})
  file(MAKE_DIRECTORY ${dir}/corpus ${dir}/artifacts)
  add_test(NAME fuzz.${name}.seed COMMAND ${seed_maker} ${dir}/seeds)
  add_test(NAME fuzz.${name} COMMAND envmis_${name} -max_total_time=10 -seed=1 ${ARGN} -artifact_prefix=${dir}/artifacts/
    ${dir}/corpus ${dir}/seeds)
  set_tests_properties(fuzz.${name}.seed PROPERTIES FIXTURES_SETUP envmis_${name}_seeds LABELS fuzz)
  set_tests_properties(fuzz.${name} PROPERTIES FIXTURES_REQUIRED envmis_${name}_seeds LABELS fuzz TIMEOUT 120)
endfunction()

add_executable(envmis_make_fuzz_seed ${CMAKE_CURRENT_LIST_DIR}/make_fuzz_seed.cpp)
target_link_libraries(envmis_make_fuzz_seed PRIVATE envmis::core envmis::build)
envmis_fuzz_target(table_fuzz envmis_make_fuzz_seed envmis::core)
envmis_fuzz_target(mapped_table_fuzz envmis_make_fuzz_seed envmis::core)

if(TARGET envmis_io)
  add_executable(envmis_make_image_fuzz_seed ${CMAKE_CURRENT_LIST_DIR}/make_image_fuzz_seed.cpp)
  target_link_libraries(envmis_make_image_fuzz_seed PRIVATE envmis::io)
  # OpenImageIO and OpenEXR leak a few bytes on some error paths and allocate what a
  # corrupt header declares (a string attribute of gigabytes): neither is envmis's to fix,
  # nor a crash, so leak detection and libFuzzer's memory limit are off for this target
  # (envmis's own leaks are caught by the ASan unit tests), and a slow input may take
  # minutes under ASan without being called a hang.
  envmis_fuzz_target(image_fuzz envmis_make_image_fuzz_seed envmis::io -detect_leaks=0 -rss_limit_mb=0 -timeout=300)

  # The report's reader and writer (nlohmann/json inside): inputs are text, so a
  # dictionary of the field names helps the fuzzer past the schema.
  add_executable(envmis_make_report_fuzz_seed ${CMAKE_CURRENT_LIST_DIR}/make_report_fuzz_seed.cpp)
  envmis_fuzz_target(report_fuzz envmis_make_report_fuzz_seed envmis::report -dict=${CMAKE_CURRENT_LIST_DIR}/report_fuzz.dict)
endif()
