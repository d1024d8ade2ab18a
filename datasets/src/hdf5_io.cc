#include "hdf5_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>

#include "ccsrm/common/error.h"

namespace ccsrm::datasets::internal {
namespace {

// Larger datasets are refused on read rather than allocated: 2^30 doubles
// (8 GiB) is far beyond any run or experiment and protects against a damaged
// or hostile header claiming astronomic extents.
constexpr std::size_t kMaxReadValues = std::size_t{1} << 30;
// Target chunk size of compressed datasets, in values (256 KiB of doubles).
constexpr std::size_t kChunkValues = 32768;
constexpr unsigned kGzipLevel = 4;
// Growth step of the in-memory file image.
constexpr std::size_t kCoreIncrementBytes = std::size_t{1} << 20;

// HDF5 rejects a null buffer even for an empty selection; empty arrays point
// here instead.
double empty_buffer_dummy = 0.0;

std::recursive_mutex& Hdf5Mutex() {
  static std::recursive_mutex mutex;
  return mutex;
}

std::string WithHdf5Detail(const std::string& what) {
  const std::string detail = TakeHdf5ErrorMessage();
  return detail.empty() ? what : what + " (HDF5: " + detail + ")";
}

const char* TypeClassName(H5T_class_t type_class) {
  switch (type_class) {
    case H5T_INTEGER:
      return "integer";
    case H5T_FLOAT:
      return "floating-point";
    case H5T_STRING:
      return "string";
    case H5T_COMPOUND:
      return "compound";
    case H5T_ENUM:
      return "enum";
    case H5T_ARRAY:
      return "array";
    case H5T_VLEN:
      return "variable-length sequence";
    default:
      return "non-numeric";
  }
}

Handle MakeUtf8StringType() {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!type.valid() || H5Tset_size(type.get(), H5T_VARIABLE) < 0 ||
      H5Tset_cset(type.get(), H5T_CSET_UTF8) < 0) {
    return Handle();
  }
  return type;
}

// Frees the strings HDF5 allocated while reading variable-length data.
void ReclaimVariableLength(hid_t mem_type, hid_t space, void* buffer) {
#if H5_VERSION_GE(1, 12, 0)
  H5Treclaim(mem_type, space, H5P_DEFAULT, buffer);
#else
  H5Dvlen_reclaim(mem_type, space, H5P_DEFAULT, buffer);
#endif
}

// Reads `count` strings of file type `file_type` through `read(mem_type,
// buffer)`, for variable-length strings (what this module and h5py write) and
// fixed-length ones (what MATLAB's h5writeatt writes). Returns false when
// HDF5 fails.
template <typename ReadFn>
bool ReadStringElements(hid_t file_type, hid_t space, std::size_t count, ReadFn read,
                        std::vector<std::string>* out) {
  const htri_t is_variable = H5Tis_variable_str(file_type);
  if (is_variable < 0) return false;
  Handle mem_type(H5Tcopy(H5T_C_S1), H5Tclose);
  if (!mem_type.valid()) return false;
  // Same character set as the file: HDF5 does not convert ASCII <-> UTF-8.
  const H5T_cset_t cset = H5Tget_cset(file_type);
  if (cset < 0 || H5Tset_cset(mem_type.get(), cset) < 0) return false;
  out->clear();
  if (is_variable > 0) {
    if (H5Tset_size(mem_type.get(), H5T_VARIABLE) < 0) return false;
    std::vector<char*> pointers(std::max<std::size_t>(count, 1), nullptr);
    if (read(mem_type.get(), static_cast<void*>(pointers.data())) < 0) return false;
    for (std::size_t i = 0; i < count; ++i) {
      out->emplace_back(pointers[i] != nullptr ? pointers[i] : "");
    }
    if (count > 0) ReclaimVariableLength(mem_type.get(), space, pointers.data());
    return true;
  }
  const std::size_t size = H5Tget_size(file_type);
  if (size == 0) return false;
  const H5T_str_t pad = H5Tget_strpad(file_type);
  if (H5Tset_size(mem_type.get(), size) < 0 || H5Tset_strpad(mem_type.get(), pad) < 0) {
    return false;
  }
  std::vector<char> buffer(std::max<std::size_t>(count, 1) * size, '\0');
  if (read(mem_type.get(), static_cast<void*>(buffer.data())) < 0) return false;
  for (std::size_t i = 0; i < count; ++i) {
    const char* begin = buffer.data() + i * size;
    std::string text(begin, strnlen(begin, size));
    if (pad == H5T_STR_SPACEPAD) {
      text.erase(text.find_last_not_of(' ') + 1);
    }
    out->push_back(std::move(text));
  }
  return true;
}

bool WriteStringAttributeOn(hid_t object, const std::string& name, const std::string& value) {
  Handle type = MakeUtf8StringType();
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  if (!type.valid() || !space.valid()) return false;
  Handle attribute(
      H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose);
  if (!attribute.valid()) return false;
  const char* text = value.c_str();
  return H5Awrite(attribute.get(), type.get(), &text) >= 0;
}

// Reads the scalar string attribute `name` of `object`. Returns false when it
// exists but cannot be read as one string; *problem then says why.
bool ReadStringAttributeOf(hid_t object, const std::string& name, std::string* value,
                           std::string* problem) {
  Handle attribute(H5Aopen(object, name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!attribute.valid()) {
    *problem = WithHdf5Detail("cannot open");
    return false;
  }
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  Handle space(H5Aget_space(attribute.get()), H5Sclose);
  if (!type.valid() || !space.valid()) {
    *problem = WithHdf5Detail("cannot read");
    return false;
  }
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_STRING) {
    *problem = std::string("expected a string, found ") + TypeClassName(type_class) + " values";
    return false;
  }
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  if (count != 1) {
    *problem = "expected one string, found " + std::to_string(count);
    return false;
  }
  std::vector<std::string> strings;
  auto read = [&](hid_t mem_type, void* buffer) {
    return H5Aread(attribute.get(), mem_type, buffer);
  };
  if (!ReadStringElements(type.get(), space.get(), 1, read, &strings)) {
    *problem = WithHdf5Detail("cannot read");
    return false;
  }
  *value = strings.front();
  return true;
}

// Splits "/a/b/c" into {"/a", "/a/b", "/a/b/c"}.
std::vector<std::string> PathPrefixes(const std::string& path) {
  std::vector<std::string> prefixes;
  for (std::size_t pos = path.find('/', 1); pos != std::string::npos;
       pos = path.find('/', pos + 1)) {
    prefixes.push_back(path.substr(0, pos));
  }
  prefixes.push_back(path);
  return prefixes;
}

}  // namespace

