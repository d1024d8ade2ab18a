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

// Builds an output folder atomically: the writer fills temp_path(), a new
// folder beside the target ("<target>.tmp-<pid>-<n>"), then Commit() puts it
// in place of the target in one step. If Commit() is never called the
// destructor removes the temporary folder, so the target is either untouched
// or complete, never half overwritten.
//
// Commit() first writes the folder's manifest, kOutputManifestName: every
// file in it with its size and content digest, so that the output policy
// (output_policy.h) can tell an earlier output from a folder a user has put
// files in since.
//
// An existing target folder is replaced as a whole: Commit() swaps the two
// folders with renameat2(RENAME_EXCHANGE) and then removes the old one. The
// caller decides whether an existing folder may be replaced (e.g. only an
// earlier output of the same command).
inline constexpr const char* kOutputManifestName = "ccsrm-manifest.txt";

class AtomicOutputDirectory {
 public:
  // Creates the temporary folder. Throws InputError when the target's parent
  // folder does not exist, when the target exists and is not a folder, or when
  // the temporary folder cannot be created.
  explicit AtomicOutputDirectory(std::string target_path);
  ~AtomicOutputDirectory();
  AtomicOutputDirectory(const AtomicOutputDirectory&) = delete;
  AtomicOutputDirectory& operator=(const AtomicOutputDirectory&) = delete;

  const std::string& temp_path() const { return temp_path_; }
  const std::string& target_path() const { return target_path_; }

  // Moves the temporary folder onto the target (replacing an existing target
  // folder, whose old content is then removed). Throws InputError on failure;
  // the target is then left as it was.
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
