# ccsrm_add_library(<module> SOURCES ... DEPS ...)
# Creates ccsrm_<module> with alias ccsrm::<module>, public headers in
# <module>/include, warnings on, C++17.
function(ccsrm_add_library module)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(ccsrm_${module} ${ARG_SOURCES})
  add_library(ccsrm::${module} ALIAS ccsrm_${module})
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

# ccsrm_add_test(<name> SOURCES ... DEPS ... [LABELS ...])
# One GoogleTest executable, registered through gtest_discover_tests.
# Tests find ../shared via CCSRM_SHARED_DIR and the source tree via
# CCSRM_SOURCE_DIR.
function(ccsrm_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  ccsrm_set_warnings(${name})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest_main GTest::gmock)
  target_compile_definitions(${name} PRIVATE
    CCSRM_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    CCSRM_SHARED_DIR="${PROJECT_SOURCE_DIR}/../shared"
    CCSRM_BINARY_DIR="${PROJECT_BINARY_DIR}")
  if(ARG_LABELS)
    gtest_discover_tests(${name} TEST_PREFIX "${name}." DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS "${ARG_LABELS}")
  else()
    gtest_discover_tests(${name} TEST_PREFIX "${name}." DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