// --- Handle ------------------------------------------------------------------

Handle& Handle::operator=(Handle&& other) noexcept {
  if (this != &other) {
    Close();
    id_ = other.id_;
    closer_ = other.closer_;
    other.id_ = H5I_INVALID_HID;
  }
  return *this;
}

bool Handle::Close() {
  if (id_ < 0) return true;
  const herr_t status = closer_(id_);
  id_ = H5I_INVALID_HID;
  return status >= 0;
}

// --- Hdf5Session ---------------------------------------------------------------

Hdf5Session::Hdf5Session() : lock_(Hdf5Mutex()) {
  H5Eget_auto2(H5E_DEFAULT, &saved_func_, &saved_data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

Hdf5Session::~Hdf5Session() {
  H5Eclear2(H5E_DEFAULT);
  H5Eset_auto2(H5E_DEFAULT, saved_func_, saved_data_);
}

std::string TakeHdf5ErrorMessage() {
  std::string message;
  // Walking upward starts at the most specific record (deepest in the
  // library), which carries the concrete cause.
  auto visit = [](unsigned /*n*/, const H5E_error2_t* error, void* data) -> herr_t {
    auto* text = static_cast<std::string*>(data);
    if (text->empty() && error->desc != nullptr && error->desc[0] != '\0') *text = error->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, visit, &message);
  H5Eclear2(H5E_DEFAULT);
  return message;
}

// --- FileWriter ----------------------------------------------------------------

FileWriter::FileWriter(std::string temp_path, std::string label)
    : temp_path_(std::move(temp_path)), label_(std::move(label)) {
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid() || H5Pset_fclose_degree(access.get(), H5F_CLOSE_STRONG) < 0 ||
      H5Pset_fapl_core(access.get(), kCoreIncrementBytes, /*backing_store=*/0) < 0) {
    Fail("", WithHdf5Detail("cannot set up the HDF5 file access"));
  }
  file_ = Handle(H5Fcreate(temp_path_.c_str(), H5F_ACC_EXCL, H5P_DEFAULT, access.get()), H5Fclose);
  if (!file_.valid()) Fail("", WithHdf5Detail("cannot create the HDF5 file in memory"));
  lcpl_ = Handle(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  if (!lcpl_.valid() || H5Pset_create_intermediate_group(lcpl_.get(), 1) < 0 ||
      H5Pset_char_encoding(lcpl_.get(), H5T_CSET_UTF8) < 0) {
    Fail("", WithHdf5Detail("cannot set up HDF5 link creation"));
  }
}

void FileWriter::Fail(const std::string& where, const std::string& what) const {
  ThrowInputError(label_, where, what);
}

void FileWriter::WriteArray(const std::string& path, const Array& array, const std::string& units) {
  CCSRM_CHECK(array.IsConsistent());
  std::vector<hsize_t> dims(array.shape.begin(), array.shape.end());
  Handle space =
      dims.empty()
          ? Handle(H5Screate(H5S_SCALAR), H5Sclose)
          : Handle(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle create(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (!space.valid() || !create.valid()) Fail(path, WithHdf5Detail("cannot describe dataset"));
  if (array.size() > kCompressAboveValues && !dims.empty()) {
    // Chunks of whole rows (frames), about kChunkValues values each, so a
    // reader slicing a time window decompresses little more than it needs.
    const std::size_t row_values = std::max<std::size_t>(array.size() / array.shape[0], 1);
    std::vector<hsize_t> chunk = dims;
    chunk[0] = std::clamp<std::size_t>(kChunkValues / row_values, 1, array.shape[0]);
    if (H5Pset_chunk(create.get(), static_cast<int>(chunk.size()), chunk.data()) < 0 ||
        H5Pset_shuffle(create.get()) < 0 || H5Pset_deflate(create.get(), kGzipLevel) < 0) {
      Fail(path, WithHdf5Detail("cannot set up compression"));
    }
  }
  Handle dataset(H5Dcreate2(file_.get(), path.c_str(), H5T_IEEE_F64LE, space.get(), lcpl_.get(),
                            create.get(), H5P_DEFAULT),
                 H5Dclose);
  if (!dataset.valid()) Fail(path, WithHdf5Detail("cannot create dataset"));
  const double* data = array.values.empty() ? &empty_buffer_dummy : array.values.data();
  if (H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    Fail(path, WithHdf5Detail("cannot write data"));
  }
  if (!WriteStringAttributeOn(dataset.get(), "units", units)) {
    Fail(path, WithHdf5Detail("cannot write units attribute"));
  }
}

void FileWriter::WriteStrings(const std::string& path, const std::vector<std::string>& strings) {
  Handle type = MakeUtf8StringType();
  const hsize_t dims[1] = {strings.size()};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose);
  if (!type.valid() || !space.valid()) Fail(path, WithHdf5Detail("cannot describe dataset"));
  Handle dataset(H5Dcreate2(file_.get(), path.c_str(), type.get(), space.get(), lcpl_.get(),
                            H5P_DEFAULT, H5P_DEFAULT),
                 H5Dclose);
  if (!dataset.valid()) Fail(path, WithHdf5Detail("cannot create dataset"));
  std::vector<const char*> pointers;
  for (const std::string& text : strings) pointers.push_back(text.c_str());
  const void* data = pointers.empty() ? static_cast<const void*>(&empty_buffer_dummy)
                                      : static_cast<const void*>(pointers.data());
  if (H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    Fail(path, WithHdf5Detail("cannot write strings"));
  }
  if (!WriteStringAttributeOn(dataset.get(), "units", "")) {
    Fail(path, WithHdf5Detail("cannot write units attribute"));
  }
}

void FileWriter::CreateGroup(const std::string& path) {
  Handle group(H5Gcreate2(file_.get(), path.c_str(), lcpl_.get(), H5P_DEFAULT, H5P_DEFAULT),
               H5Gclose);
  if (!group.valid()) Fail(path, WithHdf5Detail("cannot create group"));
}

void FileWriter::WriteStringAttribute(const std::string& name, const std::string& value) {
  if (!WriteStringAttributeOn(file_.get(), name, value)) {
    Fail("attribute '" + name + "'", WithHdf5Detail("cannot write"));
  }
}

void FileWriter::WriteDoubleAttribute(const std::string& name, double value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(space.valid() ? H5Acreate2(file_.get(), name.c_str(), H5T_IEEE_F64LE,
                                              space.get(), H5P_DEFAULT, H5P_DEFAULT)
                                 : H5I_INVALID_HID,
                   H5Aclose);
  if (!attribute.valid() || H5Awrite(attribute.get(), H5T_NATIVE_DOUBLE, &value) < 0) {
    Fail("attribute '" + name + "'", WithHdf5Detail("cannot write"));
  }
}

void FileWriter::WriteInt64Attribute(const std::string& name, std::int64_t value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(space.valid() ? H5Acreate2(file_.get(), name.c_str(), H5T_STD_I64LE, space.get(),
                                              H5P_DEFAULT, H5P_DEFAULT)
                                 : H5I_INVALID_HID,
                   H5Aclose);
  if (!attribute.valid() || H5Awrite(attribute.get(), H5T_NATIVE_INT64, &value) < 0) {
    Fail("attribute '" + name + "'", WithHdf5Detail("cannot write"));
  }
}

void FileWriter::Save() {
  const std::string& temp_path = temp_path_;
  lcpl_.Close();
  // After a global flush the in-memory image is byte-identical to the file
  // the sec2 driver leaves after H5Fclose -- for the default (HDF5 1.8
  // compatible, superblock v0) format used here. Raising the library version
  // bounds would break this: a v2+ superblock's status flags and checksum are
  // only finalised on close, and readers then reject the image.
  if (H5Fflush(file_.get(), H5F_SCOPE_GLOBAL) < 0) {
    Fail("", WithHdf5Detail("cannot finish the file"));
  }
  const ssize_t size = H5Fget_file_image(file_.get(), nullptr, 0);
  if (size <= 0) Fail("", WithHdf5Detail("cannot obtain the file image"));
  std::vector<char> image(static_cast<std::size_t>(size));
  if (H5Fget_file_image(file_.get(), image.data(), image.size()) != size) {
    Fail("", WithHdf5Detail("cannot obtain the file image"));
  }
  if (!file_.Close()) Fail("", WithHdf5Detail("cannot close the in-memory file"));

  const int fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    Fail("", "cannot create temporary file '" + temp_path + "': " + std::strerror(errno));
  }
  std::size_t written = 0;
  while (written < image.size()) {
    const ssize_t n = ::write(fd, image.data() + written, image.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string reason = n < 0 ? std::strerror(errno) : "no progress";
      ::close(fd);
      Fail("", "cannot write temporary file '" + temp_path + "' (" + std::to_string(written) +
                   " of " + std::to_string(image.size()) + " bytes written): " + reason);
    }
    written += static_cast<std::size_t>(n);
  }
  // The rename that follows must publish complete data, also after a crash.
  if (::fsync(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::close(fd);
    Fail("", "cannot flush temporary file '" + temp_path + "': " + reason);
  }
  if (::close(fd) != 0) {
    Fail("", "cannot close temporary file '" + temp_path + "': " + std::strerror(errno));
  }
}

// --- FileReader ----------------------------------------------------------------

FileReader::FileReader(const std::string& path) : label_(path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) Fail("", "cannot open: no such file");
  if (fs::is_directory(status)) Fail("", "is a directory, expected an HDF5 file");
  const htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
  if (is_hdf5 == 0) Fail("", "not an HDF5 file (no HDF5 signature found)");
  if (is_hdf5 < 0) Fail("", WithHdf5Detail("cannot open"));
  Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!access.valid() || H5Pset_fclose_degree(access.get(), H5F_CLOSE_STRONG) < 0) {
    Fail("", WithHdf5Detail("cannot set up the HDF5 file access"));
  }
  file_ = Handle(H5Fopen(path.c_str(), H5F_ACC_RDONLY, access.get()), H5Fclose);
  if (!file_.valid()) Fail("", WithHdf5Detail("not an HDF5 file or truncated"));
  root_ = Handle(H5Gopen2(file_.get(), "/", H5P_DEFAULT), H5Gclose);
  if (!root_.valid()) Fail("/", WithHdf5Detail("cannot open the root group"));
}

void FileReader::Fail(const std::string& where, const std::string& what) const {
  ThrowInputError(label_, where, what);
}

bool FileReader::Exists(const std::string& path) const {
  CCSRM_CHECK(!path.empty() && path[0] == '/');
  for (const std::string& prefix : PathPrefixes(path)) {
    const htri_t link = H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT);
    if (link < 0) Fail(prefix, WithHdf5Detail("cannot look up"));
    if (link == 0) return false;
    // A dangling soft or external link is "missing" too.
    const htri_t object = H5Oexists_by_name(file_.get(), prefix.c_str(), H5P_DEFAULT);
    if (object <= 0) {
      TakeHdf5ErrorMessage();
      return false;
    }
  }
  return true;
}

