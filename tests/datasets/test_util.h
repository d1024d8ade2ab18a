#pragma once
// Shared fixtures of the datasets tests: small records with a distinct value
// in every element, and surgery on written files (through the HDF5 C API) to
// produce the damaged files the readers must reject.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "ccsrm/datasets/array.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/datasets/run_file.h"

namespace ccsrm::datasets::testing {

// An empty directory under the system temp dir, unique to `name`.
std::filesystem::path FreshDir(const std::string& name);
// Names of the entries of `dir` (to check that no temporary is left behind).
std::vector<std::string> DirectoryEntries(const std::filesystem::path& dir);

// An array of `shape` whose element i holds offset + 0.37 i (all distinct).
Array Ramp(std::vector<std::size_t> shape, double offset);

struct RunSizes {
  std::size_t frames = 7;
  std::size_t joints = 3;
  std::size_t links = 4;
  std::vector<std::size_t> elements = {5, 4};  // per cable; C = size()
  std::vector<std::size_t> holes = {3, 2};     // per cable
  std::size_t markers = 2;                     // 0: no /markers
};

// A consistent run with every attribute set to a non-default value.
RunFile MakeRunFile(const RunSizes& sizes = RunSizes());
// The default arm's sizes (J = L = 12, C = 6, 12 elements and 11 holes per
// cable) over 48 s at 100 Hz: large enough for compression.
RunFile MakePaperSizedRunFile();

// A consistent experiment: 9 input samples, 6 mocap frames, 3 cables, 4
// markers with some NaN (not seen), rigid bodies base and link1, one quality
// figure, both optional /measured datasets.
ExperimentFile MakeExperimentFile();

// True when the arrays have the same shape and bit-identical values (so NaN
// matches NaN and 0.0 does not match -0.0).
bool Identical(const Array& a, const Array& b);

// Runs `action` and returns the message of the InputError it throws, or
// "(no exception)" / "(other exception: ...)".
std::string InputErrorMessage(const std::function<void()>& action);

// --- File surgery -------------------------------------------------------------
// Each opens `file` read-write, changes one thing and closes it.
void DeleteObject(const std::string& file, const std::string& path);
// Replaces (or creates) the dataset at `path` with `array`, stored as
// float64 (or as int32 when store_as_integer) and, unless units is nullopt,
// with a units attribute.
void ReplaceDataset(const std::string& file, const std::string& path, const Array& array,
                    const std::optional<std::string>& units, bool store_as_integer = false);
void SetUnits(const std::string& file, const std::string& path,
              const std::optional<std::string>& units);
// Replaces a root attribute with a string; fixed_length writes it the way
// MATLAB's h5writeatt does (fixed-size, null-terminated ASCII).
void SetRootString(const std::string& file, const std::string& name, const std::string& value,
                   bool fixed_length = false);
void DeleteRootAttribute(const std::string& file, const std::string& name);

}  // namespace ccsrm::datasets::testing
