#include "ccsrm/mocap/signal.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>

#include "ccsrm/common/error.h"
#include "ccsrm/common/gsl_errors.h"

namespace ccsrm::mocap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One pass of the cascade over y[0..n) in place (direct form II transposed),
// each section starting from the steady state of a constant input y[0]: with
// unity DC gain the output of a section equals its input at steady state, so
// z2 = (b2 - a2)·x0 and z1 = (1 - b0)·x0.
void FilterPass(const std::vector<BiquadSection>& sections, double* y, std::size_t n) {
  if (n == 0) return;
  for (const BiquadSection& s : sections) {
    const double x0 = y[0];
    double z1 = (1.0 - s.b0) * x0;
    double z2 = (s.b2 - s.a2) * x0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = y[i];
      const double out = s.b0 * x + z1;
      z1 = s.b1 * x - s.a1 * out + z2;
      z2 = s.b2 * x - s.a2 * out;
      y[i] = out;
    }
  }
}

// The runs [begin, end) of consecutive finite samples of x[0], x[stride],
// ... x[(n-1)·stride], in order.
std::vector<std::pair<std::size_t, std::size_t>> FiniteRuns(const double* x, std::size_t n,
                                                            std::size_t stride) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::size_t i = 0;
  while (i < n) {
    if (!std::isfinite(x[i * stride])) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < n && std::isfinite(x[end * stride])) ++end;
    runs.emplace_back(i, end);
    i = end;
  }
  return runs;
}

// Value at x[0] of the least-squares line through x[0], x[step], ...,
// x[(m-1)·step] (step = ±1): the end of a run with its noise averaged.
double EndPivot(const double* x, std::size_t m, int step) {
  if (m < 2) return x[0];
  double sum_i = 0.0, sum_ii = 0.0, sum_x = 0.0, sum_ix = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double v = x[static_cast<std::ptrdiff_t>(i) * step];
    const double di = static_cast<double>(i);
    sum_i += di;
    sum_ii += di * di;
    sum_x += v;
    sum_ix += di * v;
  }
  const double count = static_cast<double>(m);
  const double slope = (count * sum_ix - sum_i * sum_x) / (count * sum_ii - sum_i * sum_i);
  return (sum_x - slope * sum_i) / count;
}

struct SplineDeleter {
  void operator()(gsl_spline* s) const { gsl_spline_free(s); }
};
struct AccelDeleter {
  void operator()(gsl_interp_accel* a) const { gsl_interp_accel_free(a); }
};

// Interpolates (x[i], y[i]), i < n, with n >= 2 strictly increasing x, at the
// query points xq inside [x[0], x[n-1]]: natural cubic spline for n >= 3 when
// cubic is asked, else linear.
class Interpolator {
 public:
  Interpolator(const double* x, const double* y, std::size_t n, bool cubic) : x_(x), y_(y), n_(n) {
    CCSRM_CHECK(n >= 2);
    if (cubic && n >= 3) {
      UseGslErrorCodes();
      spline_.reset(gsl_spline_alloc(gsl_interp_cspline, n));
      accel_.reset(gsl_interp_accel_alloc());
      CCSRM_CHECK(spline_ && accel_);
      CCSRM_CHECK(gsl_spline_init(spline_.get(), x, y, n) == GSL_SUCCESS);
    }
  }

  double operator()(double xq) const {
    if (spline_) {
      double value = kNaN;
      UseGslErrorCodes();
      if (gsl_spline_eval_e(spline_.get(), xq, accel_.get(), &value) != GSL_SUCCESS) return kNaN;
      return value;
    }
    const double* upper = std::upper_bound(x_, x_ + n_, xq);
    std::size_t hi = static_cast<std::size_t>(upper - x_);
    hi = std::clamp<std::size_t>(hi, 1, n_ - 1);
    const std::size_t lo = hi - 1;
    const double w = (xq - x_[lo]) / (x_[hi] - x_[lo]);
    return (1.0 - w) * y_[lo] + w * y_[hi];
  }

 private:
  const double* x_;
  const double* y_;
  std::size_t n_;
  std::unique_ptr<gsl_spline, SplineDeleter> spline_;
  std::unique_ptr<gsl_interp_accel, AccelDeleter> accel_;
};

}  // namespace

