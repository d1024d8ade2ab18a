#pragma once
// Runs the ccsrm program as a user would, for the end-to-end tests of the
// command line: exit status, standard output and standard error apart.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"

#ifndef CCSRM_PROGRAM
#define CCSRM_PROGRAM CCSRM_BINARY_DIR "/app/ccsrm"
#endif

namespace ccsrm::testing {

struct CommandOutcome {
  int status = -1;  // exit status; -1 when the program did not exit normally
  std::string out;  // standard output
  std::string err;  // standard error
  std::string all() const { return out + err; }
};

// A whole command line through the shell (e.g. ccsrm under mpirun).
inline CommandOutcome RunCommand(const std::string& command_line) {
  // Per-call file for stderr: test executables run in parallel under CTest.
  std::string err_path =
      (std::filesystem::temp_directory_path() / "ccsrm_test_stderr_XXXXXX").string();
  const int fd = mkstemp(err_path.data());
  if (fd >= 0) close(fd);
  const std::string command = command_line + " 2>" + err_path;
  CommandOutcome outcome;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return outcome;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) outcome.out += buffer.data();
  const int raw = pclose(pipe);
  outcome.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  outcome.err = ReadTextFile(err_path);
  std::filesystem::remove(err_path);
  return outcome;
}

// `ccsrm <args>` through the shell (args are not quoted).
inline CommandOutcome RunCcsrm(const std::string& args) {
  return RunCommand(std::string(CCSRM_PROGRAM) + " " + args);
}

// An empty scratch directory <tmp>/ccsrm_<name> (whatever was there is removed).
inline std::filesystem::path ScratchDirectory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("ccsrm_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Lines of a program's output (a one-line error is "...\n": 1).
inline int CountLines(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

}  // namespace ccsrm::testing
