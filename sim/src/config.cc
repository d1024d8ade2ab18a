#include "ccsrm/sim/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/common/yaml_document.h"
#include "ccsrm/sim/effects.h"
#include "effects/effects_yaml.h"

namespace ccsrm::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr const char* kSchema = "ccsrm-config/1";
// The YAML words of HoleFrictionModel, in its order.
const std::vector<std::string> kHoleFrictionWords = {"events", "smoothed", "off", "presliding"};
// In ConnectingKind's order.
const std::vector<std::string> kConnectingWords = {"small", "large", "none"};
// The YAML words of ConduitFrictionModel, in its order.
const std::vector<std::string> kConduitFrictionWords = {"modified_coulomb", "presliding"};
// The YAML words of RungeKuttaStepper, in its order (GSL's names).
const std::vector<std::string> kStepperWords = {"rkck", "rkf45"};

// Line (1-based) of every key path seen while parsing, so that Validate can
// name the line of a value that is out of range.
using LineMap = std::map<std::string, int>;

std::string Where(const LineMap* lines, const std::string& key) {
  if (lines != nullptr) {
    const auto it = lines->find(key);
    if (it != lines->end()) return "line " + std::to_string(it->second) + ", key '" + key + "'";
  }
  return "key '" + key + "'";
}

// Levenshtein distance, to suggest the key a typo meant.
int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// Walks one YAML mapping: every read records the key as known; Finish()
// rejects the keys nobody read (typos).
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string path, const std::string& file, LineMap* lines)
      : node_(node), path_(std::move(path)), file_(file), lines_(lines) {
    if (!node_.IsMap()) Fail(path_, node_, "expected a mapping of keys");
  }

  MapReader Section(const std::string& key) {
    return MapReader(Require(key), Join(key), file_, lines_);
  }

  double Number(const std::string& key) { return AsNumber(Require(key), Join(key)); }

  // A key added after ccsrm-config/1 was first published: files written
  // before it leave it out and mean `fallback`.
  double OptionalNumber(const std::string& key, double fallback) {
    return Absent(key) ? fallback : Number(key);
  }

  // An optional key, known to the reader either way: true when the file
  // leaves it out.
  bool Absent(const std::string& key) {
    if (node_[key].IsDefined()) return false;
    read_.insert(key);
    allowed_.push_back(key);
    return true;
  }

  bool Has(const std::string& key) const { return node_[key].IsDefined(); }

  // An optional section read by someone else (undefined when absent).
  YAML::Node OptionalNode(const std::string& key) {
    read_.insert(key);
    allowed_.push_back(key);
    if (node_[key].IsDefined()) Record(Join(key), node_[key]);
    return node_[key];
  }
  YAML::Node Node(const std::string& key) const { return node_[key]; }

  int Integer(const std::string& key) {
    const YAML::Node node = Require(key);
    const double value = AsNumber(node, Join(key));
    if (value != std::floor(value) || std::abs(value) > 1e9) {
      Fail(Join(key), node, "expected a whole number, found '" + node.Scalar() + "'");
    }
    return static_cast<int>(value);
  }

  bool Boolean(const std::string& key) {
    const YAML::Node node = Require(key);
    const std::string text = node.IsScalar() ? node.Scalar() : "";
    if (text == "true") return true;
    if (text == "false") return false;
    Fail(Join(key), node, "expected true or false, found '" + text + "'");
  }

  // A switch added after ccsrm-config/1 was first published: files written
  // before it leave it out and mean `fallback`.
  bool OptionalBoolean(const std::string& key, bool fallback) {
    return Absent(key) ? fallback : Boolean(key);
  }

  // A key added after ccsrm-config/1 was first published: files written
  // before it leave it out and get `fallback`; else one of `choices`.
  int OptionalWord(const std::string& key, const std::vector<std::string>& choices, int fallback) {
    read_.insert(key);
    allowed_.push_back(key);
    const YAML::Node node = node_[key];
    if (!node.IsDefined()) return fallback;
    Record(Join(key), node);
    const std::string word = node.IsScalar() ? node.Scalar() : std::string();
    for (std::size_t i = 0; i < choices.size(); ++i) {
      if (word == choices[i]) return static_cast<int>(i);
    }
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "'" : ", '") + c + "'";
    Fail(Join(key), node, "expected one of " + list + ", found '" + word + "'");
  }

  std::string String(const std::string& key) {
    const YAML::Node node = Require(key);
    if (!node.IsScalar()) Fail(Join(key), node, "expected a string");
    return node.Scalar();
  }

  Eigen::Vector3d Vector3(const std::string& key) {
    const YAML::Node node = Require(key);
    if (!node.IsSequence() || node.size() != 3)
      Fail(Join(key), node, "expected a list of 3 numbers");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = AsNumber(node[i], Join(key) + "[" + std::to_string(i) + "]");
    return v;
  }

  // A sequence of mappings; `item` is called with a reader for each.
  template <typename Fn>
  void ForEach(const std::string& key, Fn&& item) {
    const YAML::Node node = Require(key);
    if (!node.IsSequence()) Fail(Join(key), node, "expected a list");
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::string path = Join(key) + "[" + std::to_string(i) + "]";
      Record(path, node[i]);
      MapReader reader(node[i], path, file_, lines_);
      item(reader, static_cast<int>(i));
      reader.Finish();
    }
  }

  // A list of words, each one of `choices`; returns the index of each word.
  std::vector<int> WordList(const std::string& key, const std::vector<std::string>& choices) {
    const YAML::Node node = Require(key);
    if (!node.IsSequence()) Fail(Join(key), node, "expected a list");
    std::vector<int> out;
    for (const auto& item : node) {
      const std::string word = item.IsScalar() ? item.Scalar() : std::string();
      int index = -1;
      for (std::size_t i = 0; i < choices.size(); ++i) {
        if (word == choices[i]) index = static_cast<int>(i);
      }
      if (index < 0) {
        std::string list;
        for (const auto& c : choices) list += (list.empty() ? "'" : ", '") + c + "'";
        Fail(Join(key), item, "expected one of " + list + ", found '" + word + "'");
      }
      out.push_back(index);
    }
    return out;
  }

  void Finish() const {
    for (const auto& entry : node_) {
      const std::string key = entry.first.Scalar();
      if (read_.count(key) == 0) {
        Fail(Join(key), entry.first, "unknown key (allowed here: " + Allowed() + ")");
      }
    }
  }

  [[noreturn]] void Fail(const std::string& key, const YAML::Node& at,
                         const std::string& what) const {
    ThrowInputError(file_, "line " + std::to_string(at.Mark().line + 1) + ", key '" + key + "'",
                    what);
  }

  const std::string& path() const { return path_; }

 private:
  std::string Join(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  YAML::Node Require(const std::string& key) {
    read_.insert(key);
    allowed_.push_back(key);
    const YAML::Node child = node_[key];
    if (!child.IsDefined() || child.IsNull()) {
      // A missing key next to an unknown one is most often a typo: name the typo.
      for (const auto& entry : node_) {
        const std::string other = entry.first.Scalar();
        if (read_.count(other) == 0 && EditDistance(other, key) <= 3) {
          Fail(Join(other), entry.first, "unknown key (did you mean '" + key + "'?)");
        }
      }
      const std::string where = path_.empty() ? "top level" : "'" + path_ + "'";
      ThrowInputError(file_,
                      "line " + std::to_string(node_.Mark().line + 1) + ", key '" + Join(key) + "'",
                      "missing (required in " + where + ")");
    }
    Record(Join(key), child);
    return child;
  }

  void Record(const std::string& key, const YAML::Node& node) const {
    if (lines_ != nullptr) (*lines_)[key] = node.Mark().line + 1;
  }

  double AsNumber(const YAML::Node& node, const std::string& key) const {
    return ReadYamlNumber(node, file_,
                          "line " + std::to_string(node.Mark().line + 1) + ", key '" + key + "'");
  }

  std::string Allowed() const {
    std::string out;
    for (const auto& key : allowed_) out += (out.empty() ? "" : ", ") + key;
    return out;
  }

  YAML::Node node_;
  std::string path_;
  const std::string& file_;
  LineMap* lines_;
  std::set<std::string> read_;
  std::vector<std::string> allowed_;
};

