#pragma once
// Declared values (issue 28): the values of an arm's configuration that a
// lab measures rather than knows exactly (a hole circle drilled small, a
// link a millimetre long, a pulley of another radius, a cable stiffer than
// its datasheet), as parameters a fit can move. Each is a relative
// correction of the configuration's value, "declared.<key>" with the value
// Δ / declared (0: as declared), held in ArmParameters::declared_deltas and
// read and written by name with GetParameter / SetParameter like every
// other parameter. Simulate builds the arm with the corrected values when
// any is not 0; with none given it runs the configuration's arm as before
// (nothing else changes).
//
// The names:
//   declared.joint_disk_gap                   d
//   declared.driving_cables.axial_stiffness   E·A of the driving cables
//   declared.driving_cables.input_offset      the input point's offset
//   declared.connecting_cables.axial_stiffness E_c·A_c
//   declared.segment<k>.hole_circle_radius    per segment k = 1..segments
//   declared.segment<k>.link_length
//   declared.segment<k>.link_mass
//   declared.segment<k>.link_inertia          the three moments together
//   declared.segment<k>.small_s_pulley_radius r_sc
//   declared.segment<k>.large_s_pulley_radius r_lc
//   declared.segment<k>.large_s_wrap_angle    Θ_lc
#include <string>
#include <vector>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/parameters.h"

namespace ccsrm::sim {

// Every declared-value parameter of an arm of `arm`'s size (per segment for
// arm.segments segments), arm-wide ones first, then segment by segment in
// the order above. Their `field` is null, `effect` empty, `declared` true;
// `realistic` is the relative error a careful lab's measurement may still
// have (the loop's score step).
std::vector<ParameterInfo> DeclaredValueParameters(const ArmSize& arm);

// The arm with every correction of `parameters` applied (value · (1 + Δ)).
// Throws InputError "declared values: ..." when the corrected arm is not a
// valid arm.
ArmConfig CorrectedArm(const ArmConfig& arm, const ArmParameters& parameters);

// True when some correction is not 0.
bool AnyDeclaredCorrection(const ArmParameters& parameters);

// The configuration value a declared-value parameter corrects, on `arm`,
// in SI units (the wrap angle in rad), and its configuration key
// ("arm.segments[1].link_length_m"). Throws InputError for a name that is
// not a declared value of `arm`.
double DeclaredValue(const ArmConfig& arm, const std::string& name);
std::string DeclaredValueKey(const std::string& name);

namespace internal {
// The entry of a declared-value name (on `arm` when given, any segment
// index otherwise), or null; *beyond says why for a segment the arm lacks.
const ParameterInfo* FindDeclaredParameter(const std::string& name, const ArmSize* arm,
                                           std::string* beyond);
}  // namespace internal

}  // namespace ccsrm::sim
