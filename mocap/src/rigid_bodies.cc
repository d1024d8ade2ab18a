#include "ccsrm/mocap/rigid_bodies.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/mocap/processing.h"
#include "ccsrm/sim/kinematics.h"

namespace ccsrm::mocap {
namespace {

// A spread below this (m, the second singular value of the centred cluster)
// makes a cluster practically a line: its rotation about that line is lost
// in 0.1 mm of noise.
constexpr double kMinClusterSpreadM = 1e-3;

std::string BodyName(int link) { return link == 0 ? "base" : "link" + std::to_string(link); }

std::string Line(const YAML::Node& node) { return "line " + std::to_string(node.Mark().line + 1); }

[[noreturn]] void Fail(const std::string& file, const YAML::Node& node, const std::string& key,
                       const std::string& what) {
  ThrowInputError(file, Line(node) + ", key '" + key + "'", what);
}

void ExpectKeys(const std::string& file, const YAML::Node& map, const std::string& path,
                const std::set<std::string>& allowed) {
  for (const auto& entry : map) {
    const std::string key = entry.first.as<std::string>();
    if (allowed.count(key) == 0) {
      std::string list;
      for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
      Fail(file, entry.first, path.empty() ? key : path + "." + key,
           "unknown key (expected " + list + ")");
    }
  }
}

YAML::Node Require(const std::string& file, const YAML::Node& map, const std::string& path,
                   const std::string& key) {
  const YAML::Node node = map[key];
  if (!node) Fail(file, map, path.empty() ? key : path + "." + key, "missing");
  return node;
}

std::string ScalarString(const std::string& file, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) Fail(file, node, key, "expected a string");
  return node.as<std::string>();
}

double Number(const std::string& file, const YAML::Node& node, const std::string& key) {
  return ReadYamlNumber(node, file, Line(node) + ", key '" + key + "'");
}

// Second singular value of the centred cluster: ~0 for collinear markers.
double ClusterSpread(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(points.size(), 3);
  for (std::size_t i = 0; i < points.size(); ++i) centred.row(i) = (points[i] - mean).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred);
  return svd.singularValues().size() >= 2 ? svd.singularValues()(1) : 0.0;
}

void SortBodies(MarkerLayout* layout) {
  std::stable_sort(layout->bodies.begin(), layout->bodies.end(),
                   [](const RigidBody& a, const RigidBody& b) { return a.link < b.link; });
}

std::string FormatPosition(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.7f", value);
  return buffer;
}

}  // namespace

void ValidateMarkerLayout(const MarkerLayout& layout, const std::string& source) {
  if (layout.bodies.empty()) ThrowInputError(source, "bodies", "no rigid body given");
  std::set<int> links;
  std::map<std::string, std::string> marker_owner;
  for (const RigidBody& body : layout.bodies) {
    const std::string where = "body '" + body.name + "'";
    if (body.link < 0) ThrowInputError(source, where, "link number must be >= 0");
    if (body.name != BodyName(body.link)) {
      ThrowInputError(source, where,
                      "name must be '" + BodyName(body.link) + "' for link " +
                          std::to_string(body.link) + " ('base' is link 0, 'link<n>' link n)");
    }
    if (!links.insert(body.link).second) {
      ThrowInputError(source, where, "appears more than once");
    }
    if (body.marker_names.size() != body.p_BM.size()) {
      ThrowInputError(source, where, "marker names and positions differ in number");
    }
    if (body.marker_names.size() < 3) {
      ThrowInputError(
          source, where,
          "has " + std::to_string(body.marker_names.size()) + " markers; a pose needs at least 3");
    }
    for (std::size_t m = 0; m < body.marker_names.size(); ++m) {
      const std::string& name = body.marker_names[m];
      if (name.empty()) ThrowInputError(source, where, "a marker has an empty name");
      if (!body.p_BM[m].allFinite()) {
        ThrowInputError(source, where + ", marker '" + name + "'", "position is not finite");
      }
      const auto [it, fresh] = marker_owner.emplace(name, body.name);
      if (!fresh) {
        ThrowInputError(source, where + ", marker '" + name + "'",
                        "duplicate marker name (also on body '" + it->second + "')");
      }
    }
    if (ClusterSpread(body.p_BM) < kMinClusterSpreadM) {
      ThrowInputError(source, where,
                      "markers are (nearly) collinear: the body's rotation about their line "
                      "cannot be measured");
    }
  }
}

