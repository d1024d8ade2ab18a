// Reading ccsrm-protocol/1 files (docs/protocols.md): the YAML forms of the
// pieces, parameters and limits, resolved to a Protocol bound to one arm
// and checked once, here.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/sim/protocol.h"
#include "protocol_internal.h"

namespace ccsrm::sim {
namespace {

constexpr const char* kProtocolSchema = "ccsrm-protocol/1";
constexpr double kPi = 3.14159265358979323846;
// The same factor as the configuration's (sim/src/config.cc), so that a
// protocol's 6° is the configuration's 6° to the bit.
constexpr double kDegToRad = kPi / 180.0;
// A rate change below this at a join is rounding, not a jump [rad/s]
// (a sine's rate at a whole number of cycles differs from its start by ~1e-15).
constexpr double kJoinRateTolerance = 1e-6;
constexpr int kMaxRepeat = 100000;
// Pieces of one segment once every repeat is expanded: a day of 1 s moves
// (86 400) fits; nested repeats of 1000 x 1000 x 1000 would take minutes and
// gigabytes to expand before a single check.
constexpr std::size_t kMaxPieces = 100000;
// Highest frequency of a sine or chirp [Hz]: the inputs are planned at 1 ms
// (PlanProtocolInputs), and 20 samples a period keep a sine a sine there, so
// that its cable speeds are checked; 50 Hz is also far above the modes of
// such arms (about 1 Hz). A 1 MHz sine sampled at 1 ms is all zeros.
constexpr double kMaxFrequencyHz = 50.0;

// The unit of a field or parameter name: the text after its last '_'
// ("duration_s" -> "s"); the factor to SI for the units protocols use.
std::string UnitOf(const std::string& name) {
  const std::size_t underscore = name.rfind('_');
  return underscore == std::string::npos ? "" : name.substr(underscore + 1);
}

double ToSi(const std::string& unit) { return unit == "deg" ? kDegToRad : 1.0; }

bool KnownUnit(const std::string& unit) { return unit == "deg" || unit == "s" || unit == "hz"; }

class ProtocolReader {
 public:
  ProtocolReader(const std::string& file, const ProtocolOptions& options)
      : file_(file), options_(options) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& key,
                         const std::string& what) const {
    ThrowInputError(file_, Where(node, key), what);
  }

  std::string Where(const YAML::Node& node, const std::string& key) const {
    const YAML::Mark mark = node.Mark();
    const std::string line = mark.is_null() ? "" : "line " + std::to_string(mark.line + 1);
    if (key.empty()) return line;
    return line.empty() ? "key '" + key + "'" : line + ", key '" + key + "'";
  }

  ProtocolSource SourceOf(const YAML::Node& node, const std::string& key) const {
    ProtocolSource s;
    s.line = node.Mark().is_null() ? 0 : node.Mark().line + 1;
    s.key = key;
    return s;
  }