// The parameters whose configuration key sits in `section`'s mapping
// (ParameterInfo::config_key), read or written through the one table.
void ReadParameters(MapReader& section, ArmParameters* parameters) {
  const std::string prefix = section.path() + ".";
  for (const ParameterInfo& p : Parameters()) {
    if (p.config_key.rfind(prefix, 0) != 0) continue;
    const std::string key = p.config_key.substr(prefix.size());
    parameters->*p.field = std::isnan(p.absent_value) ? section.Number(key)
                                                      : section.OptionalNumber(key, p.absent_value);
  }
}

void WriteParameters(const std::string& section, const ArmParameters& parameters,
                     YAML::Emitter* out) {
  const std::string prefix = section + ".";
  for (const ParameterInfo& p : Parameters()) {
    if (p.config_key.rfind(prefix, 0) == 0) {
      *out << YAML::Key << p.config_key.substr(prefix.size()) << YAML::Value << parameters.*p.field;
    }
  }
}

class Checker {
 public:
  Checker(const std::string& file, const LineMap* lines) : file_(file), lines_(lines) {}

  void Positive(const std::string& key, double value) const {
    if (!(value > 0.0)) Fail(key, "must be > 0, found " + Format(value));
  }
  void NonNegative(const std::string& key, double value) const {
    if (!(value >= 0.0)) Fail(key, "must be >= 0, found " + Format(value));
  }
  void InRange(const std::string& key, double value, double lo, double hi,
               const std::string& unit = "") const {
    if (!(value >= lo && value <= hi)) {
      Fail(key, "must be in [" + Format(lo) + ", " + Format(hi) + "]" +
                    (unit.empty() ? "" : " " + unit) + ", found " + Format(value));
    }
  }
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    ThrowInputError(file_, Where(lines_, key), what);
  }

 private:
  static std::string Format(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
  }
  const std::string& file_;
  const LineMap* lines_;
};

void CheckArm(const ArmConfig& arm, const Checker& check) {
  check.Positive("arm.joint_disk_gap_m", arm.joint_disk_gap_m);
  if (arm.segments.empty()) check.Fail("arm.segments", "at least one segment is required");
  for (std::size_t i = 0; i < arm.segments.size(); ++i) {
    const SegmentConfig& s = arm.segments[i];
    const std::string p = "arm.segments[" + std::to_string(i) + "].";
    if (s.links < 1 || s.links > 100)
      check.Fail(p + "links", "must be in [1, 100], found " + std::to_string(s.links));
    check.Positive(p + "link_length_m", s.link_length_m);
    if (s.link_length_m <= arm.joint_disk_gap_m) {
      check.Fail(p + "link_length_m",
                 "must exceed arm.joint_disk_gap_m so that both disks fit on the link");
    }
    check.Positive(p + "link_mass_kg", s.link_mass_kg);
    for (int k = 0; k < 3; ++k) check.Positive(p + "link_inertia_kgm2", s.link_inertia_kgm2[k]);
    check.Positive(p + "hole_circle_radius_m", s.hole_circle_radius_m);
    // The holes lie on the link's disks, and no arm of this kind carries
    // disks wider than its links are long (they hold their holes at 0.1-0.5
    // of a link length): a hole circle beyond the link length is a unit slip,
    // and disks that wide would leave every joint its cables pass almost no
    // range (2 atan(d / 2R), model.h), which a run then blames on the motion.
    if (s.hole_circle_radius_m > s.link_length_m) {
      std::ostringstream what;
      what << std::setprecision(3) << s.hole_circle_radius_m << " m is beyond the link length "
           << s.link_length_m << " m: the holes would lie outside the link's disks (arms of this "
           << "kind have 0.1-0.5 of a link length, the paper's 0.16-0.25), and disks that wide "
           << "leave the joints these cables pass ±"
           << 2.0 * std::atan(arm.joint_disk_gap_m / (2.0 * s.hole_circle_radius_m)) * 180.0 / kPi
           << " deg: check the units";
      check.Fail(p + "hole_circle_radius_m", what.str());
    }
    if (static_cast<int>(s.connecting_pattern.size()) != s.links - 1) {
      check.Fail(p + "connecting_pattern", "needs links - 1 = " + std::to_string(s.links - 1) +
                                               " entries, found " +
                                               std::to_string(s.connecting_pattern.size()));
    }
    if (s.uses(ConnectingKind::kSmallS)) {
      check.Positive(p + "small_s.cable_length_m", s.small_s.cable_length_m);
      check.Positive(p + "small_s.pulley_radius_m", s.small_s.pulley_radius_m);
    }
    if (s.uses(ConnectingKind::kLargeS)) {
      check.Positive(p + "large_s.cable_length_m", s.large_s.cable_length_m);
      check.Positive(p + "large_s.pulley_radius_m", s.large_s.pulley_radius_m);
      check.InRange(p + "large_s.wrap_angle_deg", s.large_s.wrap_angle_rad / kDegToRad, 0.0, 720.0);
    }
    // A joint with neither a connecting mechanism on either side nor a
    // backbone would be free: its segment's cables alone cannot hold a chain
    // of joints (they bend it, they do not set how).
    if (s.uses(ConnectingKind::kNone) && !s.backbone.present()) {
      check.Fail(p + "connecting_pattern",
                 "'none' needs an elastic backbone (arm.segments[].backbone) to hold its joints");
    }
    if (s.backbone.present()) {
      check.Positive(p + "backbone.outer_diameter_m", s.backbone.outer_diameter_m);
      check.InRange(p + "backbone.inner_diameter_m", s.backbone.inner_diameter_m, 0.0,
                    s.backbone.outer_diameter_m);
      if (!(s.backbone.inner_diameter_m < s.backbone.outer_diameter_m)) {
        check.Fail(p + "backbone.inner_diameter_m", "must be below outer_diameter_m");
      }
    }
  }
  const DrivingCableConfig& d = arm.driving;
  check.Positive("driving_cables.youngs_modulus_pa", d.youngs_modulus_pa);
  check.Positive("driving_cables.cross_section_m2", d.cross_section_m2);
  check.Positive("driving_cables.density_kgpm3", d.density_kgpm3);
  check.Positive("driving_cables.input_offset_m", d.input_offset_m);
  if (d.cables.empty())
    check.Fail("driving_cables.cables", "at least one driving cable is required");
  for (std::size_t i = 0; i < d.cables.size(); ++i) {
    const std::string p = "driving_cables.cables[" + std::to_string(i) + "].";
    const int seg = d.cables[i].segment;
    if (seg < 1 || seg > static_cast<int>(arm.segments.size())) {
      check.Fail(p + "segment", "must name a segment 1.." + std::to_string(arm.segments.size()) +
                                    ", found " + std::to_string(seg));
    }
    check.InRange(p + "hole_angle_deg", d.cables[i].hole_angle_rad / kDegToRad, -360.0, 360.0);
  }
  const ConnectingCableConfig& cc = arm.connecting;
  check.Positive("connecting_cables.youngs_modulus_pa", cc.youngs_modulus_pa);
  check.Positive("connecting_cables.cross_section_m2", cc.cross_section_m2);
}

