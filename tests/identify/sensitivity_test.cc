// The derivative check and the parameter sweep on short runs whose answers
// the tests compute themselves: the table's derivative is the difference of
// runs made here, thread count and backend change no bit, trial points stay
// inside the bounds, zero and missing derivatives give statuses rather than
// NaN, and the cubic fit is exact for cubics and blind to nothing else.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/sensitivity.h"
#include "ccsrm/identify/simulation_backend.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/model.h"
#include "ccsrm/sim/parameters.h"
#include "ccsrm/sim/protocol.h"
#include "ccsrm/sim/simulator.h"

namespace ccsrm::identify {
namespace {

// The paper's arm, case 2 (friction everywhere), on a protocol compressed to
// a 1.5 s ramp, simulated for 0.3 s: the joints start to move, the cables
// stick and slip, and a run takes a fraction of a second.
struct ShortCase {
  sim::Config config;
  sim::ArmModel model;
  sim::CableInputs inputs;
  sim::SimulationOptions options;
  ShortCase()
      : config(Compressed()),
        model(config.arm),
        inputs(sim::PlanCableInputs(model, sim::PaperTrajectory(model, config.protocol), 0.3)) {
    options.duration_s = 0.3;
    options.solver = config.solver;
  }
  static sim::Config Compressed() {
    sim::Config c = sim::LoadConfig(std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml");
    c.protocol.ramp_s = 1.5;
    c.protocol.hold_s = 0.5;
    return c;
  }
  std::vector<double> Angles(const sim::ArmParameters& p) const {
    const sim::SimulationResult r = sim::Simulate(model, p, inputs, options);
    EXPECT_TRUE(r.summary.completed()) << r.summary.message;
    return SampledJointAnglesDeg(r.trajectory);
  }
  std::size_t SampledAngles() const {
    return 31 * static_cast<std::size_t>(model.num_joints()) * 2;  // 0 .. 0.3 s at 100 Hz
  }
};

const ShortCase& Case2() {
  static const ShortCase c;
  return c;
}

DerivativeCheckOptions Only(std::vector<std::string> names, int threads = 2) {
  DerivativeCheckOptions o;
  o.parameters = std::move(names);
  o.threads = threads;
  return o;
}

const ParameterDerivative& Find(const DerivativeCheckSummary& s, const std::string& name) {
  for (const ParameterDerivative& p : s.parameters) {
    if (p.name == name) return p;
  }
  ADD_FAILURE() << "no row for " << name;
  return s.parameters.front();
}

double Rms(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return std::sqrt(sum / v.size());
}

// Agreement to rounding: the same runs, combined in a different order.
void ExpectSameVector(const std::vector<double>& expected, const std::vector<double>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  double scale = 0.0;
  for (double x : expected) scale = std::max(scale, std::abs(x));
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_NEAR(expected[i], actual[i], 1e-12 * scale) << "sampled angle " << i;
  }
}

// On three threads, against serial runs made here.
TEST(DerivativeCheck, DerivativeIsTheCentralDifferenceOfRunsMadeHere) {
  const ShortCase& c = Case2();
  const sim::ArmParameters& base = c.config.parameters;
  const DerivativeCheckSummary s =
      DerivativeCheck(c.model, base, c.inputs, c.options, Only({"mu"}, 3));
  ASSERT_TRUE(s.all_runs_completed());
  EXPECT_EQ(s.runs, 1u + 2 * 2);
  EXPECT_EQ(s.sampled_angles, c.SampledAngles());
  for (const ParameterDerivative& p : s.parameters) {
    const sim::ParameterInfo& info = sim::FindParameter(p.name, "test");
    ASSERT_EQ(p.steps.size(), 2u);
    std::vector<std::vector<double>> d;
    for (const StepDerivative& step : p.steps) {
      const double r = step.relative_step;
      ASSERT_EQ(step.scheme, DifferenceScheme::kCentral);
      // p (1 -/+ r), up to the rounding of how the product is formed.
      const double value = base.*info.field;
      EXPECT_DOUBLE_EQ(step.trials[0].value, value * (1.0 - r));
      EXPECT_DOUBLE_EQ(step.trials[1].value, value * (1.0 + r));
      sim::ArmParameters minus = base, plus = base;
      minus.*info.field = step.trials[0].value;
      plus.*info.field = step.trials[1].value;
      const std::vector<double> f_minus = c.Angles(minus), f_plus = c.Angles(plus);
      std::vector<double> expected(f_plus.size());
      // d = p dθ/dp = p (θ+ - θ-) / (2 r p) [deg per unit relative change].
      for (std::size_t i = 0; i < expected.size(); ++i) {
        expected[i] = (f_plus[i] - f_minus[i]) / (2.0 * r);
      }
      ExpectSameVector(expected, step.derivative_deg);
      EXPECT_NEAR(step.rms_deg, Rms(expected), 1e-12 * Rms(expected));
      EXPECT_GT(step.rms_deg, 0.0) << p.name << " changes nothing: the test proves nothing";
      d.push_back(expected);
    }
    double diff = 0.0, n0 = 0.0, n1 = 0.0;
    for (std::size_t i = 0; i < d[0].size(); ++i) {
      diff += (d[0][i] - d[1][i]) * (d[0][i] - d[1][i]);
      n0 += d[0][i] * d[0][i];
      n1 += d[1][i] * d[1][i];
    }
    const double disagreement = std::sqrt(diff / std::max(n0, n1));
    EXPECT_NEAR(p.max_disagreement, disagreement, 1e-9 * disagreement) << p.name;
    // The status follows from the figures.
    if (p.change_per_percent_deg() < s.negligible_change_deg) {
      EXPECT_EQ(p.status, DerivativeStatus::kNegligible) << p.name;
    } else {
      EXPECT_EQ(p.status,
                disagreement <= 0.05 ? DerivativeStatus::kAgrees : DerivativeStatus::kDisagrees)
          << p.name;
    }
  }
  const std::string report = s.FullReport();
  EXPECT_NE(report.find("mu "), std::string::npos) << report;
  const nlohmann::json json = ToJson(s);
  EXPECT_EQ(json["schema"], "ccsrm-derivatives/1");
  EXPECT_EQ(json["parameters"].size(), 1u);
}

TEST(DerivativeCheck, ThreadCountChangesNoBit) {
  const ShortCase& c = Case2();
  const DerivativeCheckSummary one =
      DerivativeCheck(c.model, c.config.parameters, c.inputs, c.options, Only({"mu_s"}, 1));
  const DerivativeCheckSummary three =
      DerivativeCheck(c.model, c.config.parameters, c.inputs, c.options, Only({"mu_s"}, 3));
  ASSERT_EQ(one.parameters.size(), three.parameters.size());
  for (std::size_t i = 0; i < one.parameters.size(); ++i) {
    const ParameterDerivative &a = one.parameters[i], &b = three.parameters[i];
    ASSERT_EQ(a.steps.size(), b.steps.size());
    for (std::size_t k = 0; k < a.steps.size(); ++k) {
      EXPECT_EQ(a.steps[k].derivative_deg, b.steps[k].derivative_deg) << a.name;
      EXPECT_GT(a.steps[k].rms_deg, 0.0) << a.name;
      for (int t = 0; t < 2; ++t) {
        EXPECT_EQ(a.steps[k].trials[t].summary.steps, b.steps[k].trials[t].summary.steps);
        EXPECT_EQ(a.steps[k].trials[t].summary.stick_slip_switches,
                  b.steps[k].trials[t].summary.stick_slip_switches);
      }
    }
    EXPECT_EQ(a.disagreement, b.disagreement);
    EXPECT_EQ(a.status, b.status);
  }
}

TEST(DerivativeCheck, TrialPointsStayInsideTheBounds) {
  // T_p at its lower bound (1 N): p (1 - r) is outside, so the difference is
  // forward, from runs at 1, 1 + h and 1 + 2h. c_sc at 0 with a scale of
  // 0.05: forward too, steps r x 0.05. beta at 0 with a scale of 0: nothing
  // to step relative to, so not checked (and not run).
  const ShortCase& c = Case2();
  sim::ArmParameters base = c.config.parameters;
  base.T_p = 1.0;
  base.c_sc = 0.0;
  base.beta = 0.0;
  DerivativeCheckOptions options = Only({"T_p", "c_sc", "beta"});
  options.scale_at_zero = sim::ArmParameters{};
  options.scale_at_zero->c_sc = 0.05;
  const DerivativeCheckSummary s = DerivativeCheck(c.model, base, c.inputs, c.options, options);
  EXPECT_EQ(s.runs, 1u + 2 * 2 * 2);
  ASSERT_TRUE(s.all_runs_completed()) << s.FullReport();

  for (const ParameterDerivative& p : s.parameters) {
    const sim::ParameterInfo& info = sim::FindParameter(p.name, "test");
    for (const StepDerivative& step : p.steps) {
      for (const TrialRun& t : step.trials) {
        EXPECT_GE(t.value, info.lower) << p.name;
        EXPECT_LE(t.value, info.upper) << p.name;
      }
    }
  }
  const ParameterDerivative& beta = Find(s, "beta");
  EXPECT_EQ(beta.status, DerivativeStatus::kNotChecked);
  EXPECT_TRUE(beta.steps.empty());
  EXPECT_TRUE(s.passed()) << "a parameter not checked does not fail the check";

  const ParameterDerivative& c_sc = Find(s, "c_sc");
  EXPECT_EQ(c_sc.scale, 0.05);
  EXPECT_DOUBLE_EQ(c_sc.steps[0].trials[0].value, 0.05 * 1e-2);
  EXPECT_DOUBLE_EQ(c_sc.steps[0].trials[1].value, 0.05 * 2e-2);

  // The forward difference of T_p at r = 1e-2, from runs made here:
  // 2 h f' = -3 f(p) + 4 f(p + h) - f(p + 2h), and d = p f' = (...) / 2r.
  const ParameterDerivative& t_p = Find(s, "T_p");
  const StepDerivative& step = t_p.steps[0];
  ASSERT_EQ(step.scheme, DifferenceScheme::kForward);
  EXPECT_DOUBLE_EQ(step.trials[0].value, 1.01);
  EXPECT_DOUBLE_EQ(step.trials[1].value, 1.02);
  sim::ArmParameters one = base, two = base;
  one.T_p = step.trials[0].value;
  two.T_p = step.trials[1].value;
  const std::vector<double> f0 = c.Angles(base), f1 = c.Angles(one), f2 = c.Angles(two);
  std::vector<double> expected(f0.size());
  for (std::size_t i = 0; i < f0.size(); ++i) {
    expected[i] = (-3.0 * f0[i] + 4.0 * f1[i] - f2[i]) / (2.0 * 1e-2);
  }
  ExpectSameVector(expected, step.derivative_deg);
  EXPECT_GT(Rms(expected), 0.0);
  EXPECT_NE(s.FullReport().find("forward"), std::string::npos);
}

TEST(DerivativeCheck, ParameterWithoutEffectIsNegligibleNotNan) {
  // With hole friction off the driving cables slide through their holes with
  // no friction whatever mu and mu' are: the runs are bit-identical, the
  // derivatives exactly 0, and 0/0 must not turn into NaN or a failure.
  const ShortCase& c = Case2();
  sim::SimulationOptions frictionless = c.options;
  frictionless.solver.hole_friction = sim::HoleFrictionModel::kOff;
  const DerivativeCheckSummary s =
      DerivativeCheck(c.model, c.config.parameters, c.inputs, frictionless, Only({"mu", "mu_s"}));
  for (const ParameterDerivative& p : s.parameters) {
    for (const StepDerivative& step : p.steps) EXPECT_EQ(step.rms_deg, 0.0) << p.name;
    EXPECT_EQ(p.max_disagreement, 0.0) << p.name;
    EXPECT_TRUE(p.negligible) << p.name;
    EXPECT_EQ(p.status, DerivativeStatus::kNegligible) << p.name;
  }
  EXPECT_TRUE(s.passed());
}

TEST(DerivativeCheck, RunThatDivergesIsReportedNotThrown) {
  // A bound on the constraint violation no run can meet: every run diverges.
  const ShortCase& c = Case2();
  sim::SimulationOptions strict = c.options;
  strict.solver.max_constraint_violation = 1e-30;
  const DerivativeCheckSummary s =
      DerivativeCheck(c.model, c.config.parameters, c.inputs, strict, Only({"beta"}));
  EXPECT_FALSE(s.base_run.completed());
  EXPECT_FALSE(s.all_runs_completed());
  EXPECT_FALSE(s.passed());
  const ParameterDerivative& beta = Find(s, "beta");
  EXPECT_EQ(beta.status, DerivativeStatus::kRunFailed);
  EXPECT_NE(beta.note.find("diverged"), std::string::npos) << beta.note;
  EXPECT_TRUE(std::isnan(beta.max_disagreement));
  EXPECT_NE(s.FullReport().find("RUN FAILED"), std::string::npos);
}

TEST(DerivativeCheck, OptionsNameTheFieldTheyReject) {
  std::string error;
  EXPECT_TRUE(DerivativeCheckOptions().IsValid(&error)) << error;
  EXPECT_EQ(DerivativeCheckOptions().parameters.size(), sim::Parameters().size());
  const auto rejects = [](DerivativeCheckOptions o, const std::string& field) {
    std::string message;
    EXPECT_FALSE(o.IsValid(&message));
    EXPECT_EQ(message.rfind(field + ": ", 0), 0u) << message;
  };
  DerivativeCheckOptions o;
  o.parameters = {"mu", "friction"};
  rejects(o, "parameters");
  o.parameters = {"mu", "mu"};
  rejects(o, "parameters");
  o = DerivativeCheckOptions();
  o.relative_steps = {1e-2};
  rejects(o, "relative_steps");
  o.relative_steps = {1e-2, 0.0};
  rejects(o, "relative_steps");
  o.relative_steps = {1e-2, 1e-2};
  rejects(o, "relative_steps");
  o = DerivativeCheckOptions();
  o.threads = 0;
  rejects(o, "threads");
  o = DerivativeCheckOptions();
  o.tolerance = 0.0;
  rejects(o, "tolerance");
  // DerivativeCheck throws before running anything.
  const ShortCase& c = Case2();
  o = DerivativeCheckOptions();
  o.relative_steps = {1e-2};
  EXPECT_THROW(DerivativeCheck(c.model, c.config.parameters, c.inputs, c.options, o), InputError);
}

// ---------------------------------------------------------------- the sweep

// A backend's runs (what `mpirun ccsrm derivatives` hands to its ranks) give
// the thread pool's derivatives and sweep to the bit. 0.295 s is off the
// 100 Hz output grid: the backend's runs are simulated for the duration
// asked (Experiment::simulated_s), not to the last frame, as the pool's are.
TEST(DerivativeCheck, ABackendGivesThePoolsResultToTheBit) {
  const ShortCase& c = Case2();
  sim::SimulationOptions options = c.options;
  options.duration_s = 0.295;
  const std::vector<Experiment> experiments = {
      FrameExperiment("short case 2", c.model, c.inputs, options)};
  const std::shared_ptr<SimulationBackend> backend = MakeThreadBackend(&experiments, 2);

  DerivativeCheckOptions on_backend = Only({"mu_s", "T_p"});
  on_backend.backend = backend;
  const DerivativeCheckSummary a =
      DerivativeCheck(c.model, c.config.parameters, c.inputs, options, Only({"mu_s", "T_p"}));
  const DerivativeCheckSummary b =
      DerivativeCheck(c.model, c.config.parameters, c.inputs, options, on_backend);
  EXPECT_EQ(a.runs, b.runs);
  EXPECT_EQ(a.sampled_angles, b.sampled_angles);
  EXPECT_EQ(a.base_run.simulated_s, b.base_run.simulated_s);
  EXPECT_EQ(a.base_run.steps, b.base_run.steps);
  EXPECT_EQ(a.base_run.rhs_evaluations, b.base_run.rhs_evaluations);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (std::size_t i = 0; i < a.parameters.size(); ++i) {
    ASSERT_EQ(a.parameters[i].steps.size(), b.parameters[i].steps.size());
    for (std::size_t k = 0; k < a.parameters[i].steps.size(); ++k) {
      EXPECT_GT(a.parameters[i].steps[k].rms_deg, 0.0) << a.parameters[i].name;
      EXPECT_EQ(a.parameters[i].steps[k].derivative_deg, b.parameters[i].steps[k].derivative_deg)
          << a.parameters[i].name;
    }
    EXPECT_EQ(a.parameters[i].disagreement, b.parameters[i].disagreement);
  }

  SweepOptions sweep;
  sweep.parameter = "T_p";
  sweep.points = 5;
  sweep.threads = 2;
  const SweepSummary x = ParameterSweep(c.model, c.config.parameters, c.inputs, options, sweep);
  sweep.backend = backend;
  const SweepSummary y = ParameterSweep(c.model, c.config.parameters, c.inputs, options, sweep);
  ASSERT_TRUE(x.all_runs_completed());
  EXPECT_GT(x.variation_max, 0.0);
  EXPECT_EQ(x.angles_deg, y.angles_deg);
  EXPECT_EQ(x.residual_rms, y.residual_rms);
}

// A backend cannot cancel its runs or hold them to a wall time budget: such
// options are refused, not dropped.
TEST(DerivativeCheck, FrameExperimentRefusesWhatABackendCannotCarry) {
  const ShortCase& c = Case2();
  sim::SimulationOptions options = c.options;
  options.wall_time_budget_s = 10.0;
  EXPECT_THROW(FrameExperiment("budget", c.model, c.inputs, options), InputError);
}

// (The sweep's runs go through the pool of DerivativeCheck, whose
// independence of the thread count is tested above.)
TEST(ParameterSweep, MiddlePointIsTheBaseRun) {
  const ShortCase& c = Case2();
  SweepOptions options;
  options.parameter = "c_lc";
  options.points = 5;
  options.threads = 2;
  const SweepSummary one =
      ParameterSweep(c.model, c.config.parameters, c.inputs, c.options, options);
  ASSERT_TRUE(one.all_runs_completed());
  const double p = c.config.parameters.c_lc;
  ASSERT_EQ(one.values.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_DOUBLE_EQ(one.values[k], p * (1.0 + 0.05 * (k - 2) / 2.0));
  }
  EXPECT_EQ(one.values[2], p);
  ASSERT_EQ(one.angles_deg.rows(), 5);
  ASSERT_EQ(one.angles_deg.cols(), static_cast<Eigen::Index>(c.SampledAngles()));
  const std::vector<double> base = c.Angles(c.config.parameters);
  for (std::size_t i = 0; i < base.size(); ++i) {
    ASSERT_EQ(one.angles_deg(2, static_cast<Eigen::Index>(i)), base[i]) << i;
  }

  // The figures from the angles: variation is max - min of each angle; the
  // residual is at most the variation (a constant is a cubic).
  const Eigen::RowVectorXd range =
      one.angles_deg.colwise().maxCoeff() - one.angles_deg.colwise().minCoeff();
  EXPECT_DOUBLE_EQ(one.variation_max, range.maxCoeff());
  EXPECT_GT(one.variation_max, 0.0);
  EXPECT_LE(one.residual_max, one.variation_max);
  EXPECT_NE(one.FullReport().find("residual to the cubics"), std::string::npos);
}

TEST(ParameterSweep, RangeOutsideTheBoundsIsAnInputError) {
  const ShortCase& c = Case2();
  sim::ArmParameters base = c.config.parameters;
  base.T_p = 1.02;  // -5 % is 0.969 N, below the 1 N bound
  SweepOptions options;
  options.parameter = "T_p";
  try {
    ParameterSweep(c.model, base, c.inputs, c.options, options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("T_p"), std::string::npos) << e.what();
  }
  options.parameter = "beta";
  base.beta = 0.0;  // and no scale at zero
  EXPECT_THROW(ParameterSweep(c.model, base, c.inputs, c.options, options), InputError);
  options.points = 4;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error.rfind("points: ", 0), 0u) << error;
}

// An exact cubic in x far from 0 (a pre-tension of 100 N +- 5 %): raw powers
// of x would agree to a part in 1e6 and lose the fit to rounding.
TEST(CubicFit, ExactForACubicFarFromZero) {
  std::vector<double> x;
  for (int k = 0; k < 21; ++k) x.push_back(95.0 + 0.5 * k);
  Eigen::MatrixXd y(21, 2);
  for (int k = 0; k < 21; ++k) {
    const double u = x[k];
    y(k, 0) =
        6.0 + 0.1 * (u - 97.0) - 0.02 * (u - 103.0) * (u - 103.0) + 0.003 * std::pow(u - 100.5, 3);
    y(k, 1) = -3.0;
  }
  const Eigen::MatrixXd r = CubicFitResiduals(x, y);
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-12);
}

