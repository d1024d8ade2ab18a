#include "ccsrm/datasets/experiment_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <string>
#include <utility>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/clock.h"
#include "ccsrm/common/error.h"
#include "describe.h"
#include "hdf5_io.h"
#include "validation.h"

namespace ccsrm::datasets {
namespace {

using internal::Bound;
using internal::ExpectShape;
using internal::Fixed;
using internal::Free;

constexpr const char* kRigidBodies = "/mocap/rigid_bodies";
constexpr const char* kQuality = "/mocap/quality";

std::string BodyPath(const RigidBody& body) { return std::string(kRigidBodies) + "/" + body.name; }

// Sort key of a valid rigid-body name: 0 for "base", n for "link<n>"; -1 for
// anything else. n has no leading zeros so that every link has one name.
long RigidBodyIndex(const std::string& name) {
  if (name == "base") return 0;
  const std::string prefix = "link";
  if (name.size() <= prefix.size() || name.size() > prefix.size() + 6 ||
      name.compare(0, prefix.size(), prefix) != 0 || name[prefix.size()] == '0') {
    return -1;
  }
  for (std::size_t i = prefix.size(); i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
  }
  return std::stol(name.substr(prefix.size()));
}

// The one list of ccsrm-dataset/1 float datasets with fixed units: path,
// units, array. /mocap/quality (free units) is handled beside it. `Experiment`
// is ExperimentFile or const ExperimentFile.
template <typename Experiment, typename Visit>
void VisitArrays(Experiment& experiment, Visit&& visit) {
  visit("/input/time", "s", experiment.input_time);
  visit("/input/length_change", "m", experiment.input_length_change);
  visit("/mocap/time", "s", experiment.mocap_time);
  visit("/mocap/markers", "m", experiment.mocap_markers);
  for (auto& body : experiment.rigid_bodies) {
    visit(BodyPath(body) + "/local_position", "m", body.local_position);
  }
  if (experiment.measured_joint_angles) {
    visit("/measured/joint_angles", "rad", *experiment.measured_joint_angles);
  }
  if (experiment.measured_input_tension) {
    visit("/measured/input_tension", "N", *experiment.measured_input_tension);
  }
  if (experiment.measured_link_pose) {
    visit("/measured/link_pose", "m, 1", *experiment.measured_link_pose);
  }
  if (experiment.measured_joint_twist) {
    visit("/measured/joint_twist", "rad", *experiment.measured_joint_twist);
  }
}

// The value of an optional root attribute naming one of an enum's values
// (`Name` gives each one's text), the first when it is absent.
template <typename Enum, typename Name>
Enum ReadOptionalEnumAttribute(const internal::FileReader& reader, const std::string& attribute,
                               std::initializer_list<Enum> values, Name name) {
  if (!reader.HasRootAttribute(attribute)) return *values.begin();
  const std::string text = reader.ReadStringAttribute(attribute);
  std::string expected;
  for (Enum value : values) {
    if (text == name(value)) return value;
    expected += std::string(expected.empty() ? "" : " or ") + "'" + name(value) + "'";
  }
  reader.Fail("attribute '" + attribute + "' is '" + text + "'", "expected " + expected);
}

ExperimentSource ParseSource(const internal::FileReader& reader, const std::string& text) {
  if (text == ExperimentSourceName(ExperimentSource::kRecorded)) return ExperimentSource::kRecorded;
  if (text == ExperimentSourceName(ExperimentSource::kGenerated)) {
    return ExperimentSource::kGenerated;
  }
  reader.Fail("attribute 'source' is '" + text + "'", "expected 'recorded' or 'generated'");
}

void ValidateRigidBodies(const ExperimentFile& experiment, const std::string& file) {
  const std::set<std::string> markers(experiment.marker_names.begin(),
                                      experiment.marker_names.end());
  std::set<std::string> bodies;
  for (const RigidBody& body : experiment.rigid_bodies) {
    const std::string path = BodyPath(body);
    if (RigidBodyIndex(body.name) < 0) {
      ThrowInputError(file, path, "rigid body name must be 'base' or 'link<n>' (n = 1, 2, ...)");
    }
    if (!bodies.insert(body.name).second) {
      ThrowInputError(file, path, "rigid body appears more than once");
    }
    internal::ExpectUniqueNames(file, path + "/marker_names", body.marker_names);
    for (const std::string& name : body.marker_names) {
      if (markers.count(name) == 0) {
        ThrowInputError(file, path + "/marker_names",
                        "marker '" + name + "' is not in /mocap/marker_names");
      }
    }
    ExpectShape(file, path + "/local_position", body.local_position,
                {Bound("k", body.marker_names.size(), path + "/marker_names"), Fixed(3)});
    internal::ExpectFinite(file, path + "/local_position", body.local_position);
  }
}

void ValidateQuality(const ExperimentFile& experiment, const std::string& file) {
  for (const auto& [name, array] : experiment.mocap_quality) {
    const std::string path = std::string(kQuality) + "/" + name;
    if (!internal::IsValidLinkName(name)) {
      ThrowInputError(file, path, "invalid name (must be non-empty, without '/')");
    }
    ExpectShape(file, path, array, std::vector<internal::Dim>(array.rank(), Free("n")));
    if (experiment.mocap_quality_units.count(name) == 0) {
      ThrowInputError(file, path, "no units given (mocap_quality_units has no entry)");
    }
  }
  for (const auto& entry : experiment.mocap_quality_units) {
    if (experiment.mocap_quality.count(entry.first) == 0) {
      ThrowInputError(file, std::string(kQuality) + "/" + entry.first,
                      "units given for a quality figure that does not exist");
    }
  }
}

void ExpectWithinCaptureVolume(const ExperimentFile& experiment, const std::string& file) {
  const std::string beyond =
      MarkerBeyondCaptureVolume(experiment.mocap_markers.values, experiment.marker_names);
  if (!beyond.empty()) ThrowInputError(file, "/mocap/markers", beyond);
}

}  // namespace

const char* ExperimentSourceName(ExperimentSource source) {
  return source == ExperimentSource::kRecorded ? "recorded" : "generated";
}

const char* RecordedMotionName(RecordedMotion motion) {
  return motion == RecordedMotion::kContinuous ? "continuous" : "settled_poses";
}

const char* MarkerFrameName(MarkerFrame frame) {
  return frame == MarkerFrame::kWorld ? "world" : "capture";
}

std::string MarkerBeyondCaptureVolume(const std::vector<double>& xyz,
                                      const std::vector<std::string>& names) {
  const std::size_t markers = names.size();
  for (std::size_t i = 0; i < xyz.size() && markers > 0; ++i) {
    if (!(std::abs(xyz[i]) > kCaptureVolumeLimitM) || std::isinf(xyz[i])) continue;
    const std::size_t sample = i / 3;
    char value[32];
    std::snprintf(value, sizeof(value), "%.6g", xyz[i]);
    return "marker '" + names[sample % markers] + "' at frame " + std::to_string(sample / markers) +
           " has a coordinate of " + value +
           " m, beyond any capture volume (|coordinate| <= 100 m)";
  }
  return "";
}

void ValidateExperimentFile(const ExperimentFile& experiment, const std::string& file) {
  const std::size_t samples =
      internal::ExpectTimeBase(file, "/input/time", experiment.input_time, "N");
  const internal::Dim n = Bound("N", samples, "/input/time");
  const auto lengths =
      ExpectShape(file, "/input/length_change", experiment.input_length_change, {n, Free("C")});
  const internal::Dim c = Bound("C", lengths[1], "/input/length_change");

  const std::size_t frames =
      internal::ExpectTimeBase(file, "/mocap/time", experiment.mocap_time, "F");
  const internal::Dim f = Bound("F", frames, "/mocap/time");
  const auto markers =
      ExpectShape(file, "/mocap/markers", experiment.mocap_markers, {f, Free("M"), Fixed(3)});
  if (experiment.marker_names.size() != markers[1]) {
    ThrowInputError(file, "/mocap/marker_names",
                    "expected M=" + std::to_string(markers[1]) +
                        " names (from /mocap/markers), found " +
                        std::to_string(experiment.marker_names.size()));
  }
  internal::ExpectUniqueNames(file, "/mocap/marker_names", experiment.marker_names);
  ExpectWithinCaptureVolume(experiment, file);
  if (!experiment.input_labels.empty() && experiment.input_labels.size() != samples) {
    ThrowInputError(file, "/input/labels",
                    "expected N=" + std::to_string(samples) + " labels (from /input/time), found " +
                        std::to_string(experiment.input_labels.size()));
  }
  if (const auto& a = experiment.clock_alignment) {
    if (a->method != "trigger" && a->method != "estimate" && a->method != "offset") {
      ThrowInputError(file, "clock_alignment",
                      "expected trigger, estimate or offset, found '" + a->method + "'");
    }
    const std::pair<const char*, double> numbers[] = {
        {"clock_offset_s", a->offset_s},
        {"clock_offset_uncertainty_s", a->offset_uncertainty_s},
        {"clock_drift_ppm", a->drift_ppm},
        {"clock_drift_uncertainty_ppm", a->drift_uncertainty_ppm}};
    for (const auto& [name, value] : numbers) {
      const bool is_uncertainty = std::string(name).find("uncertainty") != std::string::npos;
      if (!std::isfinite(value) || (is_uncertainty && value < 0.0)) {
        ThrowInputError(file, name,
                        std::string(is_uncertainty ? "expected a finite value >= 0"
                                                   : "expected a finite value") +
                            ", found " + std::to_string(value));
      }
    }
  }
  ValidateRigidBodies(experiment, file);
  ValidateQuality(experiment, file);

  if (experiment.measured_joint_angles) {
    ExpectShape(file, "/measured/joint_angles", *experiment.measured_joint_angles,
                {f, Free("J"), Fixed(2)});
  }
  if (experiment.measured_input_tension) {
    ExpectShape(file, "/measured/input_tension", *experiment.measured_input_tension, {n, c});
  }
  if (experiment.measured_link_pose) {
    ExpectShape(file, "/measured/link_pose", *experiment.measured_link_pose,
                {f, Free("L"), Fixed(7)});
  }
  if (experiment.measured_joint_twist) {
    const auto twist = ExpectShape(file, "/measured/joint_twist", *experiment.measured_joint_twist,
                                   {f, Free("J")});
    const auto& angles = experiment.measured_joint_angles;
    if (angles && angles->shape[1] != twist[1]) {
      // One of the two was cut or belongs to another arm. The link poses
      // written beside them (L = J: joint i joins link i-1 and link i) tell
      // which; without them the angles, what every consumer reads, are named.
      const auto& pose = experiment.measured_link_pose;
      if (pose && pose->shape[1] == angles->shape[1]) {
        ThrowInputError(file, "/measured/joint_twist",
                        "expected J=" + std::to_string(angles->shape[1]) +
                            " joints (from /measured/joint_angles and /measured/link_pose), "
                            "found " +
                            std::to_string(twist[1]));
      }
      std::string others = "/measured/joint_twist has " + std::to_string(twist[1]);
      if (pose)
        others += " and /measured/link_pose has " + std::to_string(pose->shape[1]) + " links";
      ThrowInputError(file, "/measured/joint_angles",
                      "has J=" + std::to_string(angles->shape[1]) + " joints, but " + others +
                          ": the measured records must cover the same joints");
    }
  }
}

void WriteExperimentFile(const std::string& path, const ExperimentFile& experiment) {
  ValidateExperimentFile(experiment, path);
  internal::Hdf5Session session;
  AtomicOutputFile output(path);
  {
    internal::FileWriter writer(output.temp_path(), path);
    writer.WriteStringAttribute("schema", kExperimentSchema);
    writer.WriteStringAttribute("name", experiment.name);
    writer.WriteStringAttribute("description", experiment.description);
    writer.WriteStringAttribute("source", ExperimentSourceName(experiment.source));
    writer.WriteStringAttribute("created",
                                experiment.created.empty() ? UtcTimestamp() : experiment.created);
    writer.WriteStringAttribute("config_yaml", experiment.config_yaml);
    if (!experiment.protocol_yaml.empty())
      writer.WriteStringAttribute("protocol_yaml", experiment.protocol_yaml);
    if (!experiment.inputs_file.empty())
      writer.WriteStringAttribute("inputs_file", experiment.inputs_file);
    if (experiment.motion != RecordedMotion::kContinuous) {
      writer.WriteStringAttribute("motion", RecordedMotionName(experiment.motion));
    }
    if (experiment.marker_frame != MarkerFrame::kWorld) {
      writer.WriteStringAttribute("marker_frame", MarkerFrameName(experiment.marker_frame));
    }
    if (const auto& a = experiment.clock_alignment) {
      writer.WriteStringAttribute("clock_alignment", a->method);
      writer.WriteStringAttribute("actuator_log", a->actuator_log);
      writer.WriteDoubleAttribute("clock_offset_s", a->offset_s);
      writer.WriteDoubleAttribute("clock_offset_uncertainty_s", a->offset_uncertainty_s);
      writer.WriteDoubleAttribute("clock_drift_ppm", a->drift_ppm);
      writer.WriteDoubleAttribute("clock_drift_uncertainty_ppm", a->drift_uncertainty_ppm);
      writer.WriteStringAttribute("clock_alignment_note", a->note);
    }
    // Created explicitly so that a file without rigid bodies still has it.
    writer.CreateGroup(kRigidBodies);
    VisitArrays(experiment, [&](const std::string& dataset, const char* units, const Array& array) {
      writer.WriteArray(dataset, array, units);
    });
    if (!experiment.input_labels.empty()) {
      writer.WriteStrings("/input/labels", experiment.input_labels);
    }
    writer.WriteStrings("/mocap/marker_names", experiment.marker_names);
    for (const RigidBody& body : experiment.rigid_bodies) {
      writer.WriteStrings(BodyPath(body) + "/marker_names", body.marker_names);
    }
    if (!experiment.mocap_quality.empty()) writer.CreateGroup(kQuality);
    for (const auto& [name, array] : experiment.mocap_quality) {
      writer.WriteArray(std::string(kQuality) + "/" + name, array,
                        experiment.mocap_quality_units.at(name));
    }
    writer.Save();
  }
  output.Commit();
}

ExperimentFile ReadExperimentFile(const std::string& path) {
  internal::Hdf5Session session;
  const internal::FileReader reader(path);
  internal::CheckSchema(reader, kExperimentSchema);

  ExperimentFile experiment;
  experiment.name = reader.ReadStringAttribute("name");
  experiment.description = reader.ReadStringAttribute("description");
  experiment.source = ParseSource(reader, reader.ReadStringAttribute("source"));
  experiment.created = reader.ReadStringAttribute("created");
  experiment.config_yaml = reader.ReadStringAttribute("config_yaml");
  // Files written before protocols were recorded have neither.
  experiment.protocol_yaml = reader.ReadOptionalStringAttribute("protocol_yaml");
  experiment.inputs_file = reader.ReadOptionalStringAttribute("inputs_file");
  experiment.motion = ReadOptionalEnumAttribute(
      reader, "motion", {RecordedMotion::kContinuous, RecordedMotion::kSettledPoses},
      RecordedMotionName);
  experiment.marker_frame = ReadOptionalEnumAttribute(
      reader, "marker_frame", {MarkerFrame::kWorld, MarkerFrame::kCapture}, MarkerFrameName);
  if (reader.HasRootAttribute("clock_alignment")) {
    ClockAlignment a;
    a.method = reader.ReadStringAttribute("clock_alignment");
    a.actuator_log = reader.ReadStringAttribute("actuator_log");
    a.offset_s = reader.ReadDoubleAttribute("clock_offset_s");
    a.offset_uncertainty_s = reader.ReadDoubleAttribute("clock_offset_uncertainty_s");
    a.drift_ppm = reader.ReadDoubleAttribute("clock_drift_ppm");
    a.drift_uncertainty_ppm = reader.ReadDoubleAttribute("clock_drift_uncertainty_ppm");
    a.note = reader.ReadStringAttribute("clock_alignment_note");
    experiment.clock_alignment = a;
  }

  // Skeleton first (rigid bodies, optional members), then every array.
  for (const std::string& name : reader.ListGroup(kRigidBodies)) {
    experiment.rigid_bodies.push_back(RigidBody{name, {}, {}});
  }
  if (reader.Exists("/measured/joint_angles")) experiment.measured_joint_angles.emplace();
  if (reader.Exists("/measured/input_tension")) experiment.measured_input_tension.emplace();
  if (reader.Exists("/measured/link_pose")) experiment.measured_link_pose.emplace();
  if (reader.Exists("/measured/joint_twist")) experiment.measured_joint_twist.emplace();
  VisitArrays(experiment, [&](const std::string& dataset, const char* units, Array& array) {
    array = reader.ReadArray(dataset, units);
  });
  if (reader.Exists("/input/labels")) {
    experiment.input_labels = reader.ReadStrings("/input/labels");
  }
  experiment.marker_names = reader.ReadStrings("/mocap/marker_names");
  for (RigidBody& body : experiment.rigid_bodies) {
    body.marker_names = reader.ReadStrings(BodyPath(body) + "/marker_names");
  }
  if (reader.Exists(kQuality)) {
    for (const std::string& name : reader.ListGroup(kQuality)) {
      std::string units;
      experiment.mocap_quality[name] =
          reader.ReadArrayWithUnits(std::string(kQuality) + "/" + name, &units);
      experiment.mocap_quality_units[name] = units;
    }
  }

  ValidateExperimentFile(experiment, path);
  std::stable_sort(experiment.rigid_bodies.begin(), experiment.rigid_bodies.end(),
                   [](const RigidBody& a, const RigidBody& b) {
                     return RigidBodyIndex(a.name) < RigidBodyIndex(b.name);
                   });
  return experiment;
}

namespace internal {
std::vector<DatasetSummary> DescribeDatasets(const ExperimentFile& experiment) {
  std::vector<DatasetSummary> datasets;
  VisitArrays(experiment, [&](const std::string& path, const char* units, const Array& array) {
    datasets.push_back({path, array.shape, units, "float64"});
  });
  if (!experiment.input_labels.empty()) {
    datasets.push_back({"/input/labels", {experiment.input_labels.size()}, "", "string"});
  }
  datasets.push_back({"/mocap/marker_names", {experiment.marker_names.size()}, "", "string"});
  for (const RigidBody& body : experiment.rigid_bodies) {
    datasets.push_back(
        {BodyPath(body) + "/marker_names", {body.marker_names.size()}, "", "string"});
  }
  for (const auto& [name, array] : experiment.mocap_quality) {
    datasets.push_back({std::string(kQuality) + "/" + name, array.shape,
                        experiment.mocap_quality_units.at(name), "float64"});
  }
  // Schema order: /input, then /mocap (time, markers, names, rigid bodies by
  // link number, quality), then /measured.
  auto key = [](const std::string& p) {
    const std::string bodies = std::string(kRigidBodies) + "/";
    long body = 0;
    int section = 6;
    if (p.rfind("/input/", 0) == 0) section = 0;
    if (p == "/mocap/time") section = 1;
    if (p == "/mocap/markers") section = 2;
    if (p == "/mocap/marker_names") section = 3;
    if (p.rfind(bodies, 0) == 0) {
      section = 4;
      body = RigidBodyIndex(p.substr(bodies.size(), p.rfind('/') - bodies.size()));
    }
    if (p.rfind(std::string(kQuality) + "/", 0) == 0) section = 5;
    return std::make_pair(section, body);
  };
  std::stable_sort(datasets.begin(), datasets.end(),
                   [&](const DatasetSummary& a, const DatasetSummary& b) {
                     const auto ka = key(a.path);
                     const auto kb = key(b.path);
                     if (ka != kb) return ka < kb;
                     // Within one rigid body: marker_names before local_position.
                     return ka.first == 4 && a.path > b.path;
                   });
  return datasets;
}
}  // namespace internal

}  // namespace ccsrm::datasets