// What any real arm of this kind has, from a bench-top arm of a few
// centimetres to a metre-scale one, with steel to polymer cables. Generous:
// they do not judge a design, they refuse what no arm has (1e300, a slipped
// exponent) before a run diverges on it. The model itself (ArmModel,
// CheckArm) needs only positive values, so a test may build an arm beyond
// these on purpose.
struct PhysicalRange {
  double lower;
  double upper;
  const char* unit;
};
// Cable materials: none stiffer than diamond (~1.2e12 Pa), none softer than
// rubber (~1e6 Pa); steel wire rope is ~1e11, the paper's effective 2.6e10.
constexpr PhysicalRange kYoungsModulus{1e6, 2e12, "Pa"};
// Load-bearing cross section: from a 0.01 mm fibre (~1e-10 m^2) to a 35 mm
// rope (1e-3 m^2), far thicker than the cables of a metre-scale arm.
constexpr PhysicalRange kCrossSection{1e-10, 1e-3, "m^2"};
// Cable material density: polyethylene fibre (~970 kg/m^3, the lightest
// cable material) floats on water, so 500 is below any; nothing is denser
// than osmium (~2.26e4 kg/m^3).
constexpr PhysicalRange kDensity{500.0, 2.5e4, "kg/m^3"};
// A link carries two disk halves and a joint: shorter than 1 mm it cannot;
// a metre-scale arm's links are 0.1-0.5 m, so 2 m is beyond any.
constexpr PhysicalRange kLinkLength{1e-3, 2.0, "m"};
// From a 0.1 g printed millimetre link to 100 kg (a metre-scale steel link
// weighs a few kg).
constexpr PhysicalRange kLinkMass{1e-4, 100.0, "kg"};
// Principal inertia: 0.1 g at 0.1 mm from the axis (m r^2 = 1e-12) up to
// 100 kg spread over 2 m (m L^2 / 12 ~ 33).
constexpr PhysicalRange kLinkInertia{1e-12, 100.0, "kg m^2"};
// Radii on the disks (hole circle, pulleys) and the gap between the two
// disks of a joint: from 0.1 mm (a catheter-sized arm) to 1 m (wider than
// any disk of a metre-scale arm).
constexpr PhysicalRange kDiskSize{1e-4, 1.0, "m"};
// A connecting cable spans one joint to the next, about a link length
// (< 2 m) plus its wraps: 5 m is beyond any, 1 mm below any.
constexpr PhysicalRange kConnectingCableLength{1e-3, 5.0, "m"};
// The input point lies behind the ground disk on the way to the actuator;
// even a remote actuator pack sits within 10 m of cable.
constexpr PhysicalRange kInputOffset{1e-4, 10.0, "m"};
// |g|: 0 (a level air table, as in the paper) to 3 g (29.4 m/s^2), room for
// any planet's bench or a base that accelerates.
constexpr PhysicalRange kGravity{0.0, 30.0, "m/s^2"};

void CheckArmRanges(const ArmConfig& arm, const Checker& check) {
  const auto in = [&](const std::string& key, double value, const PhysicalRange& range) {
    check.InRange(key, value, range.lower, range.upper, range.unit);
  };
  in("arm.joint_disk_gap_m", arm.joint_disk_gap_m, kDiskSize);
  const double g = arm.gravity_mps2.norm();
  if (!(g >= kGravity.lower && g <= kGravity.upper)) {
    std::ostringstream what;
    what << "magnitude must be in [" << kGravity.lower << ", " << kGravity.upper << "] "
         << kGravity.unit << ", found " << g;
    check.Fail("arm.gravity_mps2", what.str());
  }
  for (std::size_t i = 0; i < arm.segments.size(); ++i) {
    const SegmentConfig& s = arm.segments[i];
    const std::string p = "arm.segments[" + std::to_string(i) + "].";
    in(p + "link_length_m", s.link_length_m, kLinkLength);
    in(p + "link_mass_kg", s.link_mass_kg, kLinkMass);
    for (int k = 0; k < 3; ++k) in(p + "link_inertia_kgm2", s.link_inertia_kgm2[k], kLinkInertia);
    in(p + "hole_circle_radius_m", s.hole_circle_radius_m, kDiskSize);
    if (s.uses(ConnectingKind::kSmallS)) {
      in(p + "small_s.cable_length_m", s.small_s.cable_length_m, kConnectingCableLength);
      in(p + "small_s.pulley_radius_m", s.small_s.pulley_radius_m, kDiskSize);
    }
    if (s.uses(ConnectingKind::kLargeS)) {
      in(p + "large_s.cable_length_m", s.large_s.cable_length_m, kConnectingCableLength);
      in(p + "large_s.pulley_radius_m", s.large_s.pulley_radius_m, kDiskSize);
    }
    if (s.backbone.present()) {
      in(p + "backbone.youngs_modulus_pa", s.backbone.youngs_modulus_pa, kYoungsModulus);
      in(p + "backbone.outer_diameter_m", s.backbone.outer_diameter_m, kDiskSize);
    }
  }
  const DrivingCableConfig& d = arm.driving;
  in("driving_cables.youngs_modulus_pa", d.youngs_modulus_pa, kYoungsModulus);
  in("driving_cables.cross_section_m2", d.cross_section_m2, kCrossSection);
  in("driving_cables.density_kgpm3", d.density_kgpm3, kDensity);
  in("driving_cables.input_offset_m", d.input_offset_m, kInputOffset);
  in("connecting_cables.youngs_modulus_pa", arm.connecting.youngs_modulus_pa, kYoungsModulus);
  in("connecting_cables.cross_section_m2", arm.connecting.cross_section_m2, kCrossSection);
}

