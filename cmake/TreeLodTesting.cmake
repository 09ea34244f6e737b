# Test and benchmark helpers for tests/, bench/ and each technique's folder (techniques/<name>/CMakeLists.txt).
#
# treelod_add_test(NAME [OGRE | USES_OGRE] SOURCES... [LIBS ...]): one gtest executable, which ctest
#   runs once per gtest suite ("Suite.*"). OGRE: a headless Ogre test binary, whose main()
#   (tests/ogre/OgreTestMain.cpp) tears the Root down before returning; the others' main() is
#   tests/core/TestMain.cpp. Both OGRE and USES_OGRE label the tests "ogre" (ctest -L ogre / -LE ogre),
#   the others "core". SUITE_COSTS Suite=seconds...: ctest's COST of a suite whose few tests take
#   long, so that ctest starts it early on a tree without timings of its own.
# treelod_add_ogre_tests(SOURCES... [RENDER_SYSTEM_TESTS Suite.test...]): a technique's Ogre tests
#   join test_ogre (tests/ogre/CMakeLists.txt: one executable, one Ogre start-up per process); their
#   goldens are the technique's golden/ folder; RENDER_SYSTEM_TESTS run again under GL and GLES2.
# treelod_add_cli_test(NAME SCRIPT [ARGS...]): `bash SCRIPT <treelod> <source dir> <output dir> ARGS`.

# The test sources' own optimisation (after the configuration's, so it wins): -O1 in Release, where
# -O3 spent a third of the build's compile time on assertions and set-up; what they test is built
# as configured. Not lower: header code they instantiate (GLM, the chunk codecs) runs in their
# loops, and at -O0 under ASan some tests took 3 to 7 times as long.
set(TREELOD_TEST_CXX_FLAGS "$<$<CONFIG:Release>:-O1>" CACHE STRING
  "Compile options of the test executables' own sources (the libraries they test keep the configuration's)")

# Test data and caches stay inside the build tree (XDG_CACHE_HOME).
set(TREELOD_TEST_ENV
  "XDG_CACHE_HOME=${CMAKE_BINARY_DIR}/test-cache"
  "TREELOD_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
  "TREELOD_TEST_OUT=${CMAKE_BINARY_DIR}/test-out")

function(treelod_add_test name)
  cmake_parse_arguments(T "OGRE;USES_OGRE" "" "SOURCES;LIBS;SUITE_COSTS" ${ARGN})
  if(T_OGRE)
    add_executable(${name} ${T_SOURCES} ${PROJECT_SOURCE_DIR}/tests/ogre/OgreTestMain.cpp)
    target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/ogre)
  else()
    add_executable(${name} ${T_SOURCES} ${PROJECT_SOURCE_DIR}/tests/core/TestMain.cpp)
  endif()
  target_link_libraries(${name} PRIVATE GTest::gtest ${T_LIBS} treelod_warnings)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/core) # TestTrees.h, TestOutput.h
  target_compile_options(${name} PRIVATE ${TREELOD_TEST_CXX_FLAGS})
  target_compile_definitions(${name} PRIVATE
    TREELOD_SOURCE_DIR="${PROJECT_SOURCE_DIR}" TREELOD_BINARY_DIR="${CMAKE_BINARY_DIR}")
  if(T_OGRE OR T_USES_OGRE)
    set(label ogre)
  else()
    set(label core)
    set_property(GLOBAL APPEND PROPERTY TREELOD_CORE_TEST_TARGETS ${name})
  endif()
  # One ctest test per gtest suite (cmake/TreeLodSuiteTests.cmake, after each link): a suite's tests
  # share one process, so one Ogre start-up and one bake of each tree a suite keeps (a static in
  # the test source, OgreEnvironment::keep). `ctest -R Suite\.` still selects a suite.
  set(suites ${CMAKE_CURRENT_BINARY_DIR}/${name}_suites.cmake)
  string(REPLACE ";" "|" environment "${TREELOD_TEST_ENV}")
  string(REPLACE ";" "|" suite_costs "${T_SUITE_COSTS}")
  add_custom_command(TARGET ${name} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -D TEST_EXECUTABLE=$<TARGET_FILE:${name}> -D CTEST_FILE=${suites}
            -D LABEL=${label} -D WORKING_DIRECTORY=${CMAKE_CURRENT_BINARY_DIR} -D ENVIRONMENT=${environment}
            "-DSUITE_COSTS=${suite_costs}" -P ${PROJECT_SOURCE_DIR}/cmake/TreeLodSuiteTests.cmake
    BYPRODUCTS ${suites} VERBATIM)
  file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/${name}_include.cmake
    "if(EXISTS \"${suites}\")\n  include(\"${suites}\")\nelse()\n  add_test(${name}_NOT_BUILT ${name}_NOT_BUILT)\nendif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${CMAKE_CURRENT_BINARY_DIR}/${name}_include.cmake)
  set_property(GLOBAL APPEND PROPERTY TREELOD_TEST_TARGETS ${name})
endfunction()

function(treelod_add_ogre_tests)
  cmake_parse_arguments(T "" "" "SOURCES;RENDER_SYSTEM_TESTS" ${ARGN})
  foreach(source IN LISTS T_SOURCES)
    set_property(GLOBAL APPEND PROPERTY TREELOD_OGRE_TEST_SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/${source})
  endforeach()
  set_property(GLOBAL APPEND PROPERTY TREELOD_RENDER_SYSTEM_TESTS ${T_RENDER_SYSTEM_TESTS})
endfunction()

function(treelod_add_cli_test name script)
  if(TARGET treelod AND TARGET Plugin_TreeLod)
    add_test(NAME ${name}
      COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/${script} $<TARGET_FILE:treelod> ${PROJECT_SOURCE_DIR}
              ${CMAKE_BINARY_DIR}/test-out/${name} ${ARGN})
    set_tests_properties(${name} PROPERTIES ENVIRONMENT "${TREELOD_TEST_ENV}")
  endif()
endfunction()

# Benchmarks (bench/CMakeLists.txt builds them; speed targets are checked there, never in tests):
# treelod_add_core_bench_sources(SOURCES...): Google Benchmark sources joining treelod_core_bench.
# treelod_add_study(NAME SOURCES...): a headless Ogre study (render, measure against the reference,
#   write CSV/Markdown/SVG); StudySupport.h is bench/'s. Needs TreeLodOffscreen.
function(treelod_add_core_bench_sources)
  foreach(source IN LISTS ARGN)
    set_property(GLOBAL APPEND PROPERTY TREELOD_CORE_BENCH_SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/${source})
  endforeach()
endfunction()

function(treelod_add_study name)
  if(NOT TREELOD_BUILD_BENCHMARKS OR NOT TARGET TreeLodOffscreen)
    return()
  endif()
  add_executable(${name} ${ARGN})
  target_link_libraries(${name} PRIVATE TreeLodOffscreen TreeLodBakeTechniques CLI11::CLI11
    nlohmann_json::nlohmann_json treelod_warnings)
  target_compile_definitions(${name} PRIVATE TREELOD_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/bench # StudySupport.h
    ${PROJECT_SOURCE_DIR}/plugin/scene/include)                         # RgbaImageConversion.h, via StudySupport.h
endfunction()
