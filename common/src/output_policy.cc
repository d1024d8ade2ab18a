#include "ccsrm/common/output_policy.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

#include "ccsrm/common/error.h"
#include "output_manifest.h"
#include "temporaries.h"

namespace ccsrm {
namespace internal {
namespace {
std::mutex& RegistryMutex() {
  static std::mutex mutex;
  return mutex;
}
std::set<std::string>& Registry() {
  static std::set<std::string> paths;
  return paths;
}
}  // namespace

void RegisterTemporary(const std::string& path) {
  const std::lock_guard<std::mutex> lock(RegistryMutex());
  Registry().insert(path);
}

void UnregisterTemporary(const std::string& path) {
  const std::lock_guard<std::mutex> lock(RegistryMutex());
  Registry().erase(path);
}

std::vector<std::string> RegisteredTemporaries() {
  const std::lock_guard<std::mutex> lock(RegistryMutex());
  return {Registry().begin(), Registry().end()};
}
}  // namespace internal

namespace {
namespace fs = std::filesystem;

// A line "schema: X" (or "schema: \"X\"", as OpenCV writes it) at the top
// level of a YAML file, within its first 64 KiB.
bool YamlHasSchema(const std::string& path, const std::string& schema) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t read = 0;
  while (read < 65536 && std::getline(in, line)) {
    read += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "schema: " + schema || line == "schema: \"" + schema + "\"") return true;
  }
  return false;
}

// "report/" and "report" name the same path.
fs::path Normalised(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p;
}

bool IsEmpty(const std::string& path) {
  std::error_code ec;
  return fs::is_empty(path, ec) && !ec;
}

[[noreturn]] void Refuse(const std::string& path, const std::string& option,
                         const std::string& what) {
  ThrowInputError(path, option, what);
}

// The pid in "<leaf>.tmp-<pid>-<n>[-old]", or 0 when `name` is not one.
pid_t TemporaryPid(const std::string& name, const std::string& leaf) {
  const std::string prefix = leaf + internal::kTemporaryInfix;
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  const char* digits = name.c_str() + prefix.size();
  char* end = nullptr;
  errno = 0;
  const long pid = std::strtol(digits, &end, 10);
  if (errno != 0 || end == digits || *end != '-' || pid <= 0) return 0;
  return static_cast<pid_t>(pid);
}

}  // namespace

bool IsSameOrInside(const std::string& path, const std::string& folder) {
  const fs::path p = Normalised(path);
  const fs::path f = Normalised(folder);
  auto pi = p.begin();
  for (auto fi = f.begin(); fi != f.end(); ++fi, ++pi) {
    if (pi == p.end() || *pi != *fi) return false;
  }
  return true;
}

int RemoveStaleTemporaries(const std::string& target) {
  const fs::path t = Normalised(target);
  const std::string leaf = t.filename().string();
  std::error_code ec;
  fs::directory_iterator it(t.parent_path(), ec);
  if (ec) return 0;
  int removed = 0;
  for (const fs::directory_entry& entry : it) {
    const pid_t pid = TemporaryPid(entry.path().filename().string(), leaf);
    if (pid == 0 || pid == ::getpid()) continue;
    // kill(pid, 0) fails with ESRCH once no process has that pid; EPERM
    // means some process has it (perhaps not ours): leave it.
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    if (fs::remove_all(entry.path(), ignored) > 0) ++removed;
  }
  return removed;
}

void CheckOutputPath(const std::string& path, const std::string& option, const OutputKind& kind,
                     const std::vector<std::string>& inputs) {
  if (path.empty()) ThrowInputError(option, "", "is empty: give an output path");
  std::error_code ec;
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    if (Normalised(path) == Normalised(input) || fs::equivalent(path, input, ec)) {
      Refuse(path, option, "is an input file; inputs are never modified");
    }
    if (IsSameOrInside(path, input)) {
      Refuse(path, option,
             "lies inside the input folder '" + input + "'; inputs are never modified");
    }
    if (kind.folder && IsSameOrInside(input, path)) {
      Refuse(path, option,
             "holds the input '" + input +
                 "', which replacing the folder would delete; inputs are never modified");
    }
  }
  fs::path target(path);
  if (!target.has_filename() && target.has_parent_path()) target = target.parent_path();
  const fs::path parent = target.parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    Refuse(path, option, "output folder '" + parent.string() + "' does not exist");
  }
  RemoveStaleTemporaries(path);
  if (!fs::exists(fs::symlink_status(target, ec))) return;
  const bool is_folder = fs::is_directory(target, ec);
  if (kind.folder && !is_folder) Refuse(path, option, "exists and is not a folder");
  if (!kind.folder && is_folder) Refuse(path, option, "is a folder, expected a file");
  if (IsEmpty(path) || kind.replace_any_existing) return;
  if (!kind.recognises || !kind.recognises(path)) {
    Refuse(path, option,
           "exists and is not a " + kind.description + "; refusing to replace it: choose a new " +
               (kind.folder ? "folder" : "file") + " or remove it");
  }
  if (!kind.folder) return;
  // A folder of the kind is replaced only when nothing in it is the user's.
  const std::vector<std::string> foreign = internal::ForeignEntries(path, kind.own_files);
  if (foreign.empty()) return;
  std::string names;
  for (std::size_t i = 0; i < foreign.size() && i < 3; ++i) {
    names += (i > 0 ? ", '" : "'") + foreign[i] + "'";
  }
  if (foreign.size() > 3) names += " and " + std::to_string(foreign.size() - 3) + " more";
  Refuse(path, option,
         "holds " + names +
             ", which ccsrm did not write there (or which changed since); refusing to replace "
             "the folder: move " +
             (foreign.size() == 1 ? "it" : "them") + " out, or choose a new folder");
}

void RemoveTemporariesOnInterrupt() {
  static std::once_flag once;
  std::call_once(once, [] {
    sigset_t signals;
    sigemptyset(&signals);
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&signals, s);
    // Blocked here, so in every thread started from now on; only the
    // watcher takes them, with sigwait, outside any signal handler.
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    std::thread([signals] {
      int signal_number = 0;
      if (sigwait(&signals, &signal_number) != 0) return;
      int removed = 0;
      for (const std::string& temporary : internal::RegisteredTemporaries()) {
        std::error_code ignored;
        if (fs::remove_all(temporary, ignored) > 0) ++removed;
      }
      const std::string line = std::string("ccsrm: interrupted (") + ::strsignal(signal_number) +
                               "); removed " + std::to_string(removed) + " unfinished output" +
                               (removed == 1 ? "" : "s") + "\n";
      [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, line.data(), line.size());
      // End by the signal itself, so that a shell or scheduler sees it.
      ::signal(signal_number, SIG_DFL);
      pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);
      ::raise(signal_number);
      ::_exit(128 + signal_number);
    }).detach();
  });
}

OutputKind YamlFileOutput(const std::string& schema, const std::string& description) {
  return {description + " (" + schema + ")", false,
          [schema](const std::string& p) { return YamlHasSchema(p, schema); }};
}

}  // namespace ccsrm