std::vector<BiquadSection> DesignButterworthLowPass(int order, double cutoff_hz,
                                                    double sample_rate_hz) {
  CCSRM_CHECK(order >= 1 && order <= 8);
  CCSRM_CHECK(cutoff_hz > 0.0 && cutoff_hz < 0.5 * sample_rate_hz);
  // Pre-warped analog cutoff, in units of 2·fs: the bilinear transform maps
  // the analog -3 dB point exactly onto cutoff_hz.
  const double k = std::tan(M_PI * cutoff_hz / sample_rate_hz);
  std::vector<BiquadSection> sections;
  // Analog prototype poles come in conjugate pairs at angles
  // π/2 + (2m + 1)π/(2·order) from the real axis; each pair is a section
  // s² + s/Q + 1 with 1/Q = 2 sin((2m + 1)π / (2·order)).
  for (int m = 0; m < order / 2; ++m) {
    const double inv_q = 2.0 * std::sin((2.0 * m + 1.0) * M_PI / (2.0 * order));
    const double norm = 1.0 / (1.0 + k * inv_q + k * k);
    BiquadSection s;
    s.b0 = k * k * norm;
    s.b1 = 2.0 * s.b0;
    s.b2 = s.b0;
    s.a1 = 2.0 * (k * k - 1.0) * norm;
    s.a2 = (1.0 - k * inv_q + k * k) * norm;
    sections.push_back(s);
  }
  if (order % 2 == 1) {  // the real pole at s = -1
    const double norm = 1.0 / (1.0 + k);
    BiquadSection s;
    s.b0 = k * norm;
    s.b1 = s.b0;
    s.a1 = (k - 1.0) * norm;
    sections.push_back(s);
  }
  return sections;
}

std::size_t FiltFiltPadding(double cutoff_hz, double sample_rate_hz, std::size_t n) {
  const double periods = 3.0;
  const auto pad = static_cast<std::size_t>(std::ceil(periods * sample_rate_hz / cutoff_hz));
  return n == 0 ? 0 : std::min(pad, n - 1);
}

std::size_t FiltFiltEndWindow(double cutoff_hz, double sample_rate_hz, std::size_t n) {
  const auto window = static_cast<std::size_t>(std::ceil(0.5 * sample_rate_hz / cutoff_hz));
  return std::max<std::size_t>(1, std::min(window, n));
}

void FiltFilt(const std::vector<BiquadSection>& sections, double* x, std::size_t n, std::size_t pad,
              std::size_t end_window) {
  if (n < 2) return;
  pad = std::min(pad, n - 1);
  end_window = std::clamp<std::size_t>(end_window, 1, n);
  const double first = EndPivot(x, end_window, 1);
  const double last = EndPivot(x + n - 1, end_window, -1);
  // Odd reflection: x[-i] = 2·first - x[i], x[n-1+i] = 2·last - x[n-1-i].
  std::vector<double> y(n + 2 * pad);
  for (std::size_t i = 0; i < pad; ++i) {
    y[i] = 2.0 * first - x[pad - i];
    y[pad + n + i] = 2.0 * last - x[n - 2 - i];
  }
  std::copy(x, x + n, y.begin() + static_cast<std::ptrdiff_t>(pad));
  FilterPass(sections, y.data(), y.size());
  std::reverse(y.begin(), y.end());
  FilterPass(sections, y.data(), y.size());
  std::reverse(y.begin(), y.end());
  std::copy(y.begin() + static_cast<std::ptrdiff_t>(pad),
            y.begin() + static_cast<std::ptrdiff_t>(pad + n), x);
}

void ZeroLagLowPass(const std::vector<BiquadSection>& sections, double cutoff_hz,
                    double sample_rate_hz, double* x, std::size_t n, std::size_t stride,
                    std::size_t min_run) {
  std::vector<double> run;
  for (const auto& [begin, end] : FiniteRuns(x, n, stride)) {
    if (end - begin < min_run) continue;
    run.resize(end - begin);
    for (std::size_t j = begin; j < end; ++j) run[j - begin] = x[j * stride];
    FiltFilt(sections, run.data(), run.size(),
             FiltFiltPadding(cutoff_hz, sample_rate_hz, run.size()),
             FiltFiltEndWindow(cutoff_hz, sample_rate_hz, run.size()));
    for (std::size_t j = begin; j < end; ++j) x[j * stride] = run[j - begin];
  }
}

