# Checks that the installed envmis::core is the runtime alone: its archive holds exactly the
# objects of lib/core/src (no build, study, I/O or picture code) and defines no symbol of those
# libraries or of their third-party dependencies. Run by consumer.core-contents:
#   cmake -DARCHIVE=<prefix>/lib/libenvmis_core.a -DSOURCES=<repo>/lib/core/src -DNM=nm -DAR=ar -P core_contents.cmake
foreach(variable ARCHIVE SOURCES NM AR)
  if(NOT ${variable})
    message(FATAL_ERROR "core_contents.cmake needs -D${variable}=...")
  endif()
endforeach()
if(NOT EXISTS ${ARCHIVE})
  message(FATAL_ERROR "${ARCHIVE} was not installed")
endif()

file(GLOB_RECURSE sources RELATIVE ${SOURCES} ${SOURCES}/*.cpp)
set(expected)
foreach(source ${sources})
  get_filename_component(name ${source} NAME)
  list(APPEND expected ${name}.o)
endforeach()
execute_process(COMMAND ${AR} t ${ARCHIVE} OUTPUT_VARIABLE members COMMAND_ERROR_IS_FATAL ANY)
string(REGEX REPLACE "\n$" "" members "${members}")
string(REPLACE "\n" ";" members "${members}")
list(SORT expected)
list(SORT members)
if(NOT members STREQUAL expected)
  message(FATAL_ERROR "libenvmis_core.a holds [${members}], expected the objects of lib/core/src: [${expected}]")
endif()

execute_process(COMMAND ${NM} -C --defined-only ${ARCHIVE} OUTPUT_VARIABLE symbols COMMAND_ERROR_IS_FATAL ANY)
foreach(foreign "envmis::Bsdf" "envmis::Frame" "envmis::Technique" "envmis::DirectLightingEstimator"
                "envmis::compare" "envmis::choose_alpha" "envmis::io::" "envmis::pictures::" "Eigen::"
                "envmis::write_table(" "envmis::rgbe_round(" "envmis::remap(" "envmis::AtomicFile"
                "envmis::write_file_atomically(" "envmis::build_bins(" "envmis::choose_bin_layout("
                "choose_bins(" "envmis::build_env_map(" "OpenImageIO" "OCIO" "Imf_")
  string(FIND "${symbols}" "${foreign}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "libenvmis_core.a defines a symbol of another library: '${foreign}'")
  endif()
endforeach()
list(LENGTH members count)
message(STATUS "libenvmis_core.a: ${count} objects, all from lib/core/src; no build, study, I/O or picture symbols")
