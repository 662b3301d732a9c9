# Path tracer tests (included from examples.cmake): build apps/examples' path tracer
# against the install, make equal-area tables of the sunny map (the pbrt-v4-style
# sampler needs the square), render each scene with each environment technique and
# check that every one converges to the reference (the plain table at many samples):
# mean luminance within 4 standard errors (check_mean.py); likewise with the sky turned
# at render time (--rotate); an OBJ mesh; time budgets; refusals. Small images, a few seconds
# in all on 2 cores. Needs Embree and tinyobjloader (Debian's libembree-dev and
# libtinyobjloader-dev; scripts/setup.sh installs them) and Python for the check.
find_package(embree 3 CONFIG QUIET)
find_package(tinyobjloader CONFIG QUIET)
if(NOT embree_FOUND OR NOT tinyobjloader_FOUND OR NOT Python3_Interpreter_FOUND)
  message(STATUS "examples.pathtrace tests: skipped (need libembree-dev, libtinyobjloader-dev and Python)")
  return()
endif()

set(envmis_pt_work ${envmis_examples_work}/pathtrace)
# A build folder of its own: --build-and-test cleans the folder it builds in.
set(envmis_pt_build ${envmis_examples_dir}/build-pathtrace)
if(CMAKE_CONFIGURATION_TYPES)
  set(envmis_pt_exe ${envmis_pt_build}/$<CONFIG>/envmis_example_pathtrace)
else()
  set(envmis_pt_exe ${envmis_pt_build}/envmis_example_pathtrace)
endif()
set(envmis_pt ${CMAKE_COMMAND} -E env
  OCIO=${envmis_consumer_prefix}/${CMAKE_INSTALL_DATADIR}/envmis/ocio/config.ocio ${envmis_pt_exe})
set(envmis_pt_check ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/examples/check_mean.py)

add_test(NAME examples.pathtrace.build
  COMMAND ${CMAKE_CTEST_COMMAND} --build-and-test ${PROJECT_SOURCE_DIR}/apps/examples ${envmis_pt_build}
    --build-generator ${CMAKE_GENERATOR}
    --build-makeprogram ${CMAKE_MAKE_PROGRAM}
    --build-project envmis_examples
    --build-target envmis_example_pathtrace
    --build-options -DCMAKE_PREFIX_PATH=${envmis_consumer_prefix} -DCMAKE_BUILD_TYPE=$<CONFIG>
      -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER} -DCMAKE_COMPILE_WARNING_AS_ERROR=ON)
set_tests_properties(examples.pathtrace.build PROPERTIES
  FIXTURES_REQUIRED envmis_installed FIXTURES_SETUP envmis_pt_built TIMEOUT 600 COST 80)

add_test(NAME examples.pathtrace.work COMMAND ${CMAKE_COMMAND} -E make_directory ${envmis_pt_work})
add_test(NAME examples.pathtrace.square
  COMMAND envmis convert ${envmis_examples_map} -o ${envmis_pt_work}/square.exr --size 128)
set_tests_properties(examples.pathtrace.work PROPERTIES FIXTURES_SETUP envmis_pt_work)
set_tests_properties(examples.pathtrace.square PROPERTIES
  FIXTURES_REQUIRED envmis_pt_work FIXTURES_SETUP envmis_pt_square TIMEOUT 120)
foreach(table plain:--no-compensate compensated bins:--bins:121)
  string(REPLACE ":" ";" parts ${table})
  list(POP_FRONT parts name)
  add_test(NAME examples.pathtrace.table.${name}
    COMMAND envmis precompute ${envmis_pt_work}/square.exr -o ${envmis_pt_work}/${name}.envmis
      --mapping equal-area ${parts})
  set_tests_properties(examples.pathtrace.table.${name} PROPERTIES
    FIXTURES_REQUIRED envmis_pt_square FIXTURES_SETUP envmis_pt_tables TIMEOUT 120)
endforeach()

# A render of 256 passes (seed 1) that must converge to a reference: the tests
# examples.pathtrace.NAME and NAME.converges (check_mean.py against REFERENCE.json, made
# by the tests of fixture REQUIRED; its relative MSE in NAME.json); the arguments after
# REQUIRED are the renderer's table and options.
function(envmis_pt_converges name reference required)
  add_test(NAME examples.pathtrace.${name}
    COMMAND ${envmis_pt} ${ARGN} -o ${envmis_pt_work}/${name}.exr --spp 256 --seed 1 ${envmis_pt_args}
      --reference ${envmis_pt_work}/${reference}.exr)
  add_test(NAME examples.pathtrace.${name}.converges
    COMMAND ${envmis_pt_check} ${envmis_pt_work}/${reference}.json ${envmis_pt_work}/${name}.json)
  set_tests_properties(examples.pathtrace.${name} PROPERTIES
    FIXTURES_REQUIRED ${required} FIXTURES_SETUP envmis_pt_${name} TIMEOUT 300)
  set_tests_properties(examples.pathtrace.${name}.converges PROPERTIES
    FIXTURES_REQUIRED envmis_pt_${name} TIMEOUT 60)
