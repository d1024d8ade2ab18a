#pragma once
// Comparison of two experiments field by field, for the tests of the mocap
// pipeline: the library call against what `ccsrm mocap process` writes, and
// one route into an experiment against another.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>

#include "ccsrm/datasets/array.h"
#include "ccsrm/datasets/experiment_file.h"

namespace ccsrm::testing {

// Arrays of the same shape whose values differ by at most `tolerance`, NaN
// where the other is NaN. Returns false (and adds failures naming `what`)
// otherwise; at most one failure per array.
inline bool ExpectSameArray(const datasets::Array& a, const datasets::Array& b,
                            const std::string& what, double tolerance = 0.0) {
  EXPECT_EQ(a.shape, b.shape) << what;
  if (a.shape != b.shape || a.values.size() != b.values.size()) return false;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    const double x = a.values[i], y = b.values[i];
    const bool same = (std::isnan(x) && std::isnan(y)) || std::abs(x - y) <= tolerance;
    if (!same) {
      ADD_FAILURE() << what << "[" << i << "]: " << x << " vs " << y << " (tolerance " << tolerance
                    << ")";
      return false;
    }
  }
  return true;
}

inline void ExpectSameOptionalArray(const std::optional<datasets::Array>& a,
                                    const std::optional<datasets::Array>& b,
                                    const std::string& what, double tolerance = 0.0) {
  ASSERT_EQ(a.has_value(), b.has_value()) << what;
  if (a) ExpectSameArray(*a, *b, what, tolerance);
}

// Every field but `created` (stamped when written) equal, NaN equal to NaN.
inline void ExpectSameExperiment(const datasets::ExperimentFile& a,
                                 const datasets::ExperimentFile& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.config_yaml, b.config_yaml);
  ExpectSameArray(a.input_time, b.input_time, "/input/time");
  ExpectSameArray(a.input_length_change, b.input_length_change, "/input/length_change");
  ExpectSameArray(a.mocap_time, b.mocap_time, "/mocap/time");
  ExpectSameArray(a.mocap_markers, b.mocap_markers, "/mocap/markers");
  EXPECT_EQ(a.marker_names, b.marker_names);
  ASSERT_EQ(a.rigid_bodies.size(), b.rigid_bodies.size());
  for (std::size_t i = 0; i < a.rigid_bodies.size(); ++i) {
    EXPECT_EQ(a.rigid_bodies[i].name, b.rigid_bodies[i].name);
    EXPECT_EQ(a.rigid_bodies[i].marker_names, b.rigid_bodies[i].marker_names);
    ExpectSameArray(a.rigid_bodies[i].local_position, b.rigid_bodies[i].local_position,
                    "/mocap/rigid_bodies/" + a.rigid_bodies[i].name + "/local_position");
  }
  ASSERT_EQ(a.mocap_quality.size(), b.mocap_quality.size());
  for (const auto& [name, array] : a.mocap_quality) {
    ASSERT_EQ(b.mocap_quality.count(name), 1u) << name;
    ExpectSameArray(array, b.mocap_quality.at(name), "/mocap/quality/" + name);
  }
  EXPECT_EQ(a.mocap_quality_units, b.mocap_quality_units);
  ExpectSameOptionalArray(a.measured_joint_angles, b.measured_joint_angles,
                          "/measured/joint_angles");
  ExpectSameOptionalArray(a.measured_input_tension, b.measured_input_tension,
                          "/measured/input_tension");
  ExpectSameOptionalArray(a.measured_link_pose, b.measured_link_pose, "/measured/link_pose");
  ExpectSameOptionalArray(a.measured_joint_twist, b.measured_joint_twist, "/measured/joint_twist");
}

}  // namespace ccsrm::testing
