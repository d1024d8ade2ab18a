// The design page (`ccsrm report --in design/`): a design folder written by
// the design's own writers (identify::ToJson, identify::PlannedMotionCsv)
// shows every number of design.json, draws the proposed motion from
// proposed.inputs.csv, and a broken folder is named in one line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/identify/design.h"
#include "ccsrm/reports/report.h"
#include "ccsrm/sim/config.h"
#include "report_test_util.h"
#include "run_ccsrm.h"

namespace ccsrm::reports {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

sim::Config PaperArm() {
  return sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
}

// A reversal motion of 6 s on the paper's arm, as ProposeDesign writes it.
std::string ProposedYaml(std::string* name) {
  identify::ProposalSpace space;
  space.budget_s = 6.0;
  identify::ProposedMotion motion;
  motion.amplitude_deg = 10.0;
  motion.move_s = 2.0;
  motion.opposed = true;
  return identify::ProposalProtocolYaml(motion, space, 2, name);
}

identify::CandidateInformation Candidate(const std::string& name, const std::string& yaml,
                                         std::vector<double> relative) {
  identify::CandidateInformation c;
  c.name = name;
  c.protocol_yaml = yaml;
  c.experiments = {name};
  c.duration_s = 6.0;
  c.samples = 14424;
  c.completed = true;
  c.parameters = {"mu_c", "T_p"};
  c.prior = {0.21, 50.0};
  c.relative_std_error = relative;
  for (std::size_t i = 0; i < 2; ++i) c.std_error.push_back(relative[i] * c.prior[i]);
  const bool first = relative[0] >= relative[1];
  c.worst_relative_std_error = std::max(relative[0], relative[1]);
  c.worst_parameter = first ? "mu_c" : "T_p";
  c.d_criterion = std::sqrt(relative[0] * relative[1]);
  c.a_criterion = std::sqrt(0.5 * (relative[0] * relative[0] + relative[1] * relative[1]));
  c.worst_direction_relative_std_error = 1.01 * c.worst_relative_std_error;
  c.worst_direction = {{"mu_c", 0.94}, {"T_p", -0.35}};
  c.fisher_relative = Eigen::Matrix2d::Identity();
  c.robust_worst_relative_std_error = c.worst_relative_std_error;
  c.simulations = 5;
  return c;
}

// Two plans: the paper's protocol (given) and a proposed reversal motion,
// evaluated at both corners of a box on mu_c.
fs::path WriteDesignFolder(const std::string& name) {
  identify::DesignSummary s;
  s.options.free_parameters = {"mu_c", "T_p"};
  s.options.noise_deg = 0.026;
  s.options.effective_sample_fraction = 0.016;
  s.options.prior_box = {{"mu_c", 0.17, 0.25}};
  s.options.robust_candidates = 1;
  std::string proposed_name;
  const std::string yaml = ProposedYaml(&proposed_name);
  s.candidates.push_back(Candidate("paper.yaml@amplitude_deg=6", "", {0.186, 0.00309}));
  s.candidates.push_back(Candidate(proposed_name, yaml, {0.00311, 0.00206}));
  identify::CandidateInformation& best = s.candidates[1];
  for (const double mu_c : {0.17, 0.25}) {
    identify::CornerInformation corner;
    corner.values = {{"mu_c", mu_c}};
    corner.completed = true;
    corner.relative_std_error = {mu_c == 0.17 ? 0.00452 : 0.00270, 0.00215};
    corner.worst_relative_std_error = corner.relative_std_error[0];
    corner.worst_parameter = "mu_c";
    best.corners.push_back(corner);
  }
  best.robust_worst_relative_std_error = 0.00452;
  // The best plan's derivatives checked and smooth; the paper's checked and
  // not (ranked last).
  best.derivative_step_disagreement = {0.0084, 0.0021};
  s.candidates[0].derivative_step_disagreement = {0.104, 0.0021};
  s.ranking = {1, 0};
  s.threads = 2;
  s.simulations = 30;
  s.wall_time_s = 45.6;
  const fs::path dir = ccsrm::testing::ScratchDirectory("design_page_" + name);
  const sim::Config prior = PaperArm();
  json design = identify::ToJson(s);
  design["config_yaml"] = prior.source_yaml;
  WriteTextFileAtomically((dir / "design.json").string(), design.dump(2));
  WriteTextFileAtomically((dir / "proposed.inputs.csv").string(),
                          identify::PlannedMotionCsv(prior, yaml, proposed_name, 20.0));
  return dir;
}

TEST(DesignPage, ShowsEveryNumberOfTheDesignAndDrawsTheProposedMotion) {
  if (!testing::ProgramOnPath("gnuplot")) GTEST_SKIP() << "gnuplot not installed";
  const fs::path dir = WriteDesignFolder("written");
  const fs::path out = dir.parent_path() / "design_page_written_report";
  fs::remove_all(out);  // an earlier run's page, perhaps of an older ccsrm
  const ReportSummary summary = MakeReport(dir.string(), out.string(), ReportOptions());
  EXPECT_EQ(summary.kind, "design");
  const std::string html = ReadTextFile((out / "index.html").string());
  const json report = json::parse(ReadTextFile((out / "summary.json").string()));
  // Design run (9 rows), candidates (2 × 12 columns), corners (2 rows).
  EXPECT_GT(testing::ExpectTablesMatchJson(html, report), 25);
  const json& candidates = report["tables"]["candidates"]["rows"];
  ASSERT_EQ(candidates.size(), 2u);
  EXPECT_EQ(candidates[0]["kind"], "proposed");
  EXPECT_DOUBLE_EQ(candidates[0]["rse_mu_c"].get<double>(), 0.311);  // %, 3 digits
  EXPECT_DOUBLE_EQ(candidates[0]["robust_worst"].get<double>(), 0.452);
  EXPECT_TRUE(candidates[1]["robust_worst"].is_null());  // not evaluated at the corners
  EXPECT_EQ(report["tables"]["corners"]["rows"].size(), 2u);
  // 0.186 / 0.00311: the factor the summary states.
  EXPECT_THAT(html, HasSubstr("59.8 times smaller"));
  EXPECT_THAT(html, HasSubstr("smooth (largest disagreement mu_c, 0.84 %)"));
  EXPECT_THAT(html, HasSubstr("NOT smooth in mu_c 10.4 %"));
  // Errors side by side, which parameter each informs, the planned θx
  // (the motion has no θy), cable speeds and lengths.
  EXPECT_EQ(summary.figures, 5);
  int files = 0;
  for (const std::string& ref : testing::HtmlReferences(html)) {
    if (ref.rfind("#", 0) == 0) continue;
    EXPECT_TRUE(fs::is_regular_file(out / ref)) << ref;
    ++files;
  }
  EXPECT_EQ(files, 1 + summary.figures);
  // The planned θx reaches ±10° (the motion's amplitude) on both segments.
  const std::string dat = ReadTextFile((out / "figures" / "proposed_theta_x.dat").string());
  EXPECT_THAT(dat, HasSubstr(" 10\n"));
  EXPECT_THAT(dat, HasSubstr(" -10\n"));
}

std::string ErrorOf(const fs::path& dir) {
  try {
    BuildDesignDocument(dir.string(), ReportOptions());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(DesignPage, BrokenDesignFoldersAreNamedInOneLine) {
  const fs::path empty = ccsrm::testing::ScratchDirectory("design_page_empty");
  EXPECT_EQ(ErrorOf(empty), empty.string() + ": not a design folder (no design.json)");

  const fs::path missing = WriteDesignFolder("missing");
  json design = json::parse(ReadTextFile((missing / "design.json").string()));
  design["candidates"][1].erase("corners");
  WriteTextFileAtomically((missing / "design.json").string(), design.dump());
  EXPECT_EQ(ErrorOf(missing),
            (missing / "design.json").string() + ": key 'candidates[1].corners': missing");

  const fs::path ranking = WriteDesignFolder("ranking");
  design = json::parse(ReadTextFile((ranking / "design.json").string()));
  design["ranking"] = {1, 1};
  WriteTextFileAtomically((ranking / "design.json").string(), design.dump());
  EXPECT_THAT(ErrorOf(ranking), HasSubstr("key 'ranking': expected each candidate's index once"));

  const fs::path check = WriteDesignFolder("check");
  design = json::parse(ReadTextFile((check / "design.json").string()));
  design["candidates"][0]["derivative_step_disagreement"] = {0.1};
  WriteTextFileAtomically((check / "design.json").string(), design.dump());
  EXPECT_THAT(ErrorOf(check), HasSubstr("key 'candidates[0].derivative_step_disagreement': "
                                        "expected one entry per free parameter"));

  const fs::path csv = WriteDesignFolder("csv");
  std::string text = ReadTextFile((csv / "proposed.inputs.csv").string());
  text.replace(text.rfind(",0"), 2, ",x");
  WriteTextFileAtomically((csv / "proposed.inputs.csv").string(), text);
  const std::string error = ErrorOf(csv);
  EXPECT_THAT(error, HasSubstr("proposed.inputs.csv: line 123, column 'planned_thetay12_deg'"));
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace ccsrm::reports
