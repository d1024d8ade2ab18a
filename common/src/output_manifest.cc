#include "output_manifest.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/digest.h"
#include "ccsrm/common/error.h"
#include "temporaries.h"

namespace ccsrm::internal {
namespace {

namespace fs = std::filesystem;

constexpr const char* kManifestSchema = "ccsrm-manifest/1";

struct FileEntry {
  std::uintmax_t size = 0;
  std::string digest;
};

// The digest of a file's bytes, or "" when it cannot be read.
std::string DigestOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  Fnv1aDigest digest;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) digest.Add(buffer, in.gcount());
  return in.bad() ? "" : digest.Hex();
}

// The manifest's lines "<digest> <size> <relative path>" by path; empty when
// the folder has none or it is not a manifest.
std::map<std::string, FileEntry> ReadManifest(const fs::path& folder) {
  std::map<std::string, FileEntry> entries;
  std::ifstream in(folder / kOutputManifestName);
  std::string line;
  if (!std::getline(in, line) || line != kManifestSchema) return entries;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    FileEntry entry;
    std::string path;
    if (!(fields >> entry.digest >> entry.size) || fields.get() != ' ') return {};
    std::getline(fields, path);
    if (path.empty()) return {};
    entries[path] = entry;
  }
  return entries;
}

bool IsOwnFile(const std::string& relative, const std::vector<std::string>& own_files) {
  for (const std::string& own : own_files) {
    if (relative == own || relative.rfind(own + kTemporaryInfix, 0) == 0) return true;
  }
  return false;
}

}  // namespace

void WriteOutputManifest(const std::string& folder) {
  std::vector<std::pair<std::string, std::string>> lines;  // relative path, line
  std::error_code ec;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file()) continue;
    const std::string relative = it->path().lexically_relative(folder).generic_string();
    if (relative == kOutputManifestName || relative.find('\n') != std::string::npos) continue;
    lines.emplace_back(
        relative, DigestOf(it->path()) + " " + std::to_string(it->file_size()) + " " + relative);
  }
  if (ec) ThrowInputError(folder, "", "cannot list the output folder: " + ec.message());
  std::sort(lines.begin(), lines.end());
  std::ofstream out(fs::path(folder) / kOutputManifestName, std::ios::binary);
  out << kManifestSchema << "\n";
  for (const auto& [relative, line] : lines) out << line << "\n";
  out.flush();
  if (!out) ThrowInputError(folder, "", std::string("cannot write ") + kOutputManifestName);
}

std::vector<std::string> ForeignEntries(const std::string& folder,
                                        const std::vector<std::string>& own_files) {
  const std::map<std::string, FileEntry> manifest = ReadManifest(folder);
  std::vector<std::string> foreign;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string relative = it->path().lexically_relative(folder).generic_string();
    if (relative == kOutputManifestName || IsOwnFile(relative, own_files)) continue;
    const fs::file_status status = it->symlink_status();
    if (fs::is_directory(status)) continue;
    const auto listed = manifest.find(relative);
    // A link or a device is never ccsrm's.
    if (!fs::is_regular_file(status) || listed == manifest.end() ||
        listed->second.size != it->file_size() || listed->second.digest != DigestOf(it->path())) {
      foreign.push_back(relative);
    }
  }
  if (ec) foreign.push_back("(an entry it cannot list: " + ec.message() + ")");
  std::sort(foreign.begin(), foreign.end());
  return foreign;
}

}  // namespace ccsrm::internal
