#include "ccsrm/common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ccsrm/common/error.h"
#include "output_manifest.h"
#include "temporaries.h"

namespace ccsrm {
namespace {
std::atomic<int> temp_counter{0};

// "<target>.tmp-<pid>-<n>": the pid lets a later run tell a killed run's
// leftovers (RemoveStaleTemporaries, output_policy.h) from a live run's.
std::string TemporaryName(const std::string& target) {
  return target + internal::kTemporaryInfix + std::to_string(::getpid()) + "-" +
         std::to_string(temp_counter.fetch_add(1));
}
}  // namespace

AtomicOutputFile::AtomicOutputFile(std::string target_path) : target_path_(std::move(target_path)) {
  if (target_path_.empty()) ThrowInputError("(output)", "", "empty output path");
  namespace fs = std::filesystem;
  const fs::path parent = fs::path(target_path_).parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) {
    ThrowInputError(target_path_, "", "output directory '" + parent.string() + "' does not exist");
  }
  if (fs::is_directory(target_path_)) {
    ThrowInputError(target_path_, "", "output path is a directory");
  }
  temp_path_ = TemporaryName(target_path_);
  internal::RegisterTemporary(temp_path_);
}

AtomicOutputFile::~AtomicOutputFile() {
  if (!committed_) std::remove(temp_path_.c_str());
  internal::UnregisterTemporary(temp_path_);
}

void AtomicOutputFile::Commit() {
  if (std::rename(temp_path_.c_str(), target_path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp_path_.c_str());
    ThrowInputError(target_path_, "", "cannot rename temporary output into place: " + reason);
  }
  committed_ = true;
  internal::UnregisterTemporary(temp_path_);
}

namespace {
// "report/" and "report" name the same folder; the temporary must sit beside
// it, not inside it.
std::string WithoutTrailingSeparator(const std::string& path) {
  std::filesystem::path p(path);
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p.string();
}
}  // namespace

AtomicOutputDirectory::AtomicOutputDirectory(std::string target_path)
    : target_path_(WithoutTrailingSeparator(target_path)) {
  namespace fs = std::filesystem;
  if (target_path_.empty()) ThrowInputError("(output)", "", "empty output path");
  const fs::path target(target_path_);
  const std::string leaf = target.filename().string();
  if (leaf.empty() || leaf == "." || leaf == "..") {
    ThrowInputError(target_path_, "", "output folder needs a name of its own (e.g. report/)");
  }
  const fs::path parent = target.parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) {
    ThrowInputError(target_path_, "", "output directory '" + parent.string() + "' does not exist");
  }
  std::error_code ec;
  if (fs::exists(target, ec) && !fs::is_directory(target, ec)) {
    ThrowInputError(target_path_, "", "exists and is not a folder");
  }
  temp_path_ = TemporaryName(target_path_);
  internal::RegisterTemporary(temp_path_);
  if (!fs::create_directory(temp_path_, ec) || ec) {
    ThrowInputError(target_path_, "",
                    "cannot create temporary folder '" + temp_path_ + "': " + ec.message());
  }
}

AtomicOutputDirectory::~AtomicOutputDirectory() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove_all(temp_path_, ignored);
  }
  internal::UnregisterTemporary(temp_path_);
}

void AtomicOutputDirectory::Commit() {
  namespace fs = std::filesystem;
  internal::WriteOutputManifest(temp_path_);
  std::error_code ec;
  if (!fs::exists(target_path_, ec)) {
    if (std::rename(temp_path_.c_str(), target_path_.c_str()) != 0) {
      ThrowInputError(
          target_path_, "",
          std::string("cannot rename temporary folder into place: ") + std::strerror(errno));
    }
    committed_ = true;
    internal::UnregisterTemporary(temp_path_);
    return;
  }
  // Swap the complete new folder with the old one in one step; the
  // temporary name then holds the old content, removed below.
  if (::renameat2(AT_FDCWD, temp_path_.c_str(), AT_FDCWD, target_path_.c_str(), RENAME_EXCHANGE) !=
      0) {
    if (errno != EINVAL && errno != ENOSYS) {
      ThrowInputError(target_path_, "",
                      std::string("cannot replace the existing folder: ") + std::strerror(errno));
    }
    // A file system without RENAME_EXCHANGE: move the old folder aside,
    // move the new one in, and put the old one back if that fails.
    // (Not registered for interrupts: for a moment it is the only copy.)
    const std::string aside = temp_path_ + "-old";
    if (std::rename(target_path_.c_str(), aside.c_str()) != 0) {
      ThrowInputError(
          target_path_, "",
          std::string("cannot move the existing folder aside: ") + std::strerror(errno));
    }
    if (std::rename(temp_path_.c_str(), target_path_.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      std::rename(aside.c_str(), target_path_.c_str());
      ThrowInputError(target_path_, "", "cannot rename temporary folder into place: " + reason);
    }
    committed_ = true;
    fs::remove_all(aside, ec);
    return;
  }
  // The temporary name now holds the old content: it stays registered (an
  // interrupt removes it just the same) until it is gone.
  committed_ = true;
  fs::remove_all(temp_path_, ec);
  internal::UnregisterTemporary(temp_path_);
}

void WriteTextFileAtomically(const std::string& path, const std::string& text) {
  AtomicOutputFile out(path);
  {
    std::ofstream stream(out.temp_path(), std::ios::binary);
    if (!stream) ThrowInputError(path, "", "cannot open for writing");
    stream << text;
    stream.flush();
    if (!stream) ThrowInputError(path, "", "write failed");
  }
  out.Commit();
}

std::string ReadTextFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    ThrowInputError(path, "", "is a folder, expected a file");
  }
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "", "cannot open for reading");
  std::ostringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

}  // namespace ccsrm