Handle FileReader::OpenObject(const std::string& path, H5I_type_t expected) const {
  if (!Exists(path)) Fail(path, "missing");
  Handle object(H5Oopen(file_.get(), path.c_str(), H5P_DEFAULT), H5Oclose);
  if (!object.valid()) Fail(path, WithHdf5Detail("cannot open"));
  const H5I_type_t type = H5Iget_type(object.get());
  if (type != expected) {
    const char* found = type == H5I_GROUP     ? "a group"
                        : type == H5I_DATASET ? "a dataset"
                                              : "a named datatype";
    Fail(path, std::string("expected ") + (expected == H5I_GROUP ? "a group" : "a dataset") +
                   ", found " + found);
  }
  return object;
}

std::string FileReader::ReadUnits(const Handle& dataset, const std::string& path) const {
  const htri_t exists = H5Aexists(dataset.get(), "units");
  if (exists < 0) Fail(path, WithHdf5Detail("cannot look up the units attribute"));
  if (exists == 0) Fail(path, "missing units attribute");
  std::string units;
  std::string problem;
  if (!ReadStringAttributeOf(dataset.get(), "units", &units, &problem)) {
    Fail(path, "units attribute: " + problem);
  }
  return units;
}

Array FileReader::ReadFloatData(const Handle& dataset, const std::string& path) const {
  Handle type(H5Dget_type(dataset.get()), H5Tclose);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  if (!type.valid() || !space.valid()) Fail(path, WithHdf5Detail("cannot read the header"));
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_FLOAT) {
    Fail(path, std::string("expected floating-point values, found ") + TypeClassName(type_class) +
                   " values");
  }
  const H5S_class_t space_class = H5Sget_simple_extent_type(space.get());
  if (space_class == H5S_NULL) Fail(path, "holds no data (null dataspace)");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (space_class == H5S_NO_CLASS || rank < 0) Fail(path, WithHdf5Detail("cannot read the shape"));
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0) {
    Fail(path, WithHdf5Detail("cannot read the shape"));
  }
  Array array;
  std::size_t count = 1;
  for (hsize_t extent : dims) {
    if (extent != 0 && count > kMaxReadValues / extent) {
      Fail(path, "implausibly large dataset (more than 2^30 values)");
    }
    count *= static_cast<std::size_t>(extent);
    array.shape.push_back(static_cast<std::size_t>(extent));
  }
  array.values.resize(count);
  double* data = array.values.empty() ? &empty_buffer_dummy : array.values.data();
  if (H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    Fail(path, WithHdf5Detail("cannot read data (file truncated or damaged?)"));
  }
  return array;
}