// Two holes of one segment closer than this are one: below 1 deg two lines
// of pull differ by less than the scatter of drilled holes, whatever the
// cable. A thicker cable needs more (CheckCableLayout).
constexpr double kMinHoleSeparationDeg = 1.0;

// What a segment's driving cables must be able to do: bend it about both
// axes, either way. A cable only pulls, and it pulls its segment toward its
// own hole, so the bends the cables can make are the non-negative
// combinations of their hole directions. Those cover every direction only
// when no closed half-plane through the axis holds every hole (the largest
// angular gap between neighbouring holes is below 180 deg), which takes
// three cables at least. Two cables at one angle pull along one line, and
// their holes overlap on the disks. Refused here, before a run "completes"
// with a segment swinging out of the plan (issue 32).
void CheckCableLayout(const ArmConfig& arm, const Checker& check) {
  const auto degrees = [](double rad, int digits = 6) {
    std::ostringstream out;
    out << std::setprecision(digits) << rad / kDegToRad;
    return out.str();
  };
  // A cable's diameter, from its load-bearing cross section (a solid round).
  const double diameter = 2.0 * std::sqrt(arm.driving.cross_section_m2 / kPi);
  for (std::size_t s = 0; s < arm.segments.size(); ++s) {
    const SegmentConfig& segment = arm.segments[s];
    const std::string name = "segment " + std::to_string(s + 1) + " ('" + segment.name + "')";
    struct Hole {
      double angle_rad;   // in [0, 2 pi)
      std::size_t cable;  // index into arm.driving.cables
    };
    std::vector<Hole> holes;
    for (std::size_t k = 0; k < arm.driving.cables.size(); ++k) {
      if (arm.driving.cables[k].segment != static_cast<int>(s) + 1) continue;
      double angle = std::fmod(arm.driving.cables[k].hole_angle_rad, 2.0 * kPi);
      if (angle < 0.0) angle += 2.0 * kPi;
      holes.push_back({angle, k});
    }
    const auto key = [](std::size_t cable) {
      return "driving_cables.cables[" + std::to_string(cable) + "]";
    };
    if (holes.empty()) {
      check.Fail("arm.segments[" + std::to_string(s) + "]",
                 name +
                     " has no driving cable: at least three are needed to bend it about "
                     "both axes");
    }
    if (holes.size() < 3) {
      std::string list;
      for (const Hole& h : holes)
        list += (list.empty() ? "" : " and ") + std::to_string(h.cable + 1);
      check.Fail(key(holes.back().cable),
                 name + " has " + std::to_string(holes.size()) + " driving cable" +
                     (holes.size() == 1 ? " (cable " : "s (cables ") + list +
                     "): at least three are needed to bend it about both axes (a cable only "
                     "pulls)");
    }
    std::sort(holes.begin(), holes.end(),
              [](const Hole& a, const Hole& b) { return a.angle_rad < b.angle_rad; });
    // Holes overlap when their centres are closer than one cable diameter
    // on the segment's hole circle (chord 2 r sin(dphi / 2) < diameter).
    const double overlap =
        2.0 * std::asin(std::min(1.0, diameter / (2.0 * segment.hole_circle_radius_m)));
    const double tolerance = std::max(kMinHoleSeparationDeg * kDegToRad, overlap);
    double widest_gap = 0.0;
    std::size_t gap_after = 0;
    for (std::size_t i = 0; i < holes.size(); ++i) {
      const Hole& a = holes[i];
      const Hole& b = holes[(i + 1) % holes.size()];
      const double gap =
          i + 1 < holes.size() ? b.angle_rad - a.angle_rad : b.angle_rad + 2.0 * kPi - a.angle_rad;
      if (gap < tolerance) {
        const std::size_t first = std::min(a.cable, b.cable), second = std::max(a.cable, b.cable);
        check.Fail(key(second),
                   name + ": cables " + std::to_string(first + 1) + " and " +
                       std::to_string(second + 1) + " sit at hole angles " +
                       degrees(arm.driving.cables[first].hole_angle_rad) + " and " +
                       degrees(arm.driving.cables[second].hole_angle_rad) + " deg, closer than " +
                       degrees(tolerance, 3) +
                       " deg: coincident holes (they overlap on the disks, the larger of 1 deg "
                       "and one cable diameter on the hole circle) pull along one line");
      }
      if (gap > widest_gap) {
        widest_gap = gap;
        gap_after = i;
      }
    }
    // A closed half-plane: a gap of 180 deg exactly (cables at 0, 90 and
    // 180 deg) leaves the direction across it out of reach too.
    if (widest_gap >= kPi - 1e-9) {
      std::string list;
      for (const Hole& h : holes) {
        list += (list.empty() ? "" : ", ") + degrees(arm.driving.cables[h.cable].hole_angle_rad);
      }
      const Hole& from = holes[gap_after];
      const Hole& to = holes[(gap_after + 1) % holes.size()];
      check.Fail(key(holes.back().cable),
                 name + ": its " + std::to_string(holes.size()) + " cables (hole angles " + list +
                     " deg) lie within a half-plane, no cable between " +
                     degrees(arm.driving.cables[from.cable].hole_angle_rad) + " and " +
                     degrees(arm.driving.cables[to.cable].hole_angle_rad) + " deg (a gap of " +
                     degrees(widest_gap, 3) +
                     " deg): cables only pull, so the segment cannot be bent toward that side");
    }
  }
}

