#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {

// Median of a sparse grid of pixels: the background of a dark frame with a
// few bright spots, at a fraction of the cost of a full median.
double BackgroundLevel(const cv::Mat& gray) {
  constexpr int kStep = 16;
  std::vector<unsigned char> samples;
  samples.reserve(static_cast<std::size_t>(gray.rows / kStep + 1) * (gray.cols / kStep + 1));
  for (int r = kStep / 2; r < gray.rows; r += kStep) {
    const unsigned char* row = gray.ptr<unsigned char>(r);
    for (int c = kStep / 2; c < gray.cols; c += kStep) samples.push_back(row[c]);
  }
  if (samples.empty()) return 0.0;
  auto middle = samples.begin() + samples.size() / 2;
  std::nth_element(samples.begin(), middle, samples.end());
  return *middle;
}

}  // namespace

bool BlobDetectionOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error != nullptr) *error = what;
    return false;
  };
  if (!(threshold_level > 0.0 && threshold_level < 255.0))
    return fail("detection threshold_level must be in (0, 255)");
  if (min_area_px < 1 || max_area_px < min_area_px)
    return fail("detection areas must satisfy 1 <= min_area_px <= max_area_px");
  if (window_margin_px < 0 || border_margin_px < 0) return fail("detection margins must be >= 0");
  if (!(max_elongation >= 1.0)) return fail("detection max_elongation must be >= 1");
  return true;
}

std::vector<Blob> DetectBlobs(const cv::Mat& gray, const BlobDetectionOptions& options) {
  CCSRM_CHECK(gray.type() == CV_8UC1);
  std::vector<Blob> blobs;
  if (gray.empty()) return blobs;
  const double background = BackgroundLevel(gray);
  const double level = background + options.threshold_level;
  if (level >= 255.0) return blobs;
  cv::Mat mask;
  cv::threshold(gray, mask, level, 255, cv::THRESH_BINARY);
  // Most frames are nearly empty: skip the labelling pass when nothing is lit.
  if (cv::countNonZero(mask) == 0) return blobs;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  for (int label = 1; label < count; ++label) {
    const int area = stats.at<int>(label, cv::CC_STAT_AREA);
    if (area < options.min_area_px || area > options.max_area_px) continue;
    const int left = stats.at<int>(label, cv::CC_STAT_LEFT);
    const int top = stats.at<int>(label, cv::CC_STAT_TOP);
    const int width = stats.at<int>(label, cv::CC_STAT_WIDTH);
    const int height = stats.at<int>(label, cv::CC_STAT_HEIGHT);
    const int margin = options.border_margin_px;
    if (left < margin || top < margin || left + width > gray.cols - margin ||
        top + height > gray.rows - margin) {
      continue;  // clipped by the border: the centroid would be biased
    }
    // Intensity-weighted moments over the region grown by the window margin,
    // leaving out pixels of other blobs.
    const int c0 = std::max(0, left - options.window_margin_px);
    const int r0 = std::max(0, top - options.window_margin_px);
    const int c1 = std::min(gray.cols - 1, left + width - 1 + options.window_margin_px);
    const int r1 = std::min(gray.rows - 1, top + height - 1 + options.window_margin_px);
    double sum = 0.0, su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
    for (int r = r0; r <= r1; ++r) {
      const unsigned char* row = gray.ptr<unsigned char>(r);
      const int* row_labels = labels.ptr<int>(r);
      for (int c = c0; c <= c1; ++c) {
        if (row_labels[c] != 0 && row_labels[c] != label) continue;
        const double w = row[c] - background;
        if (w <= 0.0) continue;
        sum += w;
        su += w * c;
        sv += w * r;
        suu += w * c * c;
        svv += w * r * r;
        suv += w * c * r;
      }
    }
    if (!(sum > 0.0)) continue;
    const double u = su / sum;
    const double v = sv / sum;
    const double cuu = suu / sum - u * u;
    const double cvv = svv / sum - v * v;
    const double cuv = suv / sum - u * v;
    // Principal variances of the spot: a merged pair is elongated.
    const double mean = 0.5 * (cuu + cvv);
    const double spread = std::sqrt(0.25 * (cuu - cvv) * (cuu - cvv) + cuv * cuv);
    const double major = mean + spread;
    const double minor = std::max(mean - spread, 1e-9);
    if (std::sqrt(major / minor) > options.max_elongation) continue;
    Blob blob;
    blob.uv_px = Eigen::Vector2d(u, v);
    blob.intensity = sum;
    blob.area_px = area;
    blobs.push_back(blob);
  }
  return blobs;
}

}  // namespace ccsrm::cameras
