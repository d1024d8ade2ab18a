#include "ccsrm/cameras/video_io.h"

#include <unistd.h>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "ccsrm/common/error.h"

namespace ccsrm::cameras {
namespace {
std::atomic<int> temp_counter{0};
}

VideoFileWriter::VideoFileWriter(std::string path, double frame_rate_hz, int width_px,
                                 int height_px)
    : path_(std::move(path)), width_px_(width_px), height_px_(height_px) {
  namespace fs = std::filesystem;
  const fs::path target(path_);
  if (!target.parent_path().empty() && !fs::is_directory(target.parent_path())) {
    ThrowInputError(path_, "",
                    "output directory '" + target.parent_path().string() + "' does not exist");
  }
  // FFmpeg picks the container from the extension, so the temporary keeps it.
  temp_path_ = (target.parent_path() /
                ("." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(temp_counter.fetch_add(1)) + target.extension().string()))
                   .string();
  writer_.open(temp_path_, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
               frame_rate_hz, cv::Size(width_px, height_px), false);
  if (!writer_.isOpened()) {
    std::remove(temp_path_.c_str());
    ThrowInputError(path_, "", "cannot create an FFV1 video (is OpenCV built with FFmpeg?)");
  }
}

VideoFileWriter::~VideoFileWriter() {
  if (!committed_ && !temp_path_.empty()) {
    writer_.release();
    std::remove(temp_path_.c_str());
  }
}

VideoFileWriter::VideoFileWriter(VideoFileWriter&& other) noexcept
    : path_(std::move(other.path_)),
      temp_path_(std::move(other.temp_path_)),
      width_px_(other.width_px_),
      height_px_(other.height_px_),
      writer_(std::move(other.writer_)),
      committed_(other.committed_) {
  other.temp_path_.clear();
  other.committed_ = true;
}

void VideoFileWriter::Write(const cv::Mat& gray) {
  CCSRM_CHECK(gray.type() == CV_8UC1 && gray.cols == width_px_ && gray.rows == height_px_);
  CCSRM_CHECK(!committed_);
  writer_.write(gray);
}

void VideoFileWriter::Commit() {
  writer_.release();
  if (std::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temp_path_.c_str());
    ThrowInputError(path_, "", "cannot rename temporary video into place: " + reason);
  }
  committed_ = true;
}

VideoFrameReader::VideoFrameReader(std::string path) : path_(std::move(path)) {
  const bool is_pattern = path_.find('%') != std::string::npos;
  if (!is_pattern && !std::filesystem::is_regular_file(path_)) {
    ThrowInputError(path_, "", "cannot open video (no such file)");
  }
  try {
    capture_.open(path_, is_pattern ? cv::CAP_IMAGES : cv::CAP_FFMPEG);
  } catch (const cv::Exception& e) {
    ThrowInputError(path_, "", "cannot open video (OpenCV: " + e.err + ")");
  }
  if (!capture_.isOpened()) {
    ThrowInputError(path_, "", "cannot open video (not a video OpenCV can decode)");
  }
  reported_frames_ = static_cast<long>(capture_.get(cv::CAP_PROP_FRAME_COUNT));
  reported_fps_ = capture_.get(cv::CAP_PROP_FPS);
  cv::Mat frame;
  bool ok = false;
  try {
    ok = capture_.read(frame);
  } catch (const cv::Exception& e) {
    ThrowInputError(path_, "frame 0", "cannot decode (OpenCV: " + e.err + ")");
  }
  if (!ok || frame.empty()) ThrowInputError(path_, "", "cannot open video (no decodable frame)");
  width_px_ = frame.cols;
  height_px_ = frame.rows;
  first_ = frame;
  first_pending_ = true;
}

bool VideoFrameReader::Read(cv::Mat* gray) {
  cv::Mat frame;
  if (first_pending_) {
    frame = first_;
    first_pending_ = false;
    first_.release();
  } else {
    bool ok = false;
    try {
      ok = capture_.read(frame);
    } catch (const cv::Exception& e) {
      ThrowInputError(path_, "frame " + std::to_string(frames_read_),
                      "cannot decode (OpenCV: " + e.err + ")");
    }
    if (!ok || frame.empty()) return false;
  }
  if (frame.cols != width_px_ || frame.rows != height_px_) {
    ThrowInputError(path_, "frame " + std::to_string(frames_read_),
                    "size changes within the video");
  }
  if (frame.channels() == 3) {
    cv::cvtColor(frame, *gray, cv::COLOR_BGR2GRAY);
  } else if (frame.channels() == 4) {
    cv::cvtColor(frame, *gray, cv::COLOR_BGRA2GRAY);
  } else {
    *gray = frame;
  }
  if (gray->depth() != CV_8U) {
    ThrowInputError(path_, "frame " + std::to_string(frames_read_), "expected 8-bit pixels");
  }
  ++frames_read_;
  return true;
}

}  // namespace ccsrm::cameras
