#pragma once
// A design of a few seconds of runs for the MPI and resume tests: plans of
// 0.5 s moves of the loop sample's arm (case 4), mu_c and T_p free.
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"

namespace ccsrm::testing {

// Writes the move's protocol into `dir`; returns `design ... --plans` with
// the moves to amplitude_deg 4 and to -3 then 5 (a plan of two experiments),
// and one more to each of `more_amplitudes_deg`, ready for further options.
inline std::string SmallDesign(const std::filesystem::path& dir,
                               const std::string& more_amplitudes_deg = "") {
  const std::string protocol = (dir / "move.yaml").string();
  WriteTextFileAtomically(
      protocol,
      "schema: ccsrm-protocol/1\nparameters: {amplitude_deg: 2}\nsegments:\n  all:\n"
      "    - move: {to: {theta_x_deg: amplitude_deg}, duration_s: 0.5}\n");
  std::string args = "design --config " + std::string(CCSRM_SOURCE_DIR) +
                     "/datasets/samples/loop/arm.yaml --case 4 --free mu_c,T_p --plans " +
                     protocol + "@amplitude_deg=4 " + protocol + "@amplitude_deg=-3+" + protocol +
                     "@amplitude_deg=5";
  if (!more_amplitudes_deg.empty())
    args += " " + protocol + "@amplitude_deg=" + more_amplitudes_deg;
  return args + " ";
}

}  // namespace ccsrm::testing
