# Finds every third-party package and fails early with the Debian package to
# install. scripts/install-deps.sh installs all of them.
macro(ccsrm_require found_var debian_package what)
  if(NOT ${found_var})
    message(FATAL_ERROR
      "ccsrm: ${what} not found. Install the Debian package '${debian_package}' "
      "(or run scripts/install-deps.sh as root).")
  endif()
endmacro()

find_package(Eigen3 3.4 QUIET NO_MODULE)
ccsrm_require(Eigen3_FOUND libeigen3-dev "Eigen 3.4")
find_package(GSL QUIET)
ccsrm_require(GSL_FOUND libgsl-dev "GSL")
find_package(HDF5 QUIET COMPONENTS C)
ccsrm_require(HDF5_FOUND libhdf5-dev "HDF5 (C API)")
find_package(yaml-cpp QUIET)
ccsrm_require(yaml-cpp_FOUND libyaml-cpp-dev "yaml-cpp")
find_package(CLI11 QUIET)
ccsrm_require(CLI11_FOUND libcli11-dev "CLI11")
find_package(nlohmann_json 3 QUIET)
ccsrm_require(nlohmann_json_FOUND nlohmann-json3-dev "nlohmann-json")
find_package(Ceres QUIET)
ccsrm_require(Ceres_FOUND libceres-dev "Ceres Solver")
find_package(OpenCV 4 QUIET COMPONENTS core imgproc calib3d videoio imgcodecs)
ccsrm_require(OpenCV_FOUND libopencv-dev "OpenCV 4")
find_package(Threads REQUIRED)

if(CCSRM_BUILD_TESTS)
  find_package(GTest QUIET)
  ccsrm_require(GTest_FOUND "libgtest-dev libgmock-dev" "GoogleTest")
endif()
if(CCSRM_BUILD_BENCHMARKS)
  find_package(benchmark QUIET)
  ccsrm_require(benchmark_FOUND libbenchmark-dev "Google Benchmark")
endif()

# HDF5's FindHDF5 gives variables on older CMake; wrap them in one target.
if(NOT TARGET ccsrm_hdf5)
  add_library(ccsrm_hdf5 INTERFACE)
  target_include_directories(ccsrm_hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
  target_link_libraries(ccsrm_hdf5 INTERFACE ${HDF5_C_LIBRARIES})
  target_compile_definitions(ccsrm_hdf5 INTERFACE ${HDF5_C_DEFINITIONS})
endif()

# SuiteSparse KLU (libsuitesparse-dev, which Ceres depends on) factorizes the
# simulator's sparse augmented system; Eigen's KLUSupport wraps it.
find_path(KLU_INCLUDE_DIR klu.h PATH_SUFFIXES suitesparse)
find_library(KLU_LIBRARY klu)
find_library(BTF_LIBRARY btf)
find_library(AMD_LIBRARY amd)
find_library(COLAMD_LIBRARY colamd)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
if(KLU_INCLUDE_DIR AND KLU_LIBRARY)
  set(KLU_FOUND TRUE)
endif()
ccsrm_require(KLU_FOUND libsuitesparse-dev "SuiteSparse KLU")
if(NOT TARGET ccsrm_klu)
  add_library(ccsrm_klu INTERFACE)
  target_include_directories(ccsrm_klu SYSTEM INTERFACE ${KLU_INCLUDE_DIR})
  target_link_libraries(ccsrm_klu INTERFACE ${KLU_LIBRARY} ${BTF_LIBRARY} ${AMD_LIBRARY}
    ${COLAMD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY})
endif()
