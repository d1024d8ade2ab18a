#pragma once
// The manifest an output folder carries (AtomicOutputDirectory writes it
// last, before the folder goes into place): every file ccsrm wrote there,
// with its size and content digest. The output policy (output_policy.h)
// replaces a folder only when everything in it is on its manifest and
// unchanged, so a file a user put in it, or a stub made to look like an
// earlier output, is never deleted. Private to common.
#include <string>
#include <vector>

namespace ccsrm::internal {

// Writes the manifest of every regular file under `folder` into it.
// Throws InputError (naming the folder) when it cannot.
void WriteOutputManifest(const std::string& folder);

// The entries under `folder` that are not ccsrm's (relative paths, e.g.
// "thesis.tex" or "plots/x.png"), sorted; empty when there is none. An
// entry is ccsrm's when it is the manifest, a folder, a regular file listed
// on the manifest with the same size and digest, or one of `own_files`
// (top-level names a job writes in place, e.g. its checkpoint) or their
// temporaries. Without a manifest, only `own_files` are ccsrm's.
std::vector<std::string> ForeignEntries(const std::string& folder,
                                        const std::vector<std::string>& own_files);

}  // namespace ccsrm::internal