endfunction()

# Per scene: a reference (plain table, 4096 passes, seed 1000) and each technique.
set(envmis_pt_args --size 48x36 --bounces 3)
foreach(scene objects materials interior mesh)
  add_test(NAME examples.pathtrace.${scene}.reference
    COMMAND ${envmis_pt} ${envmis_pt_work}/plain.envmis -o ${envmis_pt_work}/${scene}-reference.exr
      --scene ${scene} --spp 4096 --seed 1000 ${envmis_pt_args})
  set_tests_properties(examples.pathtrace.${scene}.reference PROPERTIES
    FIXTURES_REQUIRED "envmis_pt_built;envmis_pt_tables" FIXTURES_SETUP envmis_pt_${scene} TIMEOUT 300)
  foreach(technique plain:plain:global compensated:compensated:global bins:bins:bins pbrt:compensated:pbrt)
    string(REPLACE ":" ";" parts ${technique})
    list(POP_FRONT parts name table env)
    envmis_pt_converges(${scene}.${name} ${scene}-reference envmis_pt_${scene}
      ${envmis_pt_work}/${table}.envmis --scene ${scene} --env ${env})
  endforeach()
endforeach()

# Bins at the camera's hit only, the compensated table of the same image beyond; at the
# first two vertices, the binned table's own plain density beyond; several environment
# samples a vertex (balance heuristic with counts).
envmis_pt_converges(objects.bins-first objects-reference envmis_pt_objects ${envmis_pt_work}/bins.envmis
  --scene objects --env bins --bins-depth 1 --beyond ${envmis_pt_work}/compensated.envmis)
envmis_pt_converges(objects.bins-depth objects-reference envmis_pt_objects ${envmis_pt_work}/bins.envmis
  --scene objects --env bins --bins-depth 2)
envmis_pt_converges(objects.light-samples objects-reference envmis_pt_objects ${envmis_pt_work}/compensated.envmis
  --scene objects --light-samples 4)

# The sky turned at render time (--rotate 90, rotated.h): every technique converges to
# the turned reference, which differs from the unturned one.
add_test(NAME examples.pathtrace.rotated.reference
  COMMAND ${envmis_pt} ${envmis_pt_work}/plain.envmis -o ${envmis_pt_work}/rotated-reference.exr
    --scene objects --spp 4096 --seed 1000 --rotate 90 ${envmis_pt_args})
add_test(NAME examples.pathtrace.rotated.differs
  COMMAND ${envmis_pt_check} ${envmis_pt_work}/objects-reference.json ${envmis_pt_work}/rotated-reference.json --differ)
set_tests_properties(examples.pathtrace.rotated.reference PROPERTIES
  FIXTURES_REQUIRED "envmis_pt_built;envmis_pt_tables" FIXTURES_SETUP envmis_pt_rotated TIMEOUT 300)
set_tests_properties(examples.pathtrace.rotated.differs PROPERTIES
  FIXTURES_REQUIRED "envmis_pt_rotated;envmis_pt_objects" TIMEOUT 60)
foreach(technique compensated:compensated:global bins:bins:bins pbrt:compensated:pbrt)
  string(REPLACE ":" ";" parts ${technique})
  list(POP_FRONT parts name table env)
  envmis_pt_converges(rotated.${name} rotated-reference envmis_pt_rotated
    ${envmis_pt_work}/${table}.envmis --scene objects --env ${env} --rotate 90)
endforeach()

# A time budget ends the render after the first pass that reaches it.
add_test(NAME examples.pathtrace.time-budget
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/timed.exr --time 0.2
    ${envmis_pt_args})
set_tests_properties(examples.pathtrace.time-budget PROPERTIES
  FIXTURES_REQUIRED "envmis_pt_built;envmis_pt_tables" PASS_REGULAR_EXPRESSION "48x36, [0-9]+ spp, 0\\.[2-9]" TIMEOUT 60)

# A mesh read from an OBJ file replaces the knot: the ground's 2 triangles and its 4.
add_test(NAME examples.pathtrace.obj
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/obj.exr --scene mesh
    --obj ${CMAKE_CURRENT_SOURCE_DIR}/examples/data/tetrahedron.obj --spp 4 ${envmis_pt_args})