Array FileReader::ReadArray(const std::string& path, const std::string& units) const {
  Handle dataset = OpenObject(path, H5I_DATASET);
  const std::string found = ReadUnits(dataset, path);
  if (found != units) {
    Fail(path, "units attribute is '" + found + "', expected '" + units + "'");
  }
  return ReadFloatData(dataset, path);
}

Array FileReader::ReadArrayWithUnits(const std::string& path, std::string* units) const {
  Handle dataset = OpenObject(path, H5I_DATASET);
  *units = ReadUnits(dataset, path);
  return ReadFloatData(dataset, path);
}

std::vector<std::string> FileReader::ReadStrings(const std::string& path) const {
  Handle dataset = OpenObject(path, H5I_DATASET);
  Handle type(H5Dget_type(dataset.get()), H5Tclose);
  Handle space(H5Dget_space(dataset.get()), H5Sclose);
  if (!type.valid() || !space.valid()) Fail(path, WithHdf5Detail("cannot read the header"));
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_STRING) {
    Fail(path, std::string("expected strings, found ") + TypeClassName(type_class) + " values");
  }
  const int rank = H5Sget_simple_extent_ndims(space.get());
  hsize_t count = 0;
  if (rank != 1 || H5Sget_simple_extent_dims(space.get(), &count, nullptr) < 0) {
    Fail(path, "expected a 1-d list of strings, found rank " + std::to_string(rank));
  }
  if (count > kMaxReadValues) Fail(path, "implausibly large list of strings");
  std::vector<std::string> strings;
  auto read = [&](hid_t mem_type, void* buffer) {
    return H5Dread(dataset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
  };
  if (!ReadStringElements(type.get(), space.get(), static_cast<std::size_t>(count), read,
                          &strings)) {
    Fail(path, WithHdf5Detail("cannot read strings"));
  }
  return strings;
}

