// ccsrm config check FILE
#include <cstdio>
#include <string>

#include "ccsrm/sim/config.h"
#include "ccsrm/sim/effects.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "commands.h"

namespace ccsrm::app {
namespace {

void RunConfigCheck(const std::string& path) {
  const sim::Config c = sim::LoadConfig(path);
  // The model holds the cable routing; count its hole nodes rather than
  // re-deriving the layout here.
  const sim::ArmModel model(c.arm);
  int holes = 0;
  for (const auto& cable : model.cables()) holes += cable.num_holes();
  // Far outside the range of such arms: said, with the reason, not refused.
  if (c.warnings.empty()) {
    std::printf("%s: ok\n", path.c_str());
  } else {
    std::printf("%s: ok, %zu warning%s\n", path.c_str(), c.warnings.size(),
                c.warnings.size() == 1 ? "" : "s");
  }
  for (const std::string& w : c.warnings) std::printf("  warning: %s\n", w.c_str());
  std::printf("  segments: %zu, links: %d, universal joints: %d\n", c.arm.segments.size(),
              c.arm.total_links(), c.arm.total_links());
  for (const auto& s : c.arm.segments) {
    std::string pattern;
    for (auto k : s.connecting_pattern) {
      pattern += pattern.empty() ? "" : "-";
      pattern += sim::ConnectingWord(k);
    }
    std::printf("  %s: %d links of %.4g m, %.4g kg, holes at r = %.4g m, pattern %s\n",
                s.name.c_str(), s.links, s.link_length_m, s.link_mass_kg, s.hole_circle_radius_m,
                pattern.c_str());
    if (s.backbone.present()) {
      std::printf("    elastic backbone: E I = %.4g N m^2, %.4g N m/rad per joint (k_b = %.4g)\n",
                  s.backbone.bending_stiffness_nm2(),
                  c.parameters.k_b * s.backbone.bending_stiffness_nm2() / s.link_length_m,
                  c.parameters.k_b);
    }
  }
  std::printf("  driving cables: %zu (%d hole nodes)\n", c.arm.driving.cables.size(), holes);
  std::string parameters;
  for (const sim::ParameterInfo& p : sim::Parameters()) {
    char item[64];
    std::snprintf(item, sizeof(item), "%s%s %.4g", parameters.empty() ? "" : ", ", p.name.c_str(),
                  c.parameters.*p.field);
    parameters += item;
  }
  std::printf("  parameters: %s\n", parameters.c_str());
  // Effects: which are on, with every parameter's value (defaults included).
  const std::vector<std::string> effects = c.parameters.EnabledEffects();
  if (effects.empty()) std::printf("  effects: none on\n");
  for (const std::string& effect : effects) {
    std::string values;
    for (const std::string& name : sim::EffectParameterNames(effect, c.parameters.arm, path)) {
      char item[96];
      std::snprintf(item, sizeof(item), "%s%s %.4g", values.empty() ? "" : ", ",
                    name.substr(effect.size() + 1).c_str(), sim::GetParameter(c.parameters, name));
      values += item;
    }
    std::printf("  effect on: %s (%s)\n", effect.c_str(), values.c_str());
  }
  std::printf(
      "  structure: hole friction %s, conduit friction %s, connecting friction smoothing %s\n",
      sim::HoleFrictionWord(c.solver.hole_friction).c_str(),
      sim::ConduitFrictionWord(c.solver.conduit_friction).c_str(),
      c.solver.smooth_connecting_friction ? "on" : "off");
  std::printf("  protocol: amplitude %.4g deg over %.4g s; solver: h = %.4g s, output %.4g Hz\n",
              c.protocol.amplitude_rad * 180.0 / 3.14159265358979323846, c.protocol.duration_s(),
              c.solver.smoothing_step_s, c.solver.output_rate_hz);
}

}  // namespace

void AddConfigCommands(CLI::App& root) {
  CLI::App* config = root.add_subcommand("config", "Check arm configuration files");
  config->require_subcommand(1);
  CLI::App* check = config->add_subcommand(
      "check", "Parse and validate a YAML configuration; print what it describes");
  auto path = std::make_shared<std::string>();
  check->add_option("FILE", *path, "Configuration file (YAML)")->required();
  check->callback([path] { RunConfigCheck(*path); });
}

}  // namespace ccsrm::app