MarkerLayout ParseRigidBodies(const std::string& yaml_text, const std::string& file) {
  YAML::Node root = ParseYamlDocument(yaml_text, file);
  if (!root.IsMap()) ThrowInputError(file, "", "expected a mapping with 'schema' and 'bodies'");
  ExpectKeys(file, root, "", {"schema", "bodies"});
  const YAML::Node schema = Require(file, root, "", "schema");
  const std::string schema_text = ScalarString(file, schema, "schema");
  if (schema_text != kRigidBodiesSchema) {
    Fail(file, schema, "schema",
         "is '" + schema_text + "', expected '" + std::string(kRigidBodiesSchema) + "'");
  }
  const YAML::Node bodies = Require(file, root, "", "bodies");
  if (!bodies.IsSequence() || bodies.size() == 0) {
    Fail(file, bodies, "bodies", "expected a non-empty list of bodies");
  }
  MarkerLayout layout;
  std::map<std::string, std::string> seen_body;    // name -> line of first use
  std::map<int, std::string> seen_link;            // link -> line of first use
  std::map<std::string, std::string> seen_marker;  // name -> line of first use
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const YAML::Node node = bodies[b];
    const std::string path = "bodies[" + std::to_string(b) + "]";
    if (!node.IsMap()) Fail(file, node, path, "expected a mapping with name, link, markers");
    ExpectKeys(file, node, path, {"name", "link", "markers"});
    RigidBody body;
    const YAML::Node name = Require(file, node, path, "name");
    body.name = ScalarString(file, name, path + ".name");
    const YAML::Node link = Require(file, node, path, "link");
    const double link_number = Number(file, link, path + ".link");
    if (link_number < 0 || link_number != std::floor(link_number) || link_number > 1e6) {
      Fail(file, link, path + ".link", "expected a link number: 0 (ground), 1, 2, ...");
    }
    body.link = static_cast<int>(link_number);
    if (body.name != BodyName(body.link)) {
      Fail(file, name, path + ".name",
           "is '" + body.name + "', expected '" + BodyName(body.link) + "' for link " +
               std::to_string(body.link) + " ('base' is link 0, 'link<n>' link n)");
    }
    if (!seen_body.emplace(body.name, Line(name)).second) {
      Fail(file, name, path + ".name",
           "duplicate body '" + body.name + "' (first at " + seen_body[body.name] + ")");
    }
    if (!seen_link.emplace(body.link, Line(link)).second) {
      Fail(file, link, path + ".link",
           "link " + std::to_string(body.link) + " already has a body (at " + seen_link[body.link] +
               ")");
    }
    const YAML::Node markers = Require(file, node, path, "markers");
    if (!markers.IsSequence()) Fail(file, markers, path + ".markers", "expected a list of markers");
    if (markers.size() < 3) {
      Fail(file, markers, path + ".markers",
           "has " + std::to_string(markers.size()) + " markers; a pose needs at least 3");
    }
    for (std::size_t m = 0; m < markers.size(); ++m) {
      const YAML::Node marker = markers[m];
      const std::string mpath = path + ".markers[" + std::to_string(m) + "]";
      if (!marker.IsMap()) Fail(file, marker, mpath, "expected a mapping with name, position_m");
      ExpectKeys(file, marker, mpath, {"name", "position_m"});
      const YAML::Node mname = Require(file, marker, mpath, "name");
      const std::string marker_name = ScalarString(file, mname, mpath + ".name");
      if (marker_name.empty()) Fail(file, mname, mpath + ".name", "empty marker name");
      if (!seen_marker.emplace(marker_name, Line(mname)).second) {
        Fail(file, mname, mpath + ".name",
             "duplicate marker '" + marker_name + "' (first at " + seen_marker[marker_name] + ")");
      }
      const YAML::Node position = Require(file, marker, mpath, "position_m");
      if (!position.IsSequence() || position.size() != 3) {
        Fail(file, position, mpath + ".position_m", "expected [x, y, z] in metres");
      }
      Eigen::Vector3d p;
      for (int axis = 0; axis < 3; ++axis) {
        p[axis] = Number(file, position[axis], mpath + ".position_m");
      }
      body.marker_names.push_back(marker_name);
      body.p_BM.push_back(p);
    }
    if (ClusterSpread(body.p_BM) < kMinClusterSpreadM) {
      Fail(file, markers, path + ".markers",
           "markers are (nearly) collinear: the body's rotation about their line cannot be "
           "measured");
    }
    layout.bodies.push_back(std::move(body));
  }
  SortBodies(&layout);
  ValidateMarkerLayout(layout, file);  // the same rules, for layouts built in C++
  return layout;
}