std::vector<std::string> FileReader::ListGroup(const std::string& path) const {
  Handle group = OpenObject(path, H5I_GROUP);
  H5G_info_t info;
  if (H5Gget_info(group.get(), &info) < 0) Fail(path, WithHdf5Detail("cannot list members"));
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t size = H5Lget_name_by_idx(group.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i,
                                            nullptr, 0, H5P_DEFAULT);
    if (size < 0) Fail(path, WithHdf5Detail("cannot list members"));
    std::string name(static_cast<std::size_t>(size) + 1, '\0');
    if (H5Lget_name_by_idx(group.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(),
                           name.size(), H5P_DEFAULT) < 0) {
      Fail(path, WithHdf5Detail("cannot list members"));
    }
    name.resize(static_cast<std::size_t>(size));
    names.push_back(std::move(name));
  }
  return names;
}

bool FileReader::HasRootAttribute(const std::string& name) const {
  const htri_t exists = H5Aexists(root_.get(), name.c_str());
  if (exists < 0) Fail("attribute '" + name + "'", WithHdf5Detail("cannot look up"));
  return exists > 0;
}

Handle FileReader::OpenRootAttribute(const std::string& name) const {
  if (!HasRootAttribute(name)) Fail("attribute '" + name + "'", "missing");
  Handle attribute(H5Aopen(root_.get(), name.c_str(), H5P_DEFAULT), H5Aclose);
  if (!attribute.valid()) Fail("attribute '" + name + "'", WithHdf5Detail("cannot open"));
  return attribute;
}

