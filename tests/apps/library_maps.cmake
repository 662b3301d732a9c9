# library_test's inputs, made once per ctest run (the fixture envmis_library_maps) instead
# of once in every test's process (ctest runs each test in a process of its own, so the
# suite's SetUpTestSuite ran nine times): the three bundled maps made 32x16 by
# `envmis convert`. Run as
#   cmake -DENVMIS=<envmis> -DDATA=<source>/data -DOUT=<folder> -P library_maps.cmake
# OUT is replaced; it is removed again by the fixture's clean-up test.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
foreach(name city.exr rooitou_park_1k.hdr studio.exr)
  get_filename_component(stem ${name} NAME_WE)
  execute_process(
    COMMAND "${ENVMIS}" convert "${DATA}/envmaps/${name}" -o "${OUT}/${stem}.exr" --to equirect --size 32x16
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    file(REMOVE_RECURSE "${OUT}")
    message(FATAL_ERROR "envmis convert ${name} failed (${rc}):\n${out}")
  endif()
endforeach()