MarkerLayout ReadRigidBodiesFile(const std::string& path) {
  return ParseRigidBodies(ReadTextFile(path), path);
}

std::string RigidBodiesToYaml(const MarkerLayout& layout) {
  std::ostringstream out;
  out << "# Marker clusters of the arm (mocap/README.md): positions in the body frame of\n"
         "# each link (SPEC 2: mass centre, z' along the link), in W for the ground.\n";
  out << "schema: " << kRigidBodiesSchema << "\n";
  out << "bodies:\n";
  for (const RigidBody& body : layout.bodies) {
    out << "  - name: " << body.name << "\n";
    out << "    link: " << body.link << "\n";
    out << "    markers:\n";
    for (std::size_t m = 0; m < body.marker_names.size(); ++m) {
      // Names are emitted as double-quoted YAML strings so any label survives.
      YAML::Emitter name;
      name << YAML::DoubleQuoted << body.marker_names[m];
      out << "      - {name: " << name.c_str() << ", position_m: ["
          << FormatPosition(body.p_BM[m].x()) << ", " << FormatPosition(body.p_BM[m].y()) << ", "
          << FormatPosition(body.p_BM[m].z()) << "]}\n";
    }
  }
  return out.str();
}

void WriteRigidBodiesFile(const std::string& path, const MarkerLayout& layout) {
  ValidateMarkerLayout(layout, path);
  WriteTextFileAtomically(path, RigidBodiesToYaml(layout));
}

std::vector<datasets::RigidBody> ToExperimentRigidBodies(const MarkerLayout& layout) {
  std::vector<datasets::RigidBody> records;
  for (const RigidBody& body : layout.bodies) {
    datasets::RigidBody record;
    record.name = body.name;
    record.marker_names = body.marker_names;
    record.local_position = datasets::Array({body.p_BM.size(), 3});
    for (std::size_t m = 0; m < body.p_BM.size(); ++m) {
      for (std::size_t axis = 0; axis < 3; ++axis) {
        record.local_position.at(m, axis) = body.p_BM[m][static_cast<int>(axis)];
      }
    }
    records.push_back(std::move(record));
  }
  return records;
}

MarkerLayout LayoutFromExperiment(const std::vector<datasets::RigidBody>& bodies,
                                  const std::string& file) {
  MarkerLayout layout;
  for (const datasets::RigidBody& record : bodies) {
    RigidBody body;
    body.name = record.name;
    if (record.name == "base") {
      body.link = 0;
    } else if (record.name.rfind("link", 0) == 0 && record.name.size() > 4) {
      body.link = std::atoi(record.name.c_str() + 4);
    } else {
      ThrowInputError(file, "/mocap/rigid_bodies/" + record.name,
                      "rigid body name must be 'base' or 'link<n>'");
    }
    body.marker_names = record.marker_names;
    for (std::size_t m = 0; m < record.marker_names.size(); ++m) {
      body.p_BM.emplace_back(record.local_position.at(m, 0), record.local_position.at(m, 1),
                             record.local_position.at(m, 2));
    }
    layout.bodies.push_back(std::move(body));
  }
  SortBodies(&layout);
  ValidateMarkerLayout(layout, file + ": /mocap/rigid_bodies");
  return layout;
}

