#pragma once
// One output policy for every command (docs/conventions.md, "Outputs"):
//  - an output path that is an input (the same file, a path inside an input
//    folder, or a folder output that holds an input) is refused: inputs are
//    never modified;
//  - an existing output that is not the command's own kind is refused: it is
//    the user's, not an earlier output of this command;
//  - the command's own kind (or an empty file or folder) is replaced whole
//    and atomically (AtomicOutputFile, AtomicOutputDirectory); a folder only
//    when everything in it is what ccsrm wrote there, unchanged (its
//    manifest, atomic_file.h), so a user's file inside is never deleted;
//  - temporaries are removed on SIGINT, SIGTERM and SIGHUP, and those a
//    killed run left beside a target are removed by the next run writing it.
#include <functional>
#include <string>
#include <vector>

namespace ccsrm {

// What a command writes at its output path.
struct OutputKind {
  // Names the kind in messages, e.g. "ccsrm run file (ccsrm-run/1)".
  std::string description;
  // A folder (written through AtomicOutputDirectory) or a file.
  bool folder = false;
  // True when the existing `path` is an earlier output of this kind, which
  // the command replaces. Null: only empty files and folders are replaced.
  std::function<bool(const std::string& path)> recognises;
  // A folder: top-level files the command writes in place before the folder
  // is committed (a stopped job's checkpoint and journal), which may sit
  // beside the manifest's files.
  std::vector<std::string> own_files = {};
  // The caller was asked to replace whatever is at the path (Python's
  // overwrite=True): only the input and parent-folder rules apply.
  bool replace_any_existing = false;
};

// A YAML file whose top level has the line `schema: <schema>` within its
// first 64 KiB (every YAML output of ccsrm carries one; a user's file of
// another kind does not): rigid bodies, camera files, generate's truth.
// `description` names the kind in messages ("ccsrm truth file").
OutputKind YamlFileOutput(const std::string& schema, const std::string& description);

// Checks the output `path`, given by `option` (e.g. "--out"), against the
// policy before the command does any work, and removes the temporaries a
// killed run left beside it. Throws InputError (one line naming the path and
// the option) when the path is an input or inside one, holds an input (a
// folder output), has no existing parent folder, is a file where a folder is
// written or the reverse, or exists, is not empty and is not `kind` (a
// folder: holds a file that is not on its manifest or changed since). Empty
// strings in `inputs` (options not given) are skipped.
void CheckOutputPath(const std::string& path, const std::string& option, const OutputKind& kind,
                     const std::vector<std::string>& inputs);

// True when `path` is `folder` or lies inside it (neither need exist;
// symbolic links are resolved where they exist).
bool IsSameOrInside(const std::string& path, const std::string& folder);

// Removes the temporaries "<target>.tmp-<pid>-<n>" beside `target` whose
// process no longer runs (a run killed by SIGKILL, or a crash). Returns how
// many it removed. A live run's temporaries are left alone.
int RemoveStaleTemporaries(const std::string& target);

// From the call on, SIGINT, SIGTERM and SIGHUP remove the temporaries of
// every AtomicOutputFile and AtomicOutputDirectory alive in the process,
// print one line on stderr, and end the process by that signal. Call once,
// first thing in main, before any thread starts: the signals are blocked in
// every thread and taken by one watcher thread, so the removal runs outside
// a signal handler.
void RemoveTemporariesOnInterrupt();

}  // namespace ccsrm
