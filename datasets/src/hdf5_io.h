#pragma once
// Private HDF5 plumbing of the datasets module: RAII identifiers, a writer and
// a validating reader that turn every HDF5 failure into a one-line InputError
// naming the file. Only datasets/src includes this header.
#include <hdf5.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "ccsrm/datasets/array.h"

namespace ccsrm::datasets::internal {

// Owns one HDF5 identifier and closes it with the matching H5?close function.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() { Close(); }
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) {
    other.id_ = H5I_INVALID_HID;
  }
  Handle& operator=(Handle&& other) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes now; returns false when the close itself failed (for a file this
  // is where buffered data is flushed, so writers must check it).
  bool Close();

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

// Held by every public entry point for the duration of the call: serialises
// this module's HDF5 use and turns off HDF5's automatic printing of its error
// stack on this thread (restoring the previous handler afterwards), so that
// failures surface only as InputError messages.
class Hdf5Session {
 public:
  Hdf5Session();
  ~Hdf5Session();
  Hdf5Session(const Hdf5Session&) = delete;
  Hdf5Session& operator=(const Hdf5Session&) = delete;

 private:
  std::unique_lock<std::recursive_mutex> lock_;
  H5E_auto2_t saved_func_ = nullptr;
  void* saved_data_ = nullptr;
};

// The most specific message on this thread's HDF5 error stack (e.g.
// "truncated file: eof = 2048, ..."), then clears the stack. "" when empty.
std::string TakeHdf5ErrorMessage();

// Builds one new HDF5 file in memory (HDF5's core driver) and then saves its
// image with plain POSIX I/O. Doubles are stored as IEEE 64-bit little-endian,
// strings as variable-length UTF-8; datasets above kCompressAboveValues
// values are chunked with shuffle + gzip level 4.
//
// Why in memory: HDF5 1.10 cannot recover from a failed write while it owns
// the file. After an I/O error (disk full, file size limit) H5Fclose fails and
// leaves a half-closed file behind, which crashes the process in HDF5's exit
// handler (h5py issue #914; fixed upstream only in HDF5 1.14, PRs #2291 and
// #2496). Here HDF5 never touches the disk, so an I/O failure is an ordinary
// write(2) error we report, and AtomicOutputFile removes the temporary.
class FileWriter {
 public:
  static constexpr std::size_t kCompressAboveValues = 10000;

  // The file is named `temp_path` (it must not exist yet: H5F_ACC_EXCL, and
  // O_EXCL when saved); `label` (the final target path) names the file in
  // error messages.
  FileWriter(std::string temp_path, std::string label);

  // A float64 dataset at `path` (intermediate groups are created) with a
  // `units` attribute.
  void WriteArray(const std::string& path, const Array& array, const std::string& units);
  // A 1-d dataset of variable-length UTF-8 strings with units "".
  void WriteStrings(const std::string& path, const std::vector<std::string>& strings);
  // An empty group (and its parents), e.g. a group with no members yet.
  void CreateGroup(const std::string& path);
  // Scalar attributes on the root group.
  void WriteStringAttribute(const std::string& name, const std::string& value);
  void WriteDoubleAttribute(const std::string& name, double value);
  void WriteInt64Attribute(const std::string& name, std::int64_t value);
  // Finishes the file and writes its bytes to the temporary path, then fsyncs
  // it. Throws InputError naming the target when anything fails (a partly
  // written temporary is the caller's to remove: AtomicOutputFile does).
  void Save();

 private:
  [[noreturn]] void Fail(const std::string& where, const std::string& what) const;
  std::string temp_path_;
  std::string label_;
  Handle file_;
  Handle lcpl_;  // link creation: intermediate groups, UTF-8 names
};

// Opens an HDF5 file read-only and reads from it with checks; every failure
// throws InputError "<file>: <path>: <problem>".
class FileReader {
 public:
  // Throws for a missing file, a file that is not HDF5, or one HDF5 cannot
  // open (truncated, damaged).
  explicit FileReader(const std::string& path);

  const std::string& file() const { return label_; }

  // Whether an object exists at the absolute `path` (every component is
  // checked, so a missing parent group is simply "no").
  bool Exists(const std::string& path) const;
  // The float64-convertible dataset at `path`: it must exist, hold floating-
  // point values and carry a `units` attribute equal to `units`.
  Array ReadArray(const std::string& path, const std::string& units) const;
  // As ReadArray, accepting any units and returning them in *units.
  Array ReadArrayWithUnits(const std::string& path, std::string* units) const;
  // A 1-d dataset of strings (variable- or fixed-length).
  std::vector<std::string> ReadStrings(const std::string& path) const;
  // Names of the members of the group at `path`, in name order.
  std::vector<std::string> ListGroup(const std::string& path) const;

  // Scalar attributes of the root group; a missing attribute throws.
  bool HasRootAttribute(const std::string& name) const;
  std::string ReadStringAttribute(const std::string& name) const;
  // The same, or "" when the file has no such attribute (one a format
  // gained later: files written before it have none).
  std::string ReadOptionalStringAttribute(const std::string& name) const;
  double ReadDoubleAttribute(const std::string& name) const;
  std::int64_t ReadInt64Attribute(const std::string& name) const;

  [[noreturn]] void Fail(const std::string& where, const std::string& what) const;

 private:
  Handle OpenObject(const std::string& path, H5I_type_t expected) const;
  Array ReadFloatData(const Handle& dataset, const std::string& path) const;
  std::string ReadUnits(const Handle& dataset, const std::string& path) const;
  Handle OpenRootAttribute(const std::string& name) const;
  // Reads a one-element root attribute of class `expected_class` into
  // `value` as `memory_type`; `what` names the expected kind in errors.
  void ReadScalarAttribute(const std::string& name, H5T_class_t expected_class, hid_t memory_type,
                           const char* what, void* value) const;

  std::string label_;
  Handle file_;
  Handle root_;
};

// Checks the root `schema` attribute against `expected` ("ccsrm-run/1"):
// the other kind, an unknown kind and another version each get their own
// message. Throws InputError.
void CheckSchema(const FileReader& reader, const std::string& expected);

}  // namespace ccsrm::datasets::internal
