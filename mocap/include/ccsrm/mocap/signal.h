#pragma once
// One-dimensional signal tools of the mocap pipeline: zero-lag Butterworth
// low-pass filtering, cubic-spline gap filling and resampling. Signals are
// sampled at a uniform rate unless a time vector is given; NaN marks a sample
// that was not seen.
#include <cstddef>
#include <map>
#include <vector>

#include "ccsrm/datasets/array.h"

namespace ccsrm::mocap {

// One second-order section y = (b0 + b1 z⁻¹ + b2 z⁻²) / (1 + a1 z⁻¹ + a2 z⁻²) x.
// A first-order section has b2 = a2 = 0.
struct BiquadSection {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0;
  double a1 = 0.0, a2 = 0.0;
};

// Digital Butterworth low-pass of `order` (1..8) with its -3 dB point at
// cutoff_hz, by the bilinear transform with the cutoff pre-warped, as a
// cascade of sections each of unity gain at DC. Requires 0 < cutoff_hz <
// sample_rate_hz / 2 (checked, aborts: callers validate user input first).
std::vector<BiquadSection> DesignButterworthLowPass(int order, double cutoff_hz,
                                                    double sample_rate_hz);

// Frames of padding FiltFilt adds at each end of a run of n samples: about
// three cutoff periods, so the start-up transient dies out in the padding.
std::size_t FiltFiltPadding(double cutoff_hz, double sample_rate_hz, std::size_t n);

// Samples of the straight-line fit that fixes each end's pivot: half a
// cutoff period (at most n), short enough for the signal to be nearly linear
// there, long enough to average the noise of the end sample away.
std::size_t FiltFiltEndWindow(double cutoff_hz, double sample_rate_hz, std::size_t n);

// Zero-lag filtering of x[0..n) in place: the cascade forward, then backward
// (so the phase cancels and the gain is squared: -6 dB at the cutoff). Each
// end is padded with `pad` samples (capped at n - 1) reflected oddly about a
// pivot: the value at the end of a least-squares line through the first (or
// last) `end_window` samples. Reflecting about the raw end sample instead
// (end_window = 1, scipy's filtfilt) pins the output to that sample's noise
// there. The reflection continues the signal's level and slope, and every
// pass starts from the steady state of its first sample: a constant passes
// unchanged, a ramp with a start-up error that decays inside the padding.
// Requires finite samples; n < 2 leaves x as it is.
void FiltFilt(const std::vector<BiquadSection>& sections, double* x, std::size_t n, std::size_t pad,
              std::size_t end_window = 1);

// Zero-lag low-pass of a signal with NaN gaps: every run of at least min_run
// finite samples is filtered on its own (FiltFilt, padding and end window
// from FiltFiltPadding and FiltFiltEndWindow); shorter runs stay as they are, NaN stays NaN.
// `stride` is the distance between consecutive samples in `x`.
void ZeroLagLowPass(const std::vector<BiquadSection>& sections, double cutoff_hz,
                    double sample_rate_hz, double* x, std::size_t n, std::size_t stride = 1,
                    std::size_t min_run = 2);

// How much white noise ZeroLagLowPass leaves at each sample, relative to
// what it leaves far from any end. FiltFilt is one linear operator A on a run
// of n finite samples, and independent noise of equal variance σ² leaves
// σ² Σ_k A_ik² at sample i. Inside a run that is the interior gain g² = Σ h²
// of the forward-backward kernel h; near an end the pivot (a line's end over
// FiltFiltEndWindow samples) and the one-sided support leave up to about
// twice the interior's noise (docs/model-notes.md, "Recording edges"). A
// comparison that weighs every frame alike takes those ends for structure;
// dividing a residual by this profile gives every frame the interior's noise.
// Profiles are computed exactly (one impulse per column of A that the ends
// touch) and kept per run length.
class ZeroLagNoiseGain {
 public:
  ZeroLagNoiseGain(std::vector<BiquadSection> sections, double cutoff_hz, double sample_rate_hz,
                   std::size_t min_run = 2);

  // Per sample of x[0], x[stride], ... x[(n-1)·stride]: the noise the
  // low-pass leaves there over the interior's; NaN where x is NaN. A run
  // shorter than min_run, which ZeroLagLowPass leaves unfiltered, keeps its
  // raw noise: 1 / interior_gain().
  std::vector<double> Relative(const double* x, std::size_t n, std::size_t stride = 1);

  // sqrt(Σ h²): the standard deviation the low-pass leaves of unit white noise.
  double interior_gain() const { return interior_gain_; }

 private:
  // sqrt(Σ_k A_ik²) at every sample i of a run of n samples.
  const std::vector<double>& RunGain(std::size_t n);
  std::vector<double> ExactRunGain(std::size_t n) const;

  std::vector<BiquadSection> sections_;
  double cutoff_hz_ = 0.0;
  double sample_rate_hz_ = 0.0;
  std::size_t min_run_ = 2;
  std::size_t reach_ = 0;                 // kernel half-width kept: two paddings
  std::vector<double> kernel_sq_prefix_;  // Σ h(d)² for d < t - reach_, t = 0..2 reach_ + 1
  double interior_gain_ = 1.0;
  std::size_t splice_ = 0;  // runs longer than 2 splice_ share their end profiles
  std::map<std::size_t, std::vector<double>> by_length_;  // run length → gain
};

// A run of consecutive NaN samples.
struct Gap {
  std::size_t first = 0;   // index of its first sample
  std::size_t length = 0;  // samples
};

// The NaN runs of x[0], x[stride], ... x[(n-1)·stride], in order.
std::vector<Gap> FindGaps(const double* x, std::size_t n, std::size_t stride = 1);

// Fills the gap from a natural cubic spline (GSL) through up to `context`
// finite samples on each side of it (only the finite run adjacent to the
// gap), over the sample index; with fewer than three samples in all it
// interpolates linearly. A gap that touches either end of the signal has
// nothing to interpolate from: it is left as it is and false is returned.
bool FillGapBySpline(double* x, std::size_t n, const Gap& gap, std::size_t context,
                     std::size_t stride = 1);

enum class Interpolation { kLinear, kCubic };

// Values of the signal (time[i], values[i]) at new_time. Time must be strictly
// increasing. Each run of finite values is interpolated on its own (kCubic: a
// natural cubic spline, linear for a run of two samples); a new time outside
// every run (before the first or after the last sample, or inside a NaN gap)
// gets NaN: nothing is extrapolated.
std::vector<double> Resample(const std::vector<double>& time, const std::vector<double>& values,
                             const std::vector<double>& new_time, Interpolation interpolation);

// Resample applied to every column of a frames-first array (F × ...), giving
// an array of new_time.size() frames with the same trailing shape.
datasets::Array ResampleFrames(const datasets::Array& frames, const std::vector<double>& time,
                               const std::vector<double>& new_time, Interpolation interpolation);

}  // namespace ccsrm::mocap