ZeroLagNoiseGain::ZeroLagNoiseGain(std::vector<BiquadSection> sections, double cutoff_hz,
                                   double sample_rate_hz, std::size_t min_run)
    : sections_(std::move(sections)),
      cutoff_hz_(cutoff_hz),
      sample_rate_hz_(sample_rate_hz),
      min_run_(std::max<std::size_t>(min_run, 2)) {
  // The kernel from an impulse in the middle of a run long enough that
  // neither end's padding nor pivot reaches it; kept to two paddings each
  // side, where an IIR tail past the padding's three cutoff periods is long
  // gone (the padding itself assumes as much).
  const std::size_t pad = FiltFiltPadding(cutoff_hz, sample_rate_hz, SIZE_MAX);
  reach_ = 2 * pad;
  const std::size_t n = 2 * reach_ + 1;
  std::vector<double> y(n, 0.0);
  y[reach_] = 1.0;
  FiltFilt(sections_, y.data(), n, FiltFiltPadding(cutoff_hz, sample_rate_hz, n),
           FiltFiltEndWindow(cutoff_hz, sample_rate_hz, n));
  kernel_sq_prefix_.assign(n + 1, 0.0);
  for (std::size_t t = 0; t < n; ++t) kernel_sq_prefix_[t + 1] = kernel_sq_prefix_[t] + y[t] * y[t];
  interior_gain_ = std::sqrt(kernel_sq_prefix_.back());
  // Columns an end touches: the padding's reflection and the pivot's line.
  const std::size_t edge = std::max(pad, FiltFiltEndWindow(cutoff_hz, sample_rate_hz, SIZE_MAX));
  // Rows past edge + reach_ see neither end: a long run's ends are those of
  // a run of 2 splice_.
  splice_ = edge + 1 + reach_ + 1;
}

std::vector<double> ZeroLagNoiseGain::ExactRunGain(std::size_t n) const {
  const std::size_t pad = FiltFiltPadding(cutoff_hz_, sample_rate_hz_, n);
  const std::size_t window = FiltFiltEndWindow(cutoff_hz_, sample_rate_hz_, n);
  const std::size_t edge = std::max(pad, window - 1);  // last column the left end touches
  std::vector<double> sq(n, 0.0), y(n);
  const auto add_column = [&](std::size_t k) {
    std::fill(y.begin(), y.end(), 0.0);
    y[k] = 1.0;
    FiltFilt(sections_, y.data(), n, pad, window);
    for (std::size_t i = 0; i < n; ++i) sq[i] += y[i] * y[i];
  };
  if (n <= 2 * (edge + 1)) {  // every column touches an end
    for (std::size_t k = 0; k < n; ++k) add_column(k);
  } else {
    for (std::size_t k = 0; k <= edge; ++k) add_column(k);
    for (std::size_t k = n - 1 - edge; k < n; ++k) add_column(k);
    // Every other column k is the shifted kernel: row i gets Σ h(i - k)² over
    // k in [edge + 1, n - 2 - edge], from the prefix sums (d = i - k).
    const auto r = static_cast<std::ptrdiff_t>(reach_);
    for (std::size_t i = 0; i < n; ++i) {
      const auto ii = static_cast<std::ptrdiff_t>(i);
      const std::ptrdiff_t lo = std::max(ii - static_cast<std::ptrdiff_t>(n - 2 - edge), -r);
      const std::ptrdiff_t hi = std::min(ii - static_cast<std::ptrdiff_t>(edge + 1), r);
      if (lo <= hi) {
        sq[i] += kernel_sq_prefix_[static_cast<std::size_t>(hi + r + 1)] -
                 kernel_sq_prefix_[static_cast<std::size_t>(lo + r)];
      }
    }
  }
  for (double& v : sq) v = std::sqrt(v);
  return sq;
}

const std::vector<double>& ZeroLagNoiseGain::RunGain(std::size_t n) {
  if (const auto it = by_length_.find(n); it != by_length_.end()) return it->second;
  std::vector<double> gain;
  if (n <= 2 * splice_) {
    gain = ExactRunGain(n);
  } else {
    // The ends of a run of 2 splice_, the interior's gain between them.
    const std::vector<double>& ends = RunGain(2 * splice_);
    gain.assign(n, interior_gain_);
    for (std::size_t t = 0; t < splice_; ++t) {
      gain[t] = ends[t];
      gain[n - 1 - t] = ends[2 * splice_ - 1 - t];
    }
  }
  return by_length_.emplace(n, std::move(gain)).first->second;
}