// Whatever is orthogonal to the cubics on the sample points is left whole:
// z is t^4 and sign(t) |t|^0.5 made orthogonal to 1, t, t^2, t^3 here by
// Gram-Schmidt (independently of the library's QR), on uneven points.
TEST(CubicFit, LeavesExactlyWhatIsNotCubic) {
  std::vector<double> x;
  for (int k = 0; k < 9; ++k) x.push_back(0.2 + 0.01 * k * k);
  const int n = static_cast<int>(x.size());
  std::vector<std::vector<double>> basis;
  const auto orthogonalise = [&](std::vector<double> v) {
    for (const std::vector<double>& b : basis) {
      double dot = 0.0, bb = 0.0;
      for (int k = 0; k < n; ++k) {
        dot += v[k] * b[k];
        bb += b[k] * b[k];
      }
      for (int k = 0; k < n; ++k) v[k] -= dot / bb * b[k];
    }
    return v;
  };
  for (int power = 0; power < 4; ++power) {
    std::vector<double> v(n);
    for (int k = 0; k < n; ++k) v[k] = std::pow(x[k] - 0.5, power);
    basis.push_back(orthogonalise(v));
  }
  std::vector<double> quartic(n), root(n);
  for (int k = 0; k < n; ++k) {
    quartic[k] = std::pow(x[k] - 0.5, 4);
    root[k] = std::copysign(std::sqrt(std::abs(x[k] - 0.5)), x[k] - 0.5);
  }
  const std::vector<double> z1 = orthogonalise(quartic), z2 = orthogonalise(root);
  Eigen::MatrixXd y(n, 2);
  for (int k = 0; k < n; ++k) {
    const double cubic = 4.0 - 2.0 * x[k] + 7.0 * std::pow(x[k], 3);
    y(k, 0) = cubic + z1[k];
    y(k, 1) = cubic + 0.1 * z2[k];
  }
  const Eigen::MatrixXd r = CubicFitResiduals(x, y);
  for (int k = 0; k < n; ++k) {
    EXPECT_NEAR(r(k, 0), z1[k], 1e-12);
    EXPECT_NEAR(r(k, 1), 0.1 * z2[k], 1e-12);
  }
  EXPECT_GT(Eigen::Map<const Eigen::VectorXd>(z1.data(), n).norm(), 1e-3);
}

}  // namespace
}  // namespace ccsrm::identify