// Values far outside what arms of this kind have, though the model can run
// them: each a warning with its reason, not a refusal (a test rig may be
// odd on purpose). Ratios rather than absolute values, so that they hold
// from a catheter-sized arm to a metre-scale one.
std::vector<std::string> ArmWarnings(const Config& c, const LineMap* lines) {
  std::vector<std::string> warnings;
  const auto warn = [&](const std::string& key, const std::string& what) {
    warnings.push_back(FormatInputError(c.source_name, Where(lines, key), what));
  };
  const auto text = [](double v) {
    std::ostringstream out;
    out << std::setprecision(3) << v;
    return out.str();
  };
  for (std::size_t i = 0; i < c.arm.segments.size(); ++i) {
    const SegmentConfig& s = c.arm.segments[i];
    const std::string p = "arm.segments[" + std::to_string(i) + "].";
    // Hole circle against link length: arms of this kind put their holes at
    // 0.1-0.5 of a link's length from the axis (the paper's 0.16 and 0.25).
    // Below a fiftieth the cables have almost no lever on the joints.
    const double ratio = s.hole_circle_radius_m / s.link_length_m;
    if (ratio < 0.02) {  // beyond 1 is refused (CheckArm)
      warn(p + "hole_circle_radius_m",
           "hole circle radius " + text(s.hole_circle_radius_m) + " m is " + text(ratio) +
               " times the link length " + text(s.link_length_m) +
               " m: the cables would have almost no lever on the joints; arms of this kind "
               "have 0.1-0.5 (the paper's arm 0.16-0.25): check the units");
    }
    // Mass against size: the mean density of the link's envelope, a
    // cylinder of its length out to twice the hole circle (the disks reach
    // past their holes). The paper's links make 200 kg/m^3 (hollow disks on
    // a spine); below 10 a link is lighter than foam through and through,
    // above 1e4 denser than solid steel filling the whole envelope.
    const double envelope = kPi * std::pow(2.0 * s.hole_circle_radius_m, 2) * s.link_length_m;
    const double density = s.link_mass_kg / envelope;
    if (density < 10.0 || density > 1e4) {
      warn(p + "link_mass_kg",
           "a link of " + text(s.link_mass_kg) + " kg in an envelope of " + text(envelope) +
               " m^3 (its length, out to twice the hole circle) is " + text(density) +
               " kg/m^3 on average: " +
               (density < 10.0 ? "lighter than foam" : "denser than solid steel") +
               " (the paper's arm: about 200)");
    }
    // Inertia against mass and size: no principal moment exceeds all the
    // mass at the far end of the envelope, m ((L/2)^2 + (2 r_h)^2), and a
    // rigid body's moments satisfy the triangle inequality.
    const Eigen::Vector3d& I = s.link_inertia_kgm2;
    const double most = s.link_mass_kg * (std::pow(0.5 * s.link_length_m, 2) +
                                          std::pow(2.0 * s.hole_circle_radius_m, 2));
    if (I.maxCoeff() > most) {
      warn(p + "link_inertia_kgm2",
           "a principal moment of " + text(I.maxCoeff()) + " kg m^2 exceeds " + text(most) +
               ", all of the link's mass at the far end of its envelope: check the units");
    } else if (I[0] + I[1] < I[2] || I[1] + I[2] < I[0] || I[2] + I[0] < I[1]) {
      warn(p + "link_inertia_kgm2",
           "the principal moments break the triangle inequality (each at most the sum of the "
           "other two): no rigid body has them");
    }
  }
  // Stiffness against pre-tension: the strain a cable's pre-tension gives
  // it. The paper's is 0.3 %; above 2 % a steel cable has yielded (at about
  // 0.5 %) and a fibre rope is near its breaking strain (3-4 %).
  const auto strain = [&](const std::string& key, double tension, double youngs, double area,
                          const std::string& which) {
    const double e = tension / (youngs * area);
    if (e > 0.02) {
      warn(key, "the pre-tension " + text(tension) + " N stretches the " + which + " by " +
                    text(100.0 * e) + " % (E A = " + text(youngs * area) +
                    " N): beyond the elastic range of any cable (steel yields near 0.5 %, fibre "
                    "ropes break near 3 %; the paper's 0.3 %)");
    }
  };
  strain("driving_cables.pretension_n", c.parameters.T_d0, c.arm.driving.youngs_modulus_pa,
         c.arm.driving.cross_section_m2, "driving cables");
  strain("connecting_cables.pretension_n", c.parameters.T_p, c.arm.connecting.youngs_modulus_pa,
         c.arm.connecting.cross_section_m2, "connecting cables");
  return warnings;
}

void CheckSolver(const SolverConfig& s, const Checker& check) {
  // Stabilisation up to 1000 times the paper's 100 /s: past it the time
  // constant 1/alpha is below 10 us, shorter than any step the integrator
  // takes on such arms, and alpha^2 swamps the augmented mass matrix (at
  // 1e300 it is singular at t = 0). beta likewise, as alpha^2.
  check.InRange("solver.baumgarte_alpha_per_s", s.baumgarte_alpha_per_s, 0.0, 1e5, "/s");
  check.InRange("solver.baumgarte_beta_per_s2", s.baumgarte_beta_per_s2, 0.0, 1e10, "/s^2");
  // h smooths each friction switch over that time (the paper's 0.01 s);
  // beyond 1 s, the arm's slowest mode period, it would average a whole
  // move away.
  check.InRange("solver.smoothing_step_s", s.smoothing_step_s, 0.0, 1.0, "s");
  if (s.hole_friction == HoleFrictionModel::kSmoothed && !(s.smoothing_step_s > 0.0)) {
    // The stick band's slope, T mu' theta / v_eps ~ 1e6 N s/m against a
    // node mass of 1e-4 kg, is integrable explicitly only when smoothed.
    check.Fail("solver.hole_friction", "smoothed needs solver.smoothing_step_s > 0");
  }
  if (s.hole_friction == HoleFrictionModel::kPresliding && !(s.smoothing_step_s > 0.0)) {
    // Likewise the presliding spring, ~1e5 N/m against the same mass.
    check.Fail("solver.hole_friction", "presliding needs solver.smoothing_step_s > 0");
  }
  if (s.conduit_friction == ConduitFrictionModel::kPresliding && !(s.smoothing_step_s > 0.0)) {
    // The conduits' presliding spring against a link's inertia.
    check.Fail("solver.conduit_friction", "presliding needs solver.smoothing_step_s > 0");
  }
  check.Positive("solver.stick_velocity_tolerance_mps", s.stick_velocity_tolerance_mps);
  check.Positive("solver.stick_force_tolerance_n", s.stick_force_tolerance_n);
  check.Positive("solver.large_s_static_velocity_mps", s.large_s_static_velocity_mps);
  check.InRange("solver.relative_tolerance", s.relative_tolerance, 1e-14, 1e-1);
  check.InRange("solver.absolute_tolerance", s.absolute_tolerance, 1e-16, 1e-1);
  check.InRange("solver.velocity_tolerance_time_s", s.velocity_tolerance_time_s, 1e-6, 1e3);
  check.Positive("solver.initial_step_s", s.initial_step_s);
  check.Positive("solver.max_step_s", s.max_step_s);
  check.Positive("solver.min_step_s", s.min_step_s);
  if (!(s.min_step_s < s.initial_step_s && s.initial_step_s <= s.max_step_s)) {
    check.Fail("solver.initial_step_s", "must satisfy min_step_s < initial_step_s <= max_step_s");
  }
  check.Positive("solver.switch_time_tolerance_s", s.switch_time_tolerance_s);
  check.Positive("solver.max_constraint_violation", s.max_constraint_violation);
  check.InRange("solver.output_rate_hz", s.output_rate_hz, 1e-3, 1e5);
}

void CheckProtocol(const ProtocolConfig& pr, const Checker& check);

