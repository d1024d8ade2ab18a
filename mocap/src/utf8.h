#pragma once
// Private: marker labels as valid UTF-8.
//
// C3D predates Unicode and vendors' text exports use the Windows code page,
// so labels may hold bytes that are not UTF-8 (a Latin-1 "é" is the single
// byte 0xE9). Every reader passes its labels through AsUtf8 so that the rest
// of ccsrm (JSON summaries, HDF5 attributes, configuration look-ups) only
// ever sees valid UTF-8.
#include <string>

namespace ccsrm::mocap::internal {

// Returns `text` unchanged when it is valid UTF-8; otherwise every byte that
// does not start a well-formed UTF-8 sequence is read as Latin-1 (byte b →
// U+00b), which is right for the Latin-1 / Windows-1252 labels seen in
// practice and never fails.
std::string AsUtf8(const std::string& text);

// `text` fit for a one-line message: AsUtf8, with every control byte
// (newline, tab, NUL, DEL: what a damaged file holds in a name) written as
// \xNN.
std::string Printable(const std::string& text);

}  // namespace ccsrm::mocap::internal