  // Refuses keys of `node` (a mapping) outside `allowed`.
  void OnlyKeys(const YAML::Node& node, const std::string& key,
                const std::vector<std::string>& allowed) const {
    if (!node.IsMap()) Fail(node, key, "expected a mapping");
    for (const auto& entry : node) {
      const std::string name = entry.first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(entry.first, Join(key, name), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  static std::string Join(const std::string& key, const std::string& child) {
    return key.empty() ? child : key + "." + child;
  }

  // A number field named `field` (its unit is its suffix), in SI: a number
  // in the field's unit, or the name of one of the file's parameters of the
  // same unit.
  double Value(const YAML::Node& node, const std::string& key, const std::string& field) const {
    if (!node.IsScalar()) Fail(node, key, "expected a number");
    double value = 0.0;
    const std::string problem = ParseNumberText(node.Scalar(), &value);
    const std::string unit = UnitOf(field);
    if (problem.empty()) return value * ToSi(unit);
    if (problem != kNotANumber) Fail(node, key, "'" + node.Scalar() + "' " + problem);
    const auto it = parameters_.find(node.Scalar());
    if (it == parameters_.end()) {
      std::string names;
      for (const auto& [name, v] : parameters_) names += (names.empty() ? "" : ", ") + name;
      Fail(node, key,
           "expected a number or a parameter's name, found '" + node.Scalar() + "'" +
               (names.empty() ? " (the file declares no parameters)"
                              : " (parameters: " + names + ")"));
    }
    if (UnitOf(it->first) != unit) {
      Fail(node, key,
           "parameter '" + it->first + "' is in " + UnitOf(it->first) + ", this field in " + unit);
    }
    used_.insert(it->first);
    return it->second;
  }

  double Required(const YAML::Node& map, const std::string& key, const std::string& field) const {
    const YAML::Node node = map[field];
    if (!node.IsDefined()) Fail(map, key, "missing key '" + field + "'");
    return Value(node, Join(key, field), field);
  }

  double Optional(const YAML::Node& map, const std::string& key, const std::string& field,
                  double fallback) const {
    const YAML::Node node = map[field];
    return node.IsDefined() ? Value(node, Join(key, field), field) : fallback;
  }

  double Positive(const YAML::Node& map, const std::string& key, const std::string& field) const {
    const double v = Required(map, key, field);
    if (!(v > 0.0)) Fail(map[field], Join(key, field), "must be > 0");
    return v;
  }

  std::string Word(const YAML::Node& map, const std::string& key, const std::string& field,
                   const std::vector<std::string>& words) const {
    const YAML::Node node = map[field];
    if (!node.IsDefined()) return words.front();
    if (node.IsScalar()) {
      for (const std::string& w : words)
        if (node.Scalar() == w) return w;
    }
    std::string list;
    for (const std::string& w : words) list += (list.empty() ? "" : ", ") + w;
    Fail(node, Join(key, field), "expected one of: " + list);
  }

  void ReadParameters(const YAML::Node& node) {
    if (node.IsDefined() && !node.IsMap()) {
      Fail(node, "parameters", "expected a mapping of name: number");
    }
    for (const auto& entry : node.IsDefined() ? node : YAML::Node(YAML::NodeType::Map)) {
      const std::string name = entry.first.Scalar();
      const std::string key = "parameters." + name;
      if (!KnownUnit(UnitOf(name))) {
        Fail(entry.first, key,
             "a parameter's name ends in its unit: _deg, _s or _hz (e.g. amplitude_deg)");
      }
      double value = 0.0;
      if (!entry.second.IsScalar()) Fail(entry.second, key, "expected a number");
      const std::string problem = ParseNumberText(entry.second.Scalar(), &value);
      if (!problem.empty()) Fail(entry.second, key, "'" + entry.second.Scalar() + "' " + problem);
      parameters_[name] = value * ToSi(UnitOf(name));
    }
    for (const auto& [name, value] : options_.parameters) {
      if (parameters_.count(name) == 0) {
        std::string names;
        for (const auto& [n, v] : parameters_) names += (names.empty() ? "" : ", ") + n;
        ThrowInputError(options_.parameters_source, "",
                        "the protocol " + file_ + " has no parameter '" + name + "' to set" +
                            (names.empty() ? "" : " (it has: " + names + ")"));
      }
      parameters_[name] = value;
    }
  }

  const std::map<std::string, double>& parameters() const { return parameters_; }

  // A bending state of a segment of `joints` joints: theta_x_deg /
  // theta_y_deg (each a number for every joint or a list, one per joint;
  // absent: 0), or plane_deg and bend_deg.
  JointAngles State(const YAML::Node& node, const std::string& key, int joints) const {
    OnlyKeys(node, key, {"theta_x_deg", "theta_y_deg", "plane_deg", "bend_deg"});
    const bool cardan = node["theta_x_deg"].IsDefined() || node["theta_y_deg"].IsDefined();
    const bool plane = node["plane_deg"].IsDefined() || node["bend_deg"].IsDefined();
    if (cardan && plane) {
      Fail(node, key, "give theta_x_deg/theta_y_deg or plane_deg and bend_deg, not both");
    }
    JointAngles state(joints, Eigen::Vector2d::Zero());
    if (plane) {
      const double plane_rad = Required(node, key, "plane_deg");
      const double bend_rad = Required(node, key, "bend_deg");
      const Eigen::Vector2d angles = internal::PlaneBendToCardan(plane_rad, bend_rad);
      for (auto& a : state) a = angles;
      return state;
    }
    for (int axis = 0; axis < 2; ++axis) {
      const std::string field = axis == 0 ? "theta_x_deg" : "theta_y_deg";
      const YAML::Node values = node[field];
      if (!values.IsDefined()) continue;
      const std::string field_key = Join(key, field);
      if (values.IsSequence()) {
        if (static_cast<int>(values.size()) != joints) {
          Fail(values, field_key,
               "has " + std::to_string(values.size()) + " values, the segment has " +
                   std::to_string(joints) + " joints (or give one number for all)");
        }
        for (int j = 0; j < joints; ++j) {
          state[j][axis] = Value(values[j], field_key + "[" + std::to_string(j) + "]", field);
        }
      } else {
        const double v = Value(values, field_key, field);
        for (auto& a : state) a[axis] = v;
      }
    }
    return state;
  }

  // Appends the pieces of the list `node` for a segment of `joints` joints.
  void Pieces(const YAML::Node& node, const std::string& key, int joints,
              std::vector<ProtocolPiece>* out) const {
    if (!node.IsSequence() || node.size() == 0) Fail(node, key, "expected a list of pieces");
    for (std::size_t i = 0; i < node.size(); ++i) {
      const YAML::Node item = node[i];
      const std::string item_key = key + "[" + std::to_string(i) + "]";
      if (!item.IsMap() || item.size() != 1) {
        Fail(item, item_key,
             "expected one piece: hold, move, step, sine, chirp or repeat, e.g. "
             "{hold: {duration_s: 2}}");
      }
      const std::string kind = item.begin()->first.Scalar();
      const YAML::Node body = item.begin()->second;
      const std::string body_key = item_key + "." + kind;
      ProtocolPiece piece;
      piece.source = SourceOf(body, body_key);
      if (kind == "hold") {
        OnlyKeys(body, body_key, {"duration_s"});
        piece.kind = ProtocolPiece::Kind::kHold;
        piece.duration_s = Required(body, body_key, "duration_s");
        if (!(piece.duration_s >= 0.0)) {
          Fail(body["duration_s"], body_key + ".duration_s", "must be >= 0");
        }
        out->push_back(piece);
      } else if (kind == "move") {
        OnlyKeys(body, body_key, {"to", "duration_s", "profile"});
        Word(body, body_key, "profile", {"quintic", "minimum_jerk"});  // the same polynomial
        piece.kind = ProtocolPiece::Kind::kMove;
        piece.duration_s = Positive(body, body_key, "duration_s");
        piece.target = Target(body, body_key, joints);
        out->push_back(piece);
      } else if (kind == "step") {
        OnlyKeys(body, body_key, {"to", "rise_s", "duration_s"});
        const double rise = Positive(body, body_key, "rise_s");
        const double total = Positive(body, body_key, "duration_s");
        if (total < rise) {
          Fail(body["duration_s"], body_key + ".duration_s",
               "must be at least rise_s (the step's whole length, rise included)");
        }
        piece.kind = ProtocolPiece::Kind::kMove;
        piece.duration_s = rise;
        piece.target = Target(body, body_key, joints);
        out->push_back(piece);
        ProtocolPiece hold;
        hold.kind = ProtocolPiece::Kind::kHold;
        hold.duration_s = total - rise;
        hold.source = piece.source;
        out->push_back(hold);
      } else if (kind == "sine" || kind == "chirp") {
        const bool sine = kind == "sine";
        if (sine) {
          OnlyKeys(body, body_key, {"amplitude", "frequency_hz", "duration_s", "cycles", "fade_s"});
        } else {
          OnlyKeys(body, body_key,
                   {"amplitude", "start_hz", "end_hz", "duration_s", "sweep", "fade_s"});
        }
        piece.kind = ProtocolPiece::Kind::kOscillation;
        const YAML::Node amplitude = body["amplitude"];
        if (!amplitude.IsDefined()) Fail(body, body_key, "missing key 'amplitude'");
        piece.amplitude = State(amplitude, body_key + ".amplitude", joints);
        if (sine) {
          piece.start_frequency_hz = piece.end_frequency_hz =
              Frequency(body, body_key, "frequency_hz");
          const bool has_cycles = body["cycles"].IsDefined();
          if (has_cycles == body["duration_s"].IsDefined()) {
            Fail(body, body_key, "give duration_s or cycles (one of them)");
          }
          piece.duration_s = has_cycles
                                 ? Positive(body, body_key, "cycles") / piece.start_frequency_hz
                                 : Positive(body, body_key, "duration_s");
        } else {
          piece.start_frequency_hz = Frequency(body, body_key, "start_hz");
          piece.end_frequency_hz = Frequency(body, body_key, "end_hz");
          piece.duration_s = Positive(body, body_key, "duration_s");
          piece.exponential_sweep =
              Word(body, body_key, "sweep", {"linear", "exponential"}) == "exponential";
        }
        // Default fade: one period of the starting frequency, at most half
        // the piece, so that it starts and ends at rest.
        const double default_fade =
            std::min(1.0 / piece.start_frequency_hz, 0.5 * piece.duration_s);
        piece.fade_s = Optional(body, body_key, "fade_s", default_fade);
        if (!(piece.fade_s >= 0.0) || piece.fade_s > 0.5 * piece.duration_s) {
          Fail(body["fade_s"], body_key + ".fade_s",
               "must be between 0 and half the piece's duration (" +
                   std::to_string(0.5 * piece.duration_s) + " s)");
        }
        out->push_back(piece);
      } else if (kind == "repeat") {
        OnlyKeys(body, body_key, {"times", "pieces"});
        const YAML::Node times_node = body["times"];
        if (!times_node.IsDefined()) Fail(body, body_key, "missing key 'times'");
        const double times = Value(times_node, body_key + ".times", "times");
        if (!(times >= 1.0) || times != std::floor(times) || times > kMaxRepeat) {
          Fail(times_node, body_key + ".times",
               "must be a whole number from 1 to " + std::to_string(kMaxRepeat));
        }
        const YAML::Node inner = body["pieces"];
        if (!inner.IsDefined()) Fail(body, body_key, "missing key 'pieces'");
        std::vector<ProtocolPiece> block;
        Pieces(inner, body_key + ".pieces", joints, &block);
        if (out->size() + block.size() * static_cast<std::size_t>(times) > kMaxPieces) {
          Fail(times_node, body_key + ".times",
               "expands the segment to " +
                   std::to_string(out->size() + block.size() * static_cast<std::size_t>(times)) +
                   " pieces, beyond the " + std::to_string(kMaxPieces) + " a protocol may have");
        }
        for (int k = 0; k < static_cast<int>(times); ++k)
          out->insert(out->end(), block.begin(), block.end());
      } else {
        Fail(item.begin()->first, item_key + "." + kind,
             "unknown piece (expected hold, move, step, sine, chirp or repeat)");
      }
    }
  }

  // A frequency in (0, kMaxFrequencyHz].
  double Frequency(const YAML::Node& body, const std::string& key, const std::string& name) const {
    const double f = Positive(body, key, name);
    if (f > kMaxFrequencyHz) {
      char what[160];
      std::snprintf(what, sizeof(what),
                    "%.4g Hz is above the %.0f Hz a protocol may ask (inputs planned at 1 ms, 20 "
                    "samples a period)",
                    f, kMaxFrequencyHz);
      Fail(body[name], Join(key, name), what);
    }
    return f;
  }

  JointAngles Target(const YAML::Node& body, const std::string& key, int joints) const {
    const YAML::Node to = body["to"];
    if (!to.IsDefined()) Fail(body, key, "missing key 'to'");
    return State(to, key + ".to", joints);
  }

  const std::set<std::string>& used() const { return used_; }

 private:
  const std::string& file_;
  const ProtocolOptions& options_;
  std::map<std::string, double> parameters_;
  mutable std::set<std::string> used_;
};

std::string Degrees(double rad) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.4g", rad / kDegToRad);
  return text;
}

// Checks one segment's pieces once their start states are set: bends within
// the limits, no jump in rate at a join or into the final hold.
void CheckSegment(const std::string& file, const std::vector<ProtocolPiece>& pieces,
                  int first_joint, const std::vector<double>& bend_limits,
                  double bend_limit_override, const ArmConfig& arm) {
  auto fail = [&](const ProtocolPiece& p, const std::string& what) {
    ThrowInputError(file, p.source.Where(), what);
  };
  const int joints = static_cast<int>(pieces.front().start.size());
  JointAngles previous_rate(joints, Eigen::Vector2d::Zero());
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const ProtocolPiece& p = pieces[k];
    const JointAngles start_rate = internal::PieceRates(p, 0.0);
    for (int j = 0; j < joints; ++j) {
      const Eigen::Vector2d jump = start_rate[j] - previous_rate[j];
      if (jump.cwiseAbs().maxCoeff() > kJoinRateTolerance) {
        fail(p, "starts with a jump in rate at joint " + std::to_string(first_joint + j) + " (θx " +
                    Degrees(previous_rate[j].x()) + " → " + Degrees(start_rate[j].x()) +
                    " deg/s, θy " + Degrees(previous_rate[j].y()) + " → " +
                    Degrees(start_rate[j].y()) +
                    " deg/s): give the oscillation a fade_s, or join it to a piece of the same "
                    "rate");
      }
    }
    // Bends, sampled finely enough for the fastest oscillation a protocol
    // can plan within the cable-speed limits (200 samples per second and
    // at least 200 per piece).
    const int samples = std::max(200, static_cast<int>(std::ceil(p.duration_s * 200.0)));
    for (int j = 0; j < joints; ++j) {
      // A file may narrow the range (disks wider than the hole circle), not
      // widen it: past it the model has no contact between disks.
      const double range = bend_limits[first_joint - 1 + j];
      const bool narrowed = !std::isnan(bend_limit_override) && bend_limit_override < range;
      const double limit = narrowed ? bend_limit_override : range;
      double peak = 0.0, first_beyond = NAN;
      for (int i = 0; i <= samples; ++i) {
        const double t = p.duration_s * i / samples;
        const Eigen::Vector2d a = internal::PieceAngles(p, t)[j];
        const double bend = std::acos(std::clamp(std::cos(a.x()) * std::cos(a.y()), -1.0, 1.0));
        if (bend > limit && std::isnan(first_beyond)) first_beyond = t;
        peak = std::max(peak, bend);
      }
      if (peak > limit) {
        fail(p, "bends joint " + std::to_string(first_joint + j) + " to " + Degrees(peak) +
                    " deg (beyond from " + Degrees(first_beyond * kDegToRad) +
                    " s into the piece), past its " + Degrees(limit) + " deg (" +
                    (narrowed ? "limits.joint_bend_deg"
                              : "its range, where its disks meet at the hole circle" +
                                    internal::RangeSetBy(arm, first_joint + j)) +
                    ")");
      }
    }
    previous_rate = internal::PieceRates(p, p.duration_s);
  }
  for (int j = 0; j < joints; ++j) {
    if (previous_rate[j].cwiseAbs().maxCoeff() > kJoinRateTolerance) {
      fail(pieces.back(), "ends moving (joint " + std::to_string(first_joint + j) + " at θx " +
                              Degrees(previous_rate[j].x()) + ", θy " +
                              Degrees(previous_rate[j].y()) +
                              " deg/s) and the segment then holds: a jump in rate; end with a "
                              "fade_s or a piece that ends at rest");
    }
  }
}

}  // namespace

std::string ProtocolSource::Where() const {
  if (line == 0) return key.empty() ? "" : "key '" + key + "'";
  return "line " + std::to_string(line) + (key.empty() ? "" : ", key '" + key + "'");
}

Protocol ParseProtocol(const std::string& yaml_text, const std::string& source_name,
                       const ArmConfig& arm, const ProtocolOptions& options) {
  const YAML::Node root = ParseYamlDocument(yaml_text, source_name);
  ProtocolReader r(source_name, options);
  if (!root.IsMap()) r.Fail(root, "", "expected a mapping with schema, segments, ...");
  r.OnlyKeys(root, "",
             {"schema", "name", "description", "planning", "limits", "parameters", "segments"});
  const YAML::Node schema = root["schema"];
  if (!schema.IsDefined()) r.Fail(root, "", "missing key 'schema' (ccsrm-protocol/1)");
  if (!schema.IsScalar() || schema.Scalar() != kProtocolSchema) {
    r.Fail(schema, "schema",
           "expected '" + std::string(kProtocolSchema) + "', found '" +
               (schema.IsScalar() ? schema.Scalar() : std::string("a collection")) + "'" +
               (schema.IsScalar() && schema.Scalar().rfind("ccsrm-protocol/", 0) == 0
                    ? ": unsupported version"
                    : ""));
  }
  Protocol protocol;
  protocol.source_name = source_name;
  protocol.source_yaml = yaml_text;
  for (const char* field : {"name", "description"}) {
    const YAML::Node node = root[field];
    if (!node.IsDefined()) continue;
    if (!node.IsScalar()) r.Fail(node, field, "expected text");
    (std::string(field) == "name" ? protocol.name : protocol.description) = node.Scalar();
  }
  r.ReadParameters(root["parameters"]);
  if (const YAML::Node planning = root["planning"]; planning.IsDefined()) {
    if (planning.IsScalar() && planning.Scalar() == "kinematic") {
      protocol.planning = InputPlanning::Method::kKinematic;
    } else if (planning.IsScalar() && planning.Scalar() == "static_equilibrium") {
      protocol.planning = InputPlanning::Method::kStaticEquilibrium;
    } else {
      r.Fail(planning, "planning",
             "expected kinematic or static_equilibrium, found '" +
                 (planning.IsScalar() ? planning.Scalar() : std::string("a collection")) + "'");
    }
  }
  const YAML::Node limits = root["limits"];
  if (limits.IsDefined()) {
    r.OnlyKeys(limits, "limits", {"cable_speed_mps", "cable_acceleration_mps2", "joint_bend_deg"});
    ProtocolLimits& l = protocol.limits;
    if (limits["cable_speed_mps"].IsDefined())
      l.cable_speed_mps = r.Positive(limits, "limits", "cable_speed_mps");
    if (limits["cable_acceleration_mps2"].IsDefined())
      l.cable_acceleration_mps2 = r.Positive(limits, "limits", "cable_acceleration_mps2");
    if (limits["joint_bend_deg"].IsDefined()) {
      l.joint_bend_rad = r.Positive(limits, "limits", "joint_bend_deg");
      if (l.joint_bend_rad > 0.5 * kPi) {
        r.Fail(limits["joint_bend_deg"], "limits.joint_bend_deg",
               "must be at most 90 (a universal joint's θy range)");
      }
    }
  }

  const int num_segments = static_cast<int>(arm.segments.size());
  const YAML::Node segments = root["segments"];
  if (!segments.IsDefined()) r.Fail(root, "", "missing key 'segments'");
  if (!segments.IsMap() || segments.size() == 0) {
    r.Fail(segments, "segments", "expected a mapping: all, or 1, 2, ... (one per segment)");
  }
  std::vector<YAML::Node> per_segment(num_segments);
  std::vector<bool> given(num_segments, false);
  std::vector<std::string> keys(num_segments);
  for (const auto& entry : segments) {
    const std::string name = entry.first.Scalar();
    if (name == "all") {
      if (segments.size() != 1) {
        r.Fail(entry.first, "segments.all", "'all' stands alone: give it or numbered segments");
      }
      for (int s = 0; s < num_segments; ++s) {
        per_segment[s] = entry.second;
        given[s] = true;
        keys[s] = "segments.all";
      }
      continue;
    }
    int number = 0;
    try {
      std::size_t used = 0;
      number = std::stoi(name, &used);
      if (used != name.size()) number = 0;
    } catch (const std::exception&) {
      number = 0;
    }
    if (number < 1 || number > num_segments) {
      r.Fail(entry.first, "segments." + name,
             "the arm has " + std::to_string(num_segments) + " segment" +
                 (num_segments == 1 ? "" : "s") + ": expected 'all' or 1.." +
                 std::to_string(num_segments));
    }
    per_segment[number - 1] = entry.second;
    given[number - 1] = true;
    keys[number - 1] = "segments." + name;
  }
  for (int s = 0; s < num_segments; ++s) {
    if (!given[s]) {
      r.Fail(segments, "segments",
             "has no pieces for segment " + std::to_string(s + 1) + " of the arm's " +
                 std::to_string(num_segments) + " (give every segment, or 'all')");
    }
  }
  const std::vector<double> bend_limits = JointRangesRad(arm);
  int first_joint = 1;
  for (int s = 0; s < num_segments; ++s) {
    const int joints = arm.segments[s].links;
    std::vector<ProtocolPiece> pieces;
    r.Pieces(per_segment[s], keys[s], joints, &pieces);
    JointAngles state(joints, Eigen::Vector2d::Zero());
    for (ProtocolPiece& p : pieces) {
      p.start = state;
      state = internal::PieceAngles(p, p.duration_s);
    }
    CheckSegment(source_name, pieces, first_joint, bend_limits, protocol.limits.joint_bend_rad,
                 arm);
    protocol.segments.push_back(std::move(pieces));
    protocol.segment_joints.push_back(joints);
    first_joint += joints;
  }
  protocol.parameters = r.parameters();
  return protocol;
}

Protocol LoadProtocol(const std::string& path, const ArmConfig& arm,
                      const ProtocolOptions& options) {
  return ParseProtocol(ReadTextFile(path), path, arm, options);
}

std::map<std::string, double> PaperProtocolParameters(const ProtocolConfig& p) {
  return {{"amplitude_deg", p.amplitude_rad},
          {"ramp_s", p.ramp_s},
          {"hold_s", p.hold_s},
          {"return_s", p.return_s},
          {"rest_s", p.rest_s}};
}

std::string Protocol::ToYaml() const {
  YAML::Node root = YAML::Load(source_yaml);
  bool changed = false;
  for (const auto& [name, value] : parameters) {
    const double in_file_units = value / ToSi(UnitOf(name));
    const YAML::Node node = root["parameters"][name];
    double written = 0.0;
    if (node.IsScalar() && ParseNumberText(node.Scalar(), &written).empty() &&
        written * ToSi(UnitOf(name)) == value) {
      continue;
    }
    root["parameters"][name] = in_file_units;
    changed = true;
  }
  if (!changed) return source_yaml;  // as written, comments kept
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << root;
  return std::string(out.c_str()) + "\n";
}

}  // namespace ccsrm::sim