void ValidateWithLines(const Config& c, const LineMap* lines) {
  const Checker check(c.source_name, lines);
  CheckArm(c.arm, check);
  CheckArmRanges(c.arm, check);
  CheckCableLayout(c.arm, check);
  // The identifiable parameters: the same table and message as --set and --params.
  for (const ParameterInfo& p : Parameters()) {
    const std::string problem = ParameterValueProblem(p, c.parameters.*p.field);
    if (!problem.empty()) check.Fail(p.config_key, problem);
  }
  // The parameters' per-joint and per-cable lists are this arm's (an arm
  // edited in code after LoadConfig must say so: parameters.arm = arm.size()).
  if (c.parameters.arm != c.arm.size()) {
    check.Fail("effects",
               "the parameters are sized for an arm of " + std::to_string(c.parameters.arm.joints) +
                   " joints and " + std::to_string(c.parameters.arm.cables) +
                   " driving cables, the arm has " + std::to_string(c.arm.size().joints) + " and " +
                   std::to_string(c.arm.size().cables));
  }
  // Effect parameters, by their key under `effects:`.
  for (const auto& [name, value] : c.parameters.effect_values) {
    const ParameterInfo& p = FindParameter(name, c.source_name, c.arm.size());
    const std::string problem = ParameterValueProblem(p, value);
    if (!problem.empty()) check.Fail(p.config_key, problem);
  }
  std::string problem;
  if (!c.parameters.IsValid(&problem)) check.Fail("effects", problem);
  CheckSolver(c.solver, check);
  CheckProtocol(c.protocol, check);
}

void CheckProtocol(const ProtocolConfig& pr, const Checker& check) {
  check.InRange("protocol.amplitude_deg", pr.amplitude_rad / kDegToRad, -60.0, 60.0);
  // Each phase at most 1e5 s (28 h): longer is no experiment, and a run of
  // the protocol's length would not end (1e7 frames at 100 Hz).
  check.Positive("protocol.ramp_s", pr.ramp_s);
  check.Positive("protocol.return_s", pr.return_s);
  for (const auto& [key, value] : {std::pair<const char*, double>{"protocol.ramp_s", pr.ramp_s},
                                   {"protocol.hold_s", pr.hold_s},
                                   {"protocol.return_s", pr.return_s},
                                   {"protocol.rest_s", pr.rest_s}}) {
    check.InRange(key, value, 0.0, 1e5, "s");
  }
}

}  // namespace

int ArmConfig::total_links() const {
  int n = 0;
  for (const auto& s : segments) n += s.links;
  return n;
}

ArmSize ArmConfig::size() const {
  return ArmSize{total_links(), static_cast<int>(driving.cables.size()),
                 static_cast<int>(segments.size())};
}

int ArmConfig::segment_of_link(int link) const {
  int last = 0;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    last += segments[i].links;
    if (link <= last) return static_cast<int>(i);
  }
  return -1;
}

double BackboneGeometry::bending_stiffness_nm2() const {
  const double d4 = std::pow(outer_diameter_m, 4) - std::pow(inner_diameter_m, 4);
  return youngs_modulus_pa * kPi * d4 / 64.0;
}

bool SegmentConfig::uses(ConnectingKind kind) const {
  return std::find(connecting_pattern.begin(), connecting_pattern.end(), kind) !=
         connecting_pattern.end();
}

const std::string& ConnectingWord(ConnectingKind kind) {
  return kConnectingWords.at(static_cast<std::size_t>(kind));
}

const std::string& HoleFrictionWord(HoleFrictionModel model) {
  return kHoleFrictionWords.at(static_cast<std::size_t>(model));
}

const std::string& ConduitFrictionWord(ConduitFrictionModel model) {
  return kConduitFrictionWords.at(static_cast<std::size_t>(model));
}