set_tests_properties(examples.pathtrace.obj PROPERTIES
  FIXTURES_REQUIRED "envmis_pt_built;envmis_pt_tables" PASS_REGULAR_EXPRESSION "mesh \\(6 triangles\\)"
  TIMEOUT 60)

# Refusals name the problem and the fix.
add_test(NAME examples.pathtrace.refuses-pbrt-on-equirect
  COMMAND ${envmis_pt} ${envmis_examples_work}/compensated.envmis -o ${envmis_pt_work}/refused.exr --env pbrt)
add_test(NAME examples.pathtrace.refuses-bins-without-bins
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/refused.exr --env bins)
add_test(NAME examples.pathtrace.refuses-beyond-of-another-image
  COMMAND ${envmis_pt} ${envmis_pt_work}/bins.envmis -o ${envmis_pt_work}/refused.exr --env bins --bins-depth 1
    --beyond ${envmis_examples_work}/compensated.envmis)
add_test(NAME examples.pathtrace.refuses-beyond-without-depth
  COMMAND ${envmis_pt} ${envmis_pt_work}/bins.envmis -o ${envmis_pt_work}/refused.exr --env bins
    --beyond ${envmis_pt_work}/compensated.envmis)
add_test(NAME examples.pathtrace.refuses-a-missing-output-folder
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/no-such-folder/x.exr)
add_test(NAME examples.pathtrace.refuses-a-reference-of-another-size
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/refused.exr --size 16x16
    --reference ${envmis_pt_work}/objects-reference.exr)
add_test(NAME examples.pathtrace.refuses-a-signed-number
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/refused.exr --seed " -1")
add_test(NAME examples.pathtrace.refuses-unknown-scene
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/refused.exr --scene kitchen)
add_test(NAME examples.pathtrace.refuses-a-bad-obj
  COMMAND ${envmis_pt} ${envmis_pt_work}/compensated.envmis -o ${envmis_pt_work}/refused.exr --scene mesh
    --obj ${envmis_examples_map})
set_tests_properties(examples.pathtrace.refuses-pbrt-on-equirect PROPERTIES
  PASS_REGULAR_EXPRESSION "pbrt-v4's equal-area square.*--mapping equal-area")
set_tests_properties(examples.pathtrace.refuses-bins-without-bins PROPERTIES
  PASS_REGULAR_EXPRESSION "has no bins.*--bins 121")
set_tests_properties(examples.pathtrace.refuses-beyond-of-another-image PROPERTIES
  PASS_REGULAR_EXPRESSION "--beyond needs a table of the same image")
set_tests_properties(examples.pathtrace.refuses-beyond-without-depth PROPERTIES
  PASS_REGULAR_EXPRESSION "--beyond is the table past --bins-depth: add --bins-depth N")
set_tests_properties(examples.pathtrace.refuses-a-missing-output-folder PROPERTIES
  PASS_REGULAR_EXPRESSION "x\\.exr: no such folder")
set_tests_properties(examples.pathtrace.refuses-a-reference-of-another-size PROPERTIES
  PASS_REGULAR_EXPRESSION "the reference is 48x36, the render 16x16"
  FIXTURES_REQUIRED "envmis_pt_built;envmis_pt_tables;envmis_pt_objects" TIMEOUT 60)
set_tests_properties(examples.pathtrace.refuses-a-signed-number PROPERTIES
  PASS_REGULAR_EXPRESSION "--seed ' -1': expected an integer")
set_tests_properties(examples.pathtrace.refuses-unknown-scene PROPERTIES
  PASS_REGULAR_EXPRESSION "--scene 'kitchen': expected one of objects, materials, interior, mesh")
set_tests_properties(examples.pathtrace.refuses-a-bad-obj PROPERTIES
  PASS_REGULAR_EXPRESSION "not a readable OBJ file|no faces")
set_tests_properties(examples.pathtrace.refuses-pbrt-on-equirect examples.pathtrace.refuses-bins-without-bins
  examples.pathtrace.refuses-beyond-of-another-image examples.pathtrace.refuses-beyond-without-depth
  examples.pathtrace.refuses-a-missing-output-folder examples.pathtrace.refuses-a-signed-number
  examples.pathtrace.refuses-unknown-scene examples.pathtrace.refuses-a-bad-obj PROPERTIES
  FIXTURES_REQUIRED "envmis_pt_built;envmis_pt_tables;envmis_examples_tables" TIMEOUT 60)
