#pragma once
#include <string>

namespace ccsrm {

// Writes an output file atomically: the writer fills temp_path(), then
// Commit() renames it onto the target. If Commit() is never called (an
// exception, a divergence that aborts writing) the destructor removes the
// temporary, so the target path is either untouched or complete.
//
// The temporary sits in the target's directory (rename(2) is atomic only
// within one file system) and is named "<target>.tmp-<pid>-<n>".
class AtomicOutputFile {
 public:
  // Throws InputError when the target's directory does not exist.
  explicit AtomicOutputFile(std::string target_path);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  const std::string& temp_path() const { return temp_path_; }
  const std::string& target_path() const { return target_path_; }

  // Renames the temporary onto the target. Throws InputError on failure.
  void Commit();

 private:
  std::string target_path_;
  std::string temp_path_;
  bool committed_ = false;
};

// Writes text to path atomically (temporary file, then rename).
void WriteTextFileAtomically(const std::string& path, const std::string& text);

// Reads a whole text file; throws InputError naming the file if it cannot.
std::string ReadTextFile(const std::string& path);

}  // namespace ccsrm