Config ParseConfig(const std::string& yaml_text, const std::string& source_name) {
  const YAML::Node root = ParseYamlDocument(yaml_text, source_name);
  if (!root.IsMap()) ThrowInputError(source_name, "", "expected a YAML mapping at the top level");

  LineMap lines;
  Config c;
  c.source_name = source_name;
  c.source_yaml = yaml_text;
  MapReader top(root, "", source_name, &lines);
  bool has_conduit_stribeck = false;  // connecting_cables.stribeck_velocity_mps given

  const std::string schema = top.String("schema");
  if (schema != kSchema) {
    top.Fail("schema", root["schema"],
             "expected '" + std::string(kSchema) + "', found '" + schema + "'");
  }

  {
    MapReader arm = top.Section("arm");
    c.arm.joint_disk_gap_m = arm.Number("joint_disk_gap_m");
    c.arm.gravity_mps2 = arm.Vector3("gravity_mps2");
    arm.ForEach("segments", [&](MapReader& s, int) {
      SegmentConfig seg;
      seg.name = s.String("name");
      seg.links = s.Integer("links");
      seg.link_length_m = s.Number("link_length_m");
      seg.link_mass_kg = s.Number("link_mass_kg");
      seg.link_inertia_kgm2 = s.Vector3("link_inertia_kgm2");
      seg.hole_circle_radius_m = s.Number("hole_circle_radius_m");
      for (int kind : s.WordList("connecting_pattern", kConnectingWords)) {
        seg.connecting_pattern.push_back(static_cast<ConnectingKind>(kind));
      }
      // A mechanism's geometry is needed where the pattern has it.
      if (seg.uses(ConnectingKind::kSmallS) || s.Has("small_s")) {
        MapReader small = s.Section("small_s");
        seg.small_s.cable_length_m = small.Number("cable_length_m");
        seg.small_s.pulley_radius_m = small.Number("pulley_radius_m");
        small.Finish();
      }
      if (seg.uses(ConnectingKind::kLargeS) || s.Has("large_s")) {
        MapReader large = s.Section("large_s");
        seg.large_s.cable_length_m = large.Number("cable_length_m");
        seg.large_s.pulley_radius_m = large.Number("pulley_radius_m");
        seg.large_s.wrap_angle_rad = large.Number("wrap_angle_deg") * kDegToRad;
        large.Finish();
      }
      if (s.Has("backbone")) {
        MapReader rod = s.Section("backbone");
        seg.backbone.youngs_modulus_pa = rod.Number("youngs_modulus_pa");
        seg.backbone.outer_diameter_m = rod.Number("outer_diameter_m");
        seg.backbone.inner_diameter_m = rod.OptionalNumber("inner_diameter_m", 0.0);
        if (!(seg.backbone.youngs_modulus_pa > 0.0)) {
          rod.Fail("youngs_modulus_pa", rod.Node("youngs_modulus_pa"), "must be > 0");
        }
        rod.Finish();
      }
      c.arm.segments.push_back(seg);
    });
    arm.Finish();
  }
  {
    MapReader d = top.Section("driving_cables");
    DrivingCableConfig& dc = c.arm.driving;
    dc.youngs_modulus_pa = d.Number("youngs_modulus_pa");
    dc.cross_section_m2 = d.Number("cross_section_m2");
    dc.density_kgpm3 = d.Number("density_kgpm3");
    ReadParameters(d, &c.parameters);
    dc.input_offset_m = d.Number("input_offset_m");
    d.ForEach("cables", [&](MapReader& cable, int) {
      DrivingCableRoute route;
      route.segment = cable.Integer("segment");
      route.hole_angle_rad = cable.Number("hole_angle_deg") * kDegToRad;
      dc.cables.push_back(route);
    });
    d.Finish();
    // The effects' per-joint and per-cable parameters are this arm's.
    c.parameters.arm = c.arm.size();
  }
  {
    MapReader k = top.Section("connecting_cables");
    ConnectingCableConfig& cc = c.arm.connecting;
    cc.youngs_modulus_pa = k.Number("youngs_modulus_pa");
    cc.cross_section_m2 = k.Number("cross_section_m2");
    has_conduit_stribeck = k.Has("stribeck_velocity_mps");
    ReadParameters(k, &c.parameters);
    k.Finish();
  }
  // The elastic backbone's parameters: optional, as an arm without one
  // (every CCSRM) has nothing for them to act on.
  if (top.Has("backbone")) {
    MapReader b = top.Section("backbone");
    ReadParameters(b, &c.parameters);
    b.Finish();
  } else {
    for (const ParameterInfo& p : Parameters()) {
      if (p.config_key.rfind("backbone.", 0) == 0) c.parameters.*p.field = p.absent_value;
    }
  }
  {
    MapReader s = top.Section("solver");
    SolverConfig& sc = c.solver;
    sc.hole_friction =
        static_cast<HoleFrictionModel>(s.OptionalWord("hole_friction", kHoleFrictionWords, 0));
    sc.conduit_friction = static_cast<ConduitFrictionModel>(
        s.OptionalWord("conduit_friction", kConduitFrictionWords, 0));
    sc.baumgarte_alpha_per_s = s.Number("baumgarte_alpha_per_s");
    sc.baumgarte_beta_per_s2 = s.Number("baumgarte_beta_per_s2");
    sc.smoothing_step_s = s.Number("smoothing_step_s");
    sc.smooth_connecting_friction = s.Boolean("smooth_connecting_friction");
    sc.smooth_connecting_elasticity = s.Boolean("smooth_connecting_elasticity");
    sc.smooth_presliding_relaxation = s.OptionalBoolean("smooth_presliding_relaxation", true);
    sc.embed_cable_nodes = s.OptionalBoolean("embed_cable_nodes", true);
    sc.stepper = static_cast<RungeKuttaStepper>(s.OptionalWord("stepper", kStepperWords, 0));
    sc.stick_velocity_tolerance_mps = s.Number("stick_velocity_tolerance_mps");
    sc.stick_force_tolerance_n = s.Number("stick_force_tolerance_n");
    sc.large_s_static_velocity_mps = s.Number("large_s_static_velocity_mps");
    // Before the conduits had a Stribeck velocity (v_c_s), the paper's v_d
    // closed their static-to-kinetic fall: such a file means v_c_s = v_d - v_s.
    const double legacy_v_d =
        s.OptionalNumber("large_s_dynamic_velocity_mps", std::numeric_limits<double>::quiet_NaN());
    if (!std::isnan(legacy_v_d)) {
      if (has_conduit_stribeck) {
        s.Fail("solver.large_s_dynamic_velocity_mps", s.Node("large_s_dynamic_velocity_mps"),
               "replaced by connecting_cables.stribeck_velocity_mps; give only that");
      }
      const double width = legacy_v_d - sc.large_s_static_velocity_mps;
      if (!(width > 0.0)) {
        s.Fail("solver.large_s_dynamic_velocity_mps", s.Node("large_s_dynamic_velocity_mps"),
               "must exceed solver.large_s_static_velocity_mps");
      }
      c.parameters.v_c_s = width;
    }
    sc.relative_tolerance = s.Number("relative_tolerance");
    sc.absolute_tolerance = s.Number("absolute_tolerance");
    sc.velocity_tolerance_time_s = s.Number("velocity_tolerance_time_s");
    sc.initial_step_s = s.Number("initial_step_s");
    sc.max_step_s = s.Number("max_step_s");
    sc.min_step_s = s.Number("min_step_s");
    sc.switch_time_tolerance_s = s.Number("switch_time_tolerance_s");
    sc.max_constraint_violation = s.Number("max_constraint_violation");
    sc.output_rate_hz = s.Number("output_rate_hz");
    s.Finish();
  }
  {
    MapReader p = top.Section("protocol");
    ProtocolConfig& pc = c.protocol;
    pc.amplitude_rad = p.Number("amplitude_deg") * kDegToRad;
    pc.ramp_s = p.Number("ramp_s");
    pc.hold_s = p.Number("hold_s");
    pc.return_s = p.Number("return_s");
    pc.rest_s = p.Number("rest_s");
    p.Finish();
  }
  // Optional: the effects that are on and their values (ccsrm/sim/effects.h).
  const YAML::Node effects = top.OptionalNode("effects");
  if (effects.IsDefined()) {
    internal::ApplyEffectsNode(effects, source_name, "effects.", &c.parameters);
  }
  top.Finish();
  ValidateWithLines(c, &lines);
  c.warnings = ArmWarnings(c, &lines);
  return c;
}

Config LoadConfig(const std::string& path) { return ParseConfig(ReadTextFile(path), path); }

void Validate(const Config& config) { ValidateWithLines(config, nullptr); }

void ValidateArm(const ArmConfig& arm, const std::string& source_name) {
  CheckArm(arm, Checker(source_name, nullptr));
}

void ValidateSolver(const SolverConfig& solver, const std::string& source_name) {
  CheckSolver(solver, Checker(source_name, nullptr));
}

void ValidateProtocol(const ProtocolConfig& protocol, const std::string& source_name) {
  CheckProtocol(protocol, Checker(source_name, nullptr));
}

