# ccsrm_add_library(<module> SOURCES ... DEPS ...)
# Creates ccsrm_<module> with alias ccsrm::<module>, public headers in
# <module>/include, warnings on, C++17.
function(ccsrm_add_library module)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(ccsrm_${module} ${ARG_SOURCES})
  add_library(ccsrm::${module} ALIAS ccsrm_${module})
  # Position-independent so the Python module (python/) can link them into
  # a shared object; costs nothing measurable on x86-64.
  set_target_properties(ccsrm_${module} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  target_include_directories(ccsrm_${module} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
  target_compile_features(ccsrm_${module} PUBLIC cxx_std_17)
  ccsrm_set_warnings(ccsrm_${module})
  target_link_libraries(ccsrm_${module} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

function(ccsrm_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic
    $<$<CXX_COMPILER_ID:GNU>:-Wshadow=local>
    -Wno-unused-parameter)
endfunction()

# ccsrm_add_test(<name> SOURCES ... DEPS ... [LABELS ...] [ONE_PROCESS])
# One GoogleTest executable, registered through gtest_discover_tests (one
# CTest entry per test). ONE_PROCESS registers the executable as a single
# CTest entry instead, for suites whose tests share expensive results.
# Tests find ../shared via CCSRM_SHARED_DIR and the source tree via
# CCSRM_SOURCE_DIR.
set(CCSRM_SHARED_DIR "${PROJECT_SOURCE_DIR}/../shared" CACHE PATH
  "The shared folder beside the repository (paper, real mocap files)")

function(ccsrm_add_test name)
  cmake_parse_arguments(ARG "ONE_PROCESS" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  ccsrm_set_warnings(${name})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest_main GTest::gmock)
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  target_compile_definitions(${name} PRIVATE
    CCSRM_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    CCSRM_SHARED_DIR="${CCSRM_SHARED_DIR}"
    CCSRM_BINARY_DIR="${PROJECT_BINARY_DIR}")
  # Scratch folders (std::filesystem::temp_directory_path) under the build
  # tree, so that two checkouts testing at once never share one.
  set(scratch "${PROJECT_BINARY_DIR}/test-tmp")
  file(MAKE_DIRECTORY "${scratch}")
  set(properties ENVIRONMENT "TMPDIR=${scratch}")
  if(ARG_LABELS)
    list(APPEND properties LABELS "${ARG_LABELS}")
  endif()
  if(ARG_ONE_PROCESS)
    add_test(NAME ${name} COMMAND ${name})
    set_tests_properties(${name} PROPERTIES ${properties})
  else()
    gtest_discover_tests(${name} TEST_PREFIX "${name}." DISCOVERY_TIMEOUT 60
      PROPERTIES ${properties})
  endif()
endfunction()
