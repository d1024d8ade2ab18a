// The discovery's sparse regression (identify/src/term_discovery.h) on
// synthetic columns whose truth is known: it picks the terms the residual
// holds, recovers their coefficients, prefers the simpler of two terms the
// data cannot tell apart, and finds nothing worth a refit in noise.
#include "term_discovery.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>

namespace ccsrm::identify::internal {
namespace {

constexpr Eigen::Index kRows = 4000;

Eigen::VectorXd Noise(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::VectorXd v(kRows);
  for (Eigen::Index i = 0; i < kRows; ++i) v[i] = n(rng);
  return v;
}

// Smooth, different signals over "time", like the angles' sensitivities.
Eigen::VectorXd Signal(int k) {
  Eigen::VectorXd v(kRows);
  for (Eigen::Index i = 0; i < kRows; ++i) {
    const double t = static_cast<double>(i) / kRows;
    v[i] = std::sin(3.0 * (k + 1) * t + 0.7 * k) + 0.3 * k * t;
  }
  return v;
}

struct Problem {
  Eigen::MatrixXd jacobian;
  std::vector<TermColumn> columns;
};

Problem MakeProblem() {
  Problem p;
  p.jacobian.resize(kRows, 2);
  p.jacobian.col(0) = Signal(10);
  p.jacobian.col(1) = Eigen::VectorXd::Ones(kRows);
  for (int k = 0; k < 6; ++k) {
    p.columns.push_back({"term" + std::to_string(k), 1 + k % 3, 20.0 * Signal(k)});
  }
  return p;
}

TEST(TermDiscovery, PicksTheTermsTheResidualHoldsAndRecoversTheirCoefficients) {
  const Problem p = MakeProblem();
  // Residual = -(true model) + white noise of unit variance (the weighted
  // residual's units): terms 1 and 4, and a part the fit's own columns
  // explain (which the regression must leave to them).
  const Eigen::VectorXd r =
      -(0.05 * p.columns[1].weighted - 0.03 * p.columns[4].weighted + 0.8 * p.jacobian.col(0)) +
      Noise(1);
  const TermSelection s = SelectTerms(r, p.jacobian, p.columns, 1.0, kRows, 2.0, 0.05);
  ASSERT_GE(s.chosen, 0);
  const TermSupport& chosen = s.path[static_cast<std::size_t>(s.chosen)];
  EXPECT_EQ(chosen.parameters, (std::vector<std::string>{"term1", "term4"}));
  // The path runs from every term down to one.
  ASSERT_EQ(s.path.size(), 6u);
  EXPECT_EQ(s.path.front().parameters.size(), 6u);
  EXPECT_EQ(s.path.back().parameters.size(), 1u);
  // Coefficients within 5 of their standard errors' worth... the columns
  // carry 20x a unit signal over 4000 unit-noise samples: a standard error
  // of about 1e-3 on each, so 0.005 is five of them.
  EXPECT_NEAR(chosen.linearised.at("term1"), 0.05, 0.005);
  EXPECT_NEAR(chosen.linearised.at("term4"), -0.03, 0.005);
  EXPECT_GT(chosen.delta_bic, 10.0);
}

TEST(TermDiscovery, SimplerOfTwoIndistinguishableTermsWins) {
  Problem p = MakeProblem();
  // term5 (complexity 3) and an exact copy of it of complexity 1: the data
  // cannot prefer either; the simpler must be chosen.
  p.columns.push_back({"simple_copy", 1, p.columns[5].weighted});
  const Eigen::VectorXd r = -0.04 * p.columns[5].weighted + Noise(2);
  const TermSelection s = SelectTerms(r, p.jacobian, p.columns, 1.0, kRows, 2.0, 0.05);
  ASSERT_GE(s.chosen, 0);
  EXPECT_EQ(s.path[static_cast<std::size_t>(s.chosen)].parameters,
            std::vector<std::string>{"simple_copy"});
}

TEST(TermDiscovery, NoiseAloneHoldsNoTermWorthARefit) {
  const Problem p = MakeProblem();
  // Null data: the linear ΔBIC of the best support stays below the loop's
  // threshold (10, "very strong" evidence) for every seed tried.
  for (unsigned seed = 3; seed < 13; ++seed) {
    const TermSelection s = SelectTerms(Noise(seed), p.jacobian, p.columns, 1.0, kRows, 2.0, 0.05);
    ASSERT_GE(s.chosen, 0);
    EXPECT_LT(s.path[static_cast<std::size_t>(s.chosen)].delta_bic, 10.0) << "seed " << seed;
  }
}

TEST(TermDiscovery, ATermTheFitAlreadyStandsForIsSetAside) {
  Problem p = MakeProblem();
  p.columns.push_back({"fit_copy", 1, 3.0 * p.jacobian.col(1)});
  const TermSelection s = SelectTerms(Noise(20), p.jacobian, p.columns, 1.0, kRows, 2.0, 0.05);
  EXPECT_EQ(s.degenerate, std::vector<std::string>{"fit_copy"});
}

}  // namespace
}  // namespace ccsrm::identify::internal