std::string ToYaml(const Config& c) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  auto vec3 = [&](const Eigen::Vector3d& v) {
    out << YAML::Flow << YAML::BeginSeq << v[0] << v[1] << v[2] << YAML::EndSeq;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "schema" << YAML::Value << kSchema;
  out << YAML::Key << "arm" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "joint_disk_gap_m" << YAML::Value << c.arm.joint_disk_gap_m;
  out << YAML::Key << "gravity_mps2" << YAML::Value;
  vec3(c.arm.gravity_mps2);
  out << YAML::Key << "segments" << YAML::Value << YAML::BeginSeq;
  for (const SegmentConfig& s : c.arm.segments) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    out << YAML::Key << "links" << YAML::Value << s.links;
    out << YAML::Key << "link_length_m" << YAML::Value << s.link_length_m;
    out << YAML::Key << "link_mass_kg" << YAML::Value << s.link_mass_kg;
    out << YAML::Key << "link_inertia_kgm2" << YAML::Value;
    vec3(s.link_inertia_kgm2);
    out << YAML::Key << "hole_circle_radius_m" << YAML::Value << s.hole_circle_radius_m;
    out << YAML::Key << "connecting_pattern" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (ConnectingKind k : s.connecting_pattern) out << ConnectingWord(k);
    out << YAML::EndSeq;
    if (s.uses(ConnectingKind::kSmallS)) {
      out << YAML::Key << "small_s" << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "cable_length_m" << YAML::Value << s.small_s.cable_length_m;
      out << YAML::Key << "pulley_radius_m" << YAML::Value << s.small_s.pulley_radius_m;
      out << YAML::EndMap;
    }
    if (s.uses(ConnectingKind::kLargeS)) {
      out << YAML::Key << "large_s" << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "cable_length_m" << YAML::Value << s.large_s.cable_length_m;
      out << YAML::Key << "pulley_radius_m" << YAML::Value << s.large_s.pulley_radius_m;
      out << YAML::Key << "wrap_angle_deg" << YAML::Value << s.large_s.wrap_angle_rad / kDegToRad;
      out << YAML::EndMap;
    }
    if (s.backbone.present()) {
      out << YAML::Key << "backbone" << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "youngs_modulus_pa" << YAML::Value << s.backbone.youngs_modulus_pa;
      out << YAML::Key << "outer_diameter_m" << YAML::Value << s.backbone.outer_diameter_m;
      out << YAML::Key << "inner_diameter_m" << YAML::Value << s.backbone.inner_diameter_m;
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;

  const DrivingCableConfig& d = c.arm.driving;
  out << YAML::Key << "driving_cables" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "youngs_modulus_pa" << YAML::Value << d.youngs_modulus_pa;
  out << YAML::Key << "cross_section_m2" << YAML::Value << d.cross_section_m2;
  out << YAML::Key << "density_kgpm3" << YAML::Value << d.density_kgpm3;
  WriteParameters("driving_cables", c.parameters, &out);
  out << YAML::Key << "input_offset_m" << YAML::Value << d.input_offset_m;
  out << YAML::Key << "cables" << YAML::Value << YAML::BeginSeq;
  for (const DrivingCableRoute& r : d.cables) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "segment" << YAML::Value << r.segment
        << YAML::Key << "hole_angle_deg" << YAML::Value << r.hole_angle_rad / kDegToRad
        << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;

  const ConnectingCableConfig& cc = c.arm.connecting;
  out << YAML::Key << "connecting_cables" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "youngs_modulus_pa" << YAML::Value << cc.youngs_modulus_pa;
  out << YAML::Key << "cross_section_m2" << YAML::Value << cc.cross_section_m2;
  WriteParameters("connecting_cables", c.parameters, &out);
  out << YAML::EndMap;
  // Only for an arm with a backbone, so that every other writes back as before.
  bool has_backbone = false;
  for (const SegmentConfig& s : c.arm.segments) has_backbone |= s.backbone.present();
  if (has_backbone) {
    out << YAML::Key << "backbone" << YAML::Value << YAML::BeginMap;
    WriteParameters("backbone", c.parameters, &out);
    out << YAML::EndMap;
  }

  const SolverConfig& s = c.solver;
  out << YAML::Key << "solver" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "hole_friction" << YAML::Value
      << kHoleFrictionWords[static_cast<int>(s.hole_friction)];
  out << YAML::Key << "conduit_friction" << YAML::Value
      << kConduitFrictionWords[static_cast<int>(s.conduit_friction)];
  out << YAML::Key << "baumgarte_alpha_per_s" << YAML::Value << s.baumgarte_alpha_per_s;
  out << YAML::Key << "baumgarte_beta_per_s2" << YAML::Value << s.baumgarte_beta_per_s2;
  out << YAML::Key << "smoothing_step_s" << YAML::Value << s.smoothing_step_s;
  out << YAML::Key << "smooth_connecting_friction" << YAML::Value << s.smooth_connecting_friction;
  out << YAML::Key << "smooth_connecting_elasticity" << YAML::Value
      << s.smooth_connecting_elasticity;
  out << YAML::Key << "smooth_presliding_relaxation" << YAML::Value
      << s.smooth_presliding_relaxation;
  out << YAML::Key << "embed_cable_nodes" << YAML::Value << s.embed_cable_nodes;
  out << YAML::Key << "stepper" << YAML::Value << kStepperWords[static_cast<int>(s.stepper)];
  out << YAML::Key << "stick_velocity_tolerance_mps" << YAML::Value
      << s.stick_velocity_tolerance_mps;
  out << YAML::Key << "stick_force_tolerance_n" << YAML::Value << s.stick_force_tolerance_n;
  out << YAML::Key << "large_s_static_velocity_mps" << YAML::Value << s.large_s_static_velocity_mps;
  out << YAML::Key << "relative_tolerance" << YAML::Value << s.relative_tolerance;
  out << YAML::Key << "absolute_tolerance" << YAML::Value << s.absolute_tolerance;
  out << YAML::Key << "velocity_tolerance_time_s" << YAML::Value << s.velocity_tolerance_time_s;
  out << YAML::Key << "initial_step_s" << YAML::Value << s.initial_step_s;
  out << YAML::Key << "max_step_s" << YAML::Value << s.max_step_s;
  out << YAML::Key << "min_step_s" << YAML::Value << s.min_step_s;
  out << YAML::Key << "switch_time_tolerance_s" << YAML::Value << s.switch_time_tolerance_s;
  out << YAML::Key << "max_constraint_violation" << YAML::Value << s.max_constraint_violation;
  out << YAML::Key << "output_rate_hz" << YAML::Value << s.output_rate_hz;
  out << YAML::EndMap;

  const ProtocolConfig& p = c.protocol;
  out << YAML::Key << "protocol" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "amplitude_deg" << YAML::Value << p.amplitude_rad / kDegToRad;
  out << YAML::Key << "ramp_s" << YAML::Value << p.ramp_s;
  out << YAML::Key << "hold_s" << YAML::Value << p.hold_s;
  out << YAML::Key << "return_s" << YAML::Value << p.return_s;
  out << YAML::Key << "rest_s" << YAML::Value << p.rest_s;
  out << YAML::EndMap;
  // Only when an effect is on, so that a configuration without effects
  // writes back as before.
  if (c.parameters.AnyEffectOn()) {
    out << YAML::Key << "effects" << YAML::Value << YAML::BeginMap;
    for (const EffectInfo& e : Effects()) {
      if (!c.parameters.EffectOn(e.name)) continue;
      out << YAML::Key << e.name << YAML::Value << YAML::BeginMap;
      for (const std::string& name : EffectParameterNames(e.name, c.parameters.arm)) {
        out << YAML::Key << name.substr(e.name.size() + 1) << YAML::Value
            << GetParameter(c.parameters, name);
      }
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace ccsrm::sim
