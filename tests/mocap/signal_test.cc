// The signal tools against analytic signals: Butterworth design and zero-lag
// filtering, spline gap filling, resampling.
#include "ccsrm/mocap/signal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <random>
#include <vector>

namespace ccsrm::mocap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRate = 100.0;

std::vector<double> Sine(std::size_t n, double freq_hz, double amplitude, double phase = 0.0) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = amplitude * std::sin(2.0 * M_PI * freq_hz * static_cast<double>(i) / kRate + phase);
  }
  return x;
}

// |H(e^{jω})| of the cascade at freq_hz.
double Gain(const std::vector<BiquadSection>& sections, double freq_hz) {
  const std::complex<double> z1 = std::polar(1.0, -2.0 * M_PI * freq_hz / kRate);
  std::complex<double> h = 1.0;
  for (const BiquadSection& s : sections) {
    h *= (s.b0 + s.b1 * z1 + s.b2 * z1 * z1) / (1.0 + s.a1 * z1 + s.a2 * z1 * z1);
  }
  return std::abs(h);
}

TEST(Butterworth, DesignHasUnitDcGainAndMinus3DbAtTheCutoff) {
  for (int order = 1; order <= 8; ++order) {
    const auto sections = DesignButterworthLowPass(order, 5.0, kRate);
    EXPECT_EQ(sections.size(), static_cast<std::size_t>((order + 1) / 2));
    EXPECT_NEAR(Gain(sections, 0.0), 1.0, 1e-12) << order;
    EXPECT_NEAR(Gain(sections, 5.0), 1.0 / std::sqrt(2.0), 1e-9) << order;
    // Maximally flat: the gain never exceeds 1 and falls monotonically.
    double previous = 1.0;
    for (double f = 0.5; f < 50.0; f += 0.5) {
      const double g = Gain(sections, f);
      EXPECT_LE(g, previous + 1e-12) << order << " at " << f << " Hz";
      previous = g;
    }
  }
  // Order 4 at 2 cutoffs: about -24 dB per octave beyond.
  const auto fourth = DesignButterworthLowPass(4, 5.0, kRate);
  EXPECT_LT(Gain(fourth, 10.0), 0.07);
}

TEST(ZeroLagLowPass, SineWellBelowTheCutoffPassesWithNoPhaseLag) {
  // 0.25 Hz: a period of 400 frames, so phase and amplitude can be read off
  // over whole periods.
  const std::size_t n = 2000;
  const double freq = 0.25, phase = 0.4;
  std::vector<double> x = Sine(n, freq, 1.0, phase);
  const std::vector<double> original = x;
  const auto sections = DesignButterworthLowPass(2, 2.0, kRate);
  ZeroLagLowPass(sections, 2.0, kRate, x.data(), n);
  // Gain² of order 2 at 0.25 Hz of 2 Hz: 1 / (1 + 0.125⁴) = 0.99976, so
  // away from the ends the error is that loss; at the ends the pivot (a line
  // through half a cutoff period) and the odd reflection carry level and
  // slope but not curvature: about x''·(0.25 s)²/12 ≈ 0.5 % here.
  double worst_middle = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double error = std::abs(x[i] - original[i]);
    worst = std::max(worst, error);
    if (i >= 100 && i + 100 < n) worst_middle = std::max(worst_middle, error);
  }
  EXPECT_LT(worst_middle, 5e-4);
  EXPECT_LT(worst, 0.008);
  // In-phase and quadrature parts over three whole periods: any lag shows
  // as a quadrature part.
  double in_phase = 0.0, quadrature = 0.0;
  for (std::size_t i = 400; i < 1600; ++i) {
    const double angle = 2.0 * M_PI * freq * static_cast<double>(i) / kRate + phase;
    in_phase += x[i] * std::sin(angle);
    quadrature += x[i] * std::cos(angle);
  }
  EXPECT_NEAR(in_phase / 600.0, 1.0, 5e-4);
  EXPECT_LT(std::abs(std::atan2(quadrature, in_phase)), 1e-5);  // rad; 1 frame would be 0.016
}

TEST(ZeroLagLowPass, SquaredGainAtTheCutoffAndStrongAttenuationAbove) {
  const std::size_t n = 4000;
  const auto sections = DesignButterworthLowPass(2, 2.0, kRate);
  std::vector<double> at_cutoff = Sine(n, 2.0, 1.0);
  ZeroLagLowPass(sections, 2.0, kRate, at_cutoff.data(), n);
  double peak = 0.0;
  for (std::size_t i = 1000; i < 3000; ++i) peak = std::max(peak, std::abs(at_cutoff[i]));
  EXPECT_NEAR(peak, 0.5, 0.01);  // forward-backward: (1/√2)² = -6 dB
  std::vector<double> noise_band = Sine(n, 20.0, 1.0);
  ZeroLagLowPass(sections, 2.0, kRate, noise_band.data(), n);
  peak = 0.0;
  for (std::size_t i = 1000; i < 3000; ++i) peak = std::max(peak, std::abs(noise_band[i]));
  EXPECT_LT(peak, 1e-3);  // (2/20)⁴ = 1e-4 in amplitude
}

