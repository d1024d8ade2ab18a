#include "ccsrm/common/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ccsrm/common/error.h"

namespace ccsrm {
namespace {
std::atomic<int> temp_counter{0};
}

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
  temp_path_ = target_path_ + ".tmp-" + std::to_string(::getpid()) + "-" +
               std::to_string(temp_counter.fetch_add(1));
}

AtomicOutputFile::~AtomicOutputFile() {
  if (!committed_) std::remove(temp_path_.c_str());
}

void AtomicOutputFile::Commit() {
  if (std::rename(temp_path_.c_str(), target_path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp_path_.c_str());
    ThrowInputError(target_path_, "", "cannot rename temporary output into place: " + reason);
  }
  committed_ = true;
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
  std::ifstream stream(path, std::ios::binary);
  if (!stream) ThrowInputError(path, "", "cannot open for reading");
  std::ostringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

}  // namespace ccsrm