std::string FileReader::ReadOptionalStringAttribute(const std::string& name) const {
  return HasRootAttribute(name) ? ReadStringAttribute(name) : std::string();
}

std::string FileReader::ReadStringAttribute(const std::string& name) const {
  if (!HasRootAttribute(name)) Fail("attribute '" + name + "'", "missing");
  std::string value;
  std::string problem;
  if (!ReadStringAttributeOf(root_.get(), name, &value, &problem)) {
    Fail("attribute '" + name + "'", problem);
  }
  return value;
}

void FileReader::ReadScalarAttribute(const std::string& name, H5T_class_t expected_class,
                                     hid_t memory_type, const char* what, void* value) const {
  Handle attribute = OpenRootAttribute(name);
  Handle type(H5Aget_type(attribute.get()), H5Tclose);
  Handle space(H5Aget_space(attribute.get()), H5Sclose);
  const std::string where = "attribute '" + name + "'";
  if (!type.valid() || !space.valid()) Fail(where, WithHdf5Detail("cannot read"));
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != expected_class) {
    Fail(where,
         std::string("expected ") + what + ", found " + TypeClassName(type_class) + " values");
  }
  if (H5Sget_simple_extent_npoints(space.get()) != 1)
    Fail(where, std::string("expected one value"));
  if (H5Aread(attribute.get(), memory_type, value) < 0) Fail(where, WithHdf5Detail("cannot read"));
}

double FileReader::ReadDoubleAttribute(const std::string& name) const {
  double value = 0.0;
  ReadScalarAttribute(name, H5T_FLOAT, H5T_NATIVE_DOUBLE, "a floating-point number", &value);
  return value;
}

std::int64_t FileReader::ReadInt64Attribute(const std::string& name) const {
  std::int64_t value = 0;
  ReadScalarAttribute(name, H5T_INTEGER, H5T_NATIVE_INT64, "an integer", &value);
  return value;
}

// --- Schema ------------------------------------------------------------------

void CheckSchema(const FileReader& reader, const std::string& expected) {
  const std::size_t slash = expected.find('/');
  CCSRM_CHECK(slash != std::string::npos);
  const std::string expected_kind = expected.substr(0, slash);
  if (!reader.HasRootAttribute("schema")) {
    reader.Fail("",
                "root attribute 'schema' missing: not a ccsrm file (expected " + expected + ")");
  }
  const std::string schema = reader.ReadStringAttribute("schema");
  if (schema == expected) return;
  const std::string kind = schema.substr(0, schema.find('/'));
  const std::string where = "attribute 'schema' is '" + schema + "'";
  if (kind == expected_kind) {
    reader.Fail(where, "unsupported version (this ccsrm reads " + expected + ")");
  }
  if (kind == "ccsrm-run" || kind == "ccsrm-dataset") {
    reader.Fail("", "is a " + kind + " file (attribute 'schema' is '" + schema + "'), expected " +
                        expected_kind);
  }
  reader.Fail(where, "not a " + expected_kind + " file (expected " + expected + ")");
}

}  // namespace ccsrm::datasets::internal