std::vector<double> ZeroLagNoiseGain::Relative(const double* x, std::size_t n, std::size_t stride) {
  std::vector<double> out(n, std::numeric_limits<double>::quiet_NaN());
  for (const auto& [begin, end] : FiniteRuns(x, n, stride)) {
    if (end - begin < min_run_) {
      for (std::size_t j = begin; j < end; ++j) out[j] = 1.0 / interior_gain_;
    } else {
      const std::vector<double>& gain = RunGain(end - begin);
      for (std::size_t j = begin; j < end; ++j) out[j] = gain[j - begin] / interior_gain_;
    }
  }
  return out;
}

std::vector<Gap> FindGaps(const double* x, std::size_t n, std::size_t stride) {
  // What lies between the finite runs.
  std::vector<Gap> gaps;
  std::size_t next = 0;
  for (const auto& [begin, end] : FiniteRuns(x, n, stride)) {
    if (begin > next) gaps.push_back({next, begin - next});
    next = end;
  }
  if (next < n) gaps.push_back({next, n - next});
  return gaps;
}

bool FillGapBySpline(double* x, std::size_t n, const Gap& gap, std::size_t context,
                     std::size_t stride) {
  CCSRM_CHECK(gap.length > 0 && gap.first + gap.length <= n && context >= 1);
  if (gap.first == 0 || gap.first + gap.length >= n) return false;
  std::vector<double> index;
  std::vector<double> value;
  // Samples before the gap, nearest last, stopping at the previous NaN.
  std::size_t begin = gap.first;
  while (begin > 0 && gap.first - begin < context && std::isfinite(x[(begin - 1) * stride])) {
    --begin;
  }
  for (std::size_t j = begin; j < gap.first; ++j) {
    index.push_back(static_cast<double>(j));
    value.push_back(x[j * stride]);
  }
  const std::size_t after = gap.first + gap.length;
  for (std::size_t j = after; j < n && j - after < context && std::isfinite(x[j * stride]); ++j) {
    index.push_back(static_cast<double>(j));
    value.push_back(x[j * stride]);
  }
  const Interpolator interpolate(index.data(), value.data(), index.size(), true);
  for (std::size_t j = gap.first; j < after; ++j)
    x[j * stride] = interpolate(static_cast<double>(j));
  return true;
}

std::vector<double> Resample(const std::vector<double>& time, const std::vector<double>& values,
                             const std::vector<double>& new_time, Interpolation interpolation) {
  CCSRM_CHECK(time.size() == values.size());
  std::vector<double> out(new_time.size(), kNaN);
  std::size_t i = 0;
  while (i < values.size()) {
    if (!std::isfinite(values[i])) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < values.size() && std::isfinite(values[end])) ++end;
    const double t0 = time[i];
    const double t1 = time[end - 1];
    if (end - i == 1) {
      for (std::size_t q = 0; q < new_time.size(); ++q) {
        if (new_time[q] == t0) out[q] = values[i];
      }
    } else {
      const Interpolator interpolate(time.data() + i, values.data() + i, end - i,
                                     interpolation == Interpolation::kCubic);
      for (std::size_t q = 0; q < new_time.size(); ++q) {
        if (new_time[q] >= t0 && new_time[q] <= t1) out[q] = interpolate(new_time[q]);
      }
    }
    i = end;
  }
  return out;
}

datasets::Array ResampleFrames(const datasets::Array& frames, const std::vector<double>& time,
                               const std::vector<double>& new_time, Interpolation interpolation) {
  CCSRM_CHECK(frames.rank() >= 1 && frames.rows() == time.size());
  std::vector<std::size_t> shape = frames.shape;
  shape[0] = new_time.size();
  datasets::Array out(shape);
  const std::size_t columns = frames.rows() == 0 ? 0 : frames.size() / frames.rows();
  std::vector<double> column(frames.rows());
  for (std::size_t c = 0; c < columns; ++c) {
    for (std::size_t f = 0; f < frames.rows(); ++f) column[f] = frames.values[f * columns + c];
    const std::vector<double> resampled = Resample(time, column, new_time, interpolation);
    for (std::size_t f = 0; f < new_time.size(); ++f) out.values[f * columns + c] = resampled[f];
  }
  return out;
}

}  // namespace ccsrm::mocap