TEST(ZeroLagLowPass, ConstantsPassUnchangedAndRampsAlmostUpToTheEnds) {
  const std::size_t n = 300;
  std::vector<double> ramp(n);
  for (std::size_t i = 0; i < n; ++i) ramp[i] = 0.01 + 0.002 * static_cast<double>(i);
  std::vector<double> x = ramp;
  ZeroLagLowPass(DesignButterworthLowPass(4, 1.5, kRate), 1.5, kRate, x.data(), n);
  // Close in the middle; at the ends the start-up transient of each pass
  // (started from a constant, not a ramp) has decayed to a few µ in the padding.
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(x[i], ramp[i], 2e-5) << i;
  for (std::size_t i = 100; i < 200; ++i) EXPECT_NEAR(x[i], ramp[i], 1e-6) << i;
  std::vector<double> constant(n, -0.25);
  ZeroLagLowPass(DesignButterworthLowPass(3, 1.5, kRate), 1.5, kRate, constant.data(), n);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(constant[i], -0.25, 1e-15) << i;
}

// The profile is the filter's own: the scatter of many filtered white-noise
// signals at each sample, over the interior's.
TEST(ZeroLagNoiseGain, MatchesTheScatterOfFilteredWhiteNoise) {
  const std::size_t n = 400;
  const double cutoff = 4.0;
  const auto sections = DesignButterworthLowPass(2, cutoff, kRate);
  ZeroLagNoiseGain gain(sections, cutoff, kRate);
  std::vector<double> ones(n, 0.0);
  const std::vector<double> relative = gain.Relative(ones.data(), n);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  const int draws = 4000;
  std::vector<double> sq(n, 0.0);
  for (int d = 0; d < draws; ++d) {
    std::vector<double> x(n);
    for (double& v : x) v = noise(rng);
    ZeroLagLowPass(sections, cutoff, kRate, x.data(), n);
    for (std::size_t i = 0; i < n; ++i) sq[i] += x[i] * x[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double scatter = std::sqrt(sq[i] / draws) / gain.interior_gain();
    // A standard deviation from 4000 draws is within 1.1 % (one sigma) of
    // the truth: 5 % is four and a half sigma.
    EXPECT_NEAR(scatter / relative[i], 1.0, 0.05) << i;
  }
  // The middle is the interior; the last sample sits on the pivot, a line's
  // end over half a cutoff period (13 samples): 2 / sqrt(13) against the
  // interior's gain, well above it.
  EXPECT_NEAR(relative[n / 2], 1.0, 1e-9);
  EXPECT_GT(relative[n - 1], 1.5);
  EXPECT_GT(relative[0], 1.5);
}

// A long run's profile is spliced from a shorter run's ends: it must equal
// the operator's own row norms, one impulse per column.
TEST(ZeroLagNoiseGain, LongRunsEqualTheOperatorsRowNorms) {
  const double cutoff = 10.0;
  const auto sections = DesignButterworthLowPass(4, cutoff, kRate);
  ZeroLagNoiseGain gain(sections, cutoff, kRate);
  for (const std::size_t n : {std::size_t{40}, std::size_t{150}, std::size_t{700}}) {
    std::vector<double> sq(n, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      std::vector<double> y(n, 0.0);
      y[k] = 1.0;
      ZeroLagLowPass(sections, cutoff, kRate, y.data(), n);
      for (std::size_t i = 0; i < n; ++i) sq[i] += y[i] * y[i];
    }
    std::vector<double> zeros(n, 0.0);
    const std::vector<double> relative = gain.Relative(zeros.data(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_NEAR(relative[i] * gain.interior_gain(), std::sqrt(sq[i]), 1e-9) << n << " " << i;
    }
  }
}

TEST(ZeroLagNoiseGain, GapsStayNaNAndShortRunsKeepTheirRawNoise) {
  const double cutoff = 5.0;
  ZeroLagNoiseGain gain(DesignButterworthLowPass(2, cutoff, kRate), cutoff, kRate, 10);
  std::vector<double> x(300, 0.0);
  for (std::size_t i = 100; i < 110; ++i) x[i] = kNaN;
  for (std::size_t i = 115; i < 300; ++i) x[i] = kNaN;
  const std::vector<double> relative = gain.Relative(x.data(), x.size());
  EXPECT_TRUE(std::isnan(relative[105]));
  EXPECT_TRUE(std::isnan(relative[200]));
  // Frames 110..114: five, below the minimum run of 10, left unfiltered.
  EXPECT_DOUBLE_EQ(relative[112], 1.0 / gain.interior_gain());
  EXPECT_GT(1.0 / gain.interior_gain(), 3.0);  // a 5 Hz low-pass at 100 Hz removes most noise
  EXPECT_TRUE(std::isfinite(relative[50]));
}

TEST(ZeroLagLowPass, FiltersEachFiniteRunAndKeepsNaN) {
  std::vector<double> x = Sine(600, 0.5, 1.0);
  std::vector<double> expected = x;
  for (std::size_t i = 250; i < 270; ++i) x[i] = expected[i] = kNaN;
  // The runs filtered on their own are what the gapped signal must give.
  const auto sections = DesignButterworthLowPass(2, 3.0, kRate);
  ZeroLagLowPass(sections, 3.0, kRate, expected.data(), 250);
  ZeroLagLowPass(sections, 3.0, kRate, expected.data() + 270, 330);
  ZeroLagLowPass(sections, 3.0, kRate, x.data(), x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isnan(expected[i])) {
      EXPECT_TRUE(std::isnan(x[i]));
    } else {
      EXPECT_DOUBLE_EQ(x[i], expected[i]);
    }
  }
  // Strided access: every third sample of an interleaved buffer.
  std::vector<double> interleaved(3 * 600, 7.0);
  for (std::size_t i = 0; i < 600; ++i) interleaved[3 * i + 1] = std::sin(0.01 * i);
  ZeroLagLowPass(sections, 3.0, kRate, interleaved.data() + 1, 600, 3);
  EXPECT_EQ(interleaved[0], 7.0);
  EXPECT_NEAR(interleaved[3 * 300 + 1], std::sin(3.0), 1e-4);
}

TEST(FillGapBySpline, FillsAShortGapInASmoothSignalToSplineAccuracy) {
  std::vector<double> x = Sine(200, 0.5, 0.01);
  const std::vector<double> truth = x;
  for (std::size_t i = 100; i < 110; ++i) x[i] = kNaN;
  const std::vector<Gap> gaps = FindGaps(x.data(), x.size());
  ASSERT_EQ(gaps.size(), 1u);
  EXPECT_EQ(gaps[0].first, 100u);
  EXPECT_EQ(gaps[0].length, 10u);
  ASSERT_TRUE(FillGapBySpline(x.data(), x.size(), gaps[0], 10));
  for (std::size_t i = 100; i < 110; ++i) EXPECT_NEAR(x[i], truth[i], 1e-6) << i;  // 0.01 % of A
}

TEST(FillGapBySpline, LeavesGapsAtTheEndsAndFallsBackToLinearWithTwoSamples) {
  std::vector<double> x = {kNaN, kNaN, 1.0, 2.0, 3.0, kNaN};
  const std::vector<Gap> gaps = FindGaps(x.data(), x.size());
  ASSERT_EQ(gaps.size(), 2u);
  EXPECT_FALSE(FillGapBySpline(x.data(), x.size(), gaps[0], 5));
  EXPECT_FALSE(FillGapBySpline(x.data(), x.size(), gaps[1], 5));
  EXPECT_TRUE(std::isnan(x[0]));
  std::vector<double> y = {kNaN, 1.0, kNaN, kNaN, 4.0, kNaN};
  const std::vector<Gap> inner = FindGaps(y.data(), y.size());
  ASSERT_TRUE(FillGapBySpline(y.data(), y.size(), inner[1], 5));
  EXPECT_DOUBLE_EQ(y[2], 2.0);
  EXPECT_DOUBLE_EQ(y[3], 3.0);
}

TEST(Resample, LinearAndCubicOntoAnotherTimeBaseWithoutExtrapolating) {
  std::vector<double> t, v;
  for (int i = 0; i <= 100; ++i) {
    t.push_back(0.01 * i);
    v.push_back(std::sin(2.0 * t.back()));
  }
  v[50] = kNaN;  // splits the signal into two runs
  const std::vector<double> query = {-0.1, 0.123, 0.495, 0.505, 0.777, 1.0, 1.2};
  const auto linear = Resample(t, v, query, Interpolation::kLinear);
  const auto cubic = Resample(t, v, query, Interpolation::kCubic);
  for (std::size_t q : {std::size_t{0}, std::size_t{2}, std::size_t{3}, std::size_t{6}}) {
    EXPECT_TRUE(std::isnan(linear[q])) << q;
    EXPECT_TRUE(std::isnan(cubic[q])) << q;
  }
  for (std::size_t q : {std::size_t{1}, std::size_t{4}, std::size_t{5}}) {
    EXPECT_NEAR(linear[q], std::sin(2.0 * query[q]), 5e-5) << q;
    EXPECT_NEAR(cubic[q], std::sin(2.0 * query[q]), 1e-6) << q;
  }
  datasets::Array frames({101, 2});
  for (std::size_t f = 0; f <= 100; ++f) {
    frames.at(f, 0) = t[f];
    frames.at(f, 1) = -t[f];
  }
  const datasets::Array resampled =
      ResampleFrames(frames, t, {0.25, 0.555}, Interpolation::kLinear);
  ASSERT_EQ(resampled.shape, (std::vector<std::size_t>{2, 2}));
  EXPECT_NEAR(resampled.at(1, 0), 0.555, 1e-12);
  EXPECT_NEAR(resampled.at(1, 1), -0.555, 1e-12);
}

}  // namespace
}  // namespace ccsrm::mocap