StaticTrialRefinement RefineFromStaticTrial(const MarkerLayout& layout, const sim::ArmModel& model,
                                            const MarkerTable& trial, const std::string& source) {
  ValidateMarkerLayout(layout, source);
  const std::vector<std::string> names = layout.MarkerNames();
  std::vector<std::string> warnings;
  const std::vector<std::optional<std::size_t>> column = MatchMarkerLabels(names, trial, &warnings);
  if (std::none_of(column.begin(), column.end(), [](const auto& c) { return c.has_value(); })) {
    ThrowInputError(source, "", "no marker of the rigid bodies is in the static trial");
  }
  // Mean position of every marker over the frames where it was seen (file frame).
  std::vector<Eigen::Vector3d> mean_F(names.size(), Eigen::Vector3d::Constant(NAN));
  for (std::size_t k = 0; k < names.size(); ++k) {
    if (!column[k]) continue;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t count = 0;
    for (std::size_t f = 0; f < trial.frames(); ++f) {
      if (trial.is_valid(f, *column[k])) {
        sum += trial.position(f, *column[k]);
        ++count;
      }
    }
    if (count > 0) mean_F[k] = sum / static_cast<double>(count);
  }
  // World frame from the ground cluster, when it is there and seen.
  Eigen::Isometry3d X_WF = Eigen::Isometry3d::Identity();
  std::size_t k = 0;
  for (const RigidBody& body : layout.bodies) {
    if (body.link == 0) {
      std::vector<Eigen::Vector3d> from, to;
      for (std::size_t m = 0; m < body.p_BM.size(); ++m) {
        if (mean_F[k + m].allFinite()) {
          from.push_back(mean_F[k + m]);
          to.push_back(body.p_BM[m]);
        }
      }
      if (from.size() >= 3) {
        X_WF = FitRigidTransform(from, to);
      } else {
        warnings.push_back("ground markers seen fewer than 3: the file frame is taken as W");
      }
    }
    k += body.marker_names.size();
  }
  const std::vector<sim::LinkPose> straight =
      sim::ForwardKinematics(model, sim::JointAngles(model.num_joints(), Eigen::Vector2d::Zero()));
  StaticTrialRefinement result;
  result.layout = layout;
  k = 0;
  for (RigidBody& body : result.layout.bodies) {
    if (body.link > model.num_links()) {
      ThrowInputError(source, "body '" + body.name + "'",
                      "link " + std::to_string(body.link) + " is not in the arm (it has " +
                          std::to_string(model.num_links()) + " links)");
    }
    for (std::size_t m = 0; m < body.p_BM.size(); ++m, ++k) {
      if (!mean_F[k].allFinite()) {
        result.displacement_m.push_back(NAN);
        warnings.push_back("marker '" + names[k] + "' not seen in the static trial: kept nominal");
        continue;
      }
      if (body.link == 0) {  // the ground cluster defines W: it stays as given
        result.displacement_m.push_back((X_WF * mean_F[k] - body.p_BM[m]).norm());
        continue;
      }
      const sim::LinkPose& pose = straight[body.link - 1];
      const Eigen::Vector3d p_BM = pose.R_WB.transpose() * (X_WF * mean_F[k] - pose.p_WB);
      result.displacement_m.push_back((p_BM - body.p_BM[m]).norm());
      body.p_BM[m] = p_BM;
    }
  }
  result.warnings = std::move(warnings);
  ValidateMarkerLayout(result.layout, source);
  return result;
}

}  // namespace ccsrm::mocap
