#pragma once
// Reading and writing camera videos with OpenCV's videoio (FFmpeg backend).
// Videos are written as FFV1 in AVI: lossless, so a rendered frame reads back
// bit-identical (Debian's OpenCV/FFmpeg has the encoder). Readers accept any
// video OpenCV can decode, or an image sequence given as a printf pattern
// ("frames/cam1_%04d.png").
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include <string>

namespace ccsrm::cameras {

// Writes 8-bit gray frames to a temporary file beside `path`; Commit()
// renames it onto `path`. Destroyed without Commit(), it removes the
// temporary, so `path` is either untouched or complete.
class VideoFileWriter {
 public:
  // Throws InputError when the video cannot be created.
  VideoFileWriter(std::string path, double frame_rate_hz, int width_px, int height_px);
  ~VideoFileWriter();
  VideoFileWriter(VideoFileWriter&& other) noexcept;
  VideoFileWriter& operator=(VideoFileWriter&&) = delete;
  VideoFileWriter(const VideoFileWriter&) = delete;
  VideoFileWriter& operator=(const VideoFileWriter&) = delete;

  // Requires an 8-bit single-channel frame of the size given at creation
  // (checked, aborts).
  void Write(const cv::Mat& gray);
  // Closes the video and renames it into place. Throws InputError.
  void Commit();

 private:
  std::string path_;
  std::string temp_path_;
  int width_px_ = 0;
  int height_px_ = 0;
  cv::VideoWriter writer_;
  bool committed_ = false;
};

// Reads the frames of one camera as 8-bit gray images.
class VideoFrameReader {
 public:
  // Throws InputError "<path>: cannot open video (...)" when OpenCV cannot
  // open or decode it, or when it has no frame.
  explicit VideoFrameReader(std::string path);

  const std::string& path() const { return path_; }
  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }
  // Frames the container reports (may be 0 or an estimate for some formats).
  long reported_frames() const { return reported_frames_; }
  double reported_fps() const { return reported_fps_; }

  // Reads the next frame into *gray (CV_8UC1). Returns false at the end of
  // the video. Throws InputError when a frame has another size than the
  // first one.
  bool Read(cv::Mat* gray);

 private:
  std::string path_;
  cv::VideoCapture capture_;
  cv::Mat first_;
  bool first_pending_ = false;
  int width_px_ = 0;
  int height_px_ = 0;
  long reported_frames_ = 0;
  double reported_fps_ = 0.0;
  long frames_read_ = 0;
};

}  // namespace ccsrm::cameras
