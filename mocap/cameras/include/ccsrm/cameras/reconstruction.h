#pragma once
// From calibrated videos to labelled 3D markers: blob detection with
// sub-pixel centroids, undistortion, cross-view correspondence under epipolar
// constraints, N-view triangulation (DLT, then Gauss-Newton on the
// reprojection error), and labelling to the rigid bodies of a marker layout
// (pattern distances, the kinematic chain, and tracking over time).
//
// Failure policy: a marker that is not seen by two consistent views, whose
// correspondence is ambiguous, or that does not fit its body's pattern is NaN
// in that frame, never a wrong point.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

#include "ccsrm/cameras/camera_model.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/marker_table.h"
#include "ccsrm/mocap/recording.h"
#include "ccsrm/sim/model.h"

namespace ccsrm::cameras {

// ---- Blob detection -------------------------------------------------------------

struct BlobDetectionOptions {
  // A pixel belongs to a blob when it is this far above the background
  // [gray levels]. The background is the median of a sparse grid of pixels.
  double threshold_level = 40.0;
  // Accepted blob areas (pixels above threshold).
  int min_area_px = 2;
  int max_area_px = 600;
  // The centroid uses every pixel within this margin around the thresholded
  // region [px], so the faint tails of a spot count too.
  int window_margin_px = 3;
  // Blobs this close to the image border are dropped: their centroid is
  // biased by the clipped spot [px].
  int border_margin_px = 3;
  // Blobs whose principal standard deviations differ by more than this
  // ratio are dropped: two spots merged into one would give a wrong point.
  double max_elongation = 1.25;

  bool IsValid(std::string* error) const;
};

struct Blob {
  Eigen::Vector2d uv_px;   // intensity-weighted centroid, OpenCV pixel centres
  double intensity = 0.0;  // summed gray levels above the background
  int area_px = 0;
};

// Bright blobs of an 8-bit gray image: threshold + connected components +
// intensity-weighted centroid. Requires CV_8UC1 (checked, aborts).
std::vector<Blob> DetectBlobs(const cv::Mat& gray, const BlobDetectionOptions& options = {});

// ---- Triangulation ------------------------------------------------------------------

struct TriangulationOptions {
  // Largest distance of an observation from the epipolar line of its partner
  // [px, undistorted, in the partner camera's focal length].
  double epipolar_tolerance_px = 1.5;
  // Largest reprojection error of any view of an accepted point [px].
  double reprojection_tolerance_px = 1.5;
  // A point needs at least this many views (>= 2).
  int min_views = 2;
  // Gauss-Newton iterations after the DLT.
  int refinement_iterations = 8;
  // Points nearer to a camera than this are rejected [m].
  double min_depth_m = 0.05;

  bool IsValid(std::string* error) const;
};

// One observation of a 3D point: detection `blob` of camera `camera`.
struct View {
  int camera = 0;
  int blob = 0;
};

struct TriangulatedPoint {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  // m
  std::vector<View> views;
  // RMS reprojection error over the views [px].
  double rms_reprojection_px = 0.0;
  // RMS distance of the point from the views' rays [m] (the C3D residual).
  double ray_residual_m = 0.0;
};

// Linear N-view triangulation (DLT, SVD) from normalized undistorted
// coordinates xy[i] seen by cameras with extrinsics R_CW[i], p_CW[i].
Eigen::Vector3d TriangulateDlt(const std::vector<Eigen::Matrix3d>& R_CW,
                               const std::vector<Eigen::Vector3d>& p_CW,
                               const std::vector<Eigen::Vector2d>& xy);

// Gauss-Newton refinement of p_W minimising the reprojection error in
// undistorted pixels (normalized error scaled by each camera's focal
// lengths). Returns the refined point.
Eigen::Vector3d RefineTriangulation(const std::vector<const Camera*>& cameras,
                                    const std::vector<Eigen::Vector2d>& xy,
                                    const Eigen::Vector3d& p_W_initial, int iterations);

// Every 3D point of one frame: detections per camera (pixels) are
// undistorted, matched across views by epipolar constraints and verified in
// the other views, then triangulated. Each detection is used at most once.
// Points with more views are accepted first; two candidates that share a
// detection are both dropped unless one is clearly right (the same point
// through other views, or the only one that no other camera should have
// seen).
std::vector<TriangulatedPoint> TriangulateFrame(
    const CameraRig& rig, const std::vector<std::vector<Eigen::Vector2d>>& uv_px,
    const TriangulationOptions& options = {});

// ---- Labelling ----------------------------------------------------------------------

struct LabellingOptions {
  // Two marker distances of a body match when they differ by less than this [m].
  double pattern_tolerance_m = 0.003;
  // Markers further than this from their body's fitted pattern are dropped [m].
  double max_fit_error_m = 0.002;
  // A link's plate lies at most this far from the previous link's in the
  // chain [m]. Must lie between one link spacing and two (the default suits
  // links of 0.07-0.13 m; ccsrm cameras reconstruct derives it from the arm).
  double max_link_spacing_m = 0.135;
  // A body tracked in the previous frame is found again within this distance
  // of its predicted position [m] (well under the spacing of two plates).
  double reacquire_gate_m = 0.03;
  // A single marker is matched to its prediction within this distance [m].
  double marker_gate_m = 0.004;
  // A link's pose differs from its neighbour's (and from its prediction) by
  // less than this rotation [deg]: joints bend by a few degrees, a plate
  // formed by chance from other markers usually does not.
  double max_relative_rotation_deg = 30.0;
  // A body not seen is still predicted (constant velocity) for this many
  // frames; after that it is found again only by the chain.
  int max_prediction_frames = 10;

  bool IsValid(std::string* error) const;
};

// Labels the 3D points of successive frames with the markers of a layout.
// Bodies are found by their pattern of marker distances (all link plates may
// share one pattern), assigned to links along the kinematic chain from the
// ground (W's origin is joint 1) or by tracking their pose from the previous
// frames, and checked by a rigid fit.
class MarkerLabeller {
 public:
  MarkerLabeller(mocap::MarkerLayout layout, LabellingOptions options);

  // Positions of every layout marker (MarkerNames() order) for the next
  // frame; NaN where not found. label_of_point (when not null) receives, per
  // input point, the marker index it was given or -1.
  std::vector<Eigen::Vector3d> LabelFrame(const std::vector<Eigen::Vector3d>& points,
                                          std::vector<int>* label_of_point = nullptr);

  const mocap::MarkerLayout& layout() const { return layout_; }

 private:
  struct BodyTrack {
    bool valid = false;         // a pose was seen within max_prediction_frames
    bool has_velocity = false;  // the two last poses were in consecutive frames
    int frames_since_seen = 0;
    Eigen::Matrix3d R_WB = Eigen::Matrix3d::Identity();  // last pose seen
    Eigen::Vector3d p_WB = Eigen::Vector3d::Zero();
    Eigen::Matrix3d dR_per_frame = Eigen::Matrix3d::Identity();  // world increment
    Eigen::Vector3d v_per_frame = Eigen::Vector3d::Zero();       // m per frame
  };
  struct Frame;
  bool PredictPose(std::size_t body, Eigen::Matrix3d* R_WB, Eigen::Vector3d* p_WB) const;

  mocap::MarkerLayout layout_;
  LabellingOptions options_;
  std::vector<std::size_t> first_marker_;  // per body, index of its first marker
  std::vector<int> pattern_of_body_;       // bodies with equal p_BM share a pattern
  std::vector<BodyTrack> tracks_;
};

// ---- The whole pipeline ---------------------------------------------------------------

// LabellingOptions::max_link_spacing_m for an arm: halfway between its
// longest link and twice its shortest, so a plate is never looked for beyond
// the next link.
double MaxLinkSpacing(const sim::ArmModel& model);

struct ReconstructionOptions {
  BlobDetectionOptions detection;
  TriangulationOptions triangulation;
  LabellingOptions labelling;
  // Frames to process: from first_frame, at most max_frames (0 = all).
  std::size_t first_frame = 0;
  std::size_t max_frames = 0;
  // Called after each frame with (frames done, frames expected or 0).
  std::function<void(std::size_t, std::size_t)> progress;

  bool IsValid(std::string* error) const;
};

struct CameraQuality {
  std::string name;
  std::size_t frames_read = 0;
  // Frames with no detection at all (a dropped or black frame), plus the
  // frames missing at the end of a shorter video.
  std::size_t empty_frames = 0;
  std::size_t detections = 0;
  // Detections that went into a labelled marker.
  std::size_t used_detections = 0;
  // RMS reprojection error of the labelled markers in this camera [px].
  double reprojection_rms_px = 0.0;
};

struct MarkerQuality {
  std::string label;
  double visibility = 0.0;           // fraction of frames with a position
  double mean_views = 0.0;           // cameras per reconstructed sample
  double mean_ray_residual_m = 0.0;  // triangulation residual (ray distance)
};

struct ReconstructionQuality {
  std::size_t frames = 0;
  std::vector<CameraQuality> cameras;
  std::vector<MarkerQuality> markers;
  std::size_t triangulated_points = 0;
  // Triangulated points that matched no marker of the layout.
  std::size_t unlabelled_points = 0;
  double wall_time_s = 0.0;
  double frames_per_second = 0.0;
  std::vector<std::string> warnings;

  // A few lines: frames, speed, per-camera reprojection RMS and detections,
  // visibility and residual ranges over the markers.
  std::string BriefReport() const;
};

struct ReconstructionResult {
  // As the file readers give: metres, NaN where not seen, labels in layout
  // order, rate from the rig; has_residual with the ray residual and the
  // cameras that saw each sample (bit i = camera i + 1, first 7 cameras, as in C3D).
  mocap::MarkerTable markers;
  ReconstructionQuality quality;
};

// Reconstructs the layout's markers from one video per camera (rig order).
// Throws InputError when the options are invalid, the number of videos is
// not the number of cameras, a video cannot be read, or its frame size
// differs from its camera's. A shorter video counts as a camera that stopped
// (its missing frames are empty; a warning says so).
ReconstructionResult ReconstructMarkers(const CameraRig& rig,
                                        const std::vector<std::string>& videos,
                                        const mocap::MarkerLayout& layout,
                                        const ReconstructionOptions& options = {});

// The camera front end as the marker source of mocap::ProcessRecording
// (`ccsrm mocap process --cameras`): when called, loads the rig from
// `cameras_file` (LoadCameraRig), sets options.labelling.max_link_spacing_m
// from the arm when the model is known (MaxLinkSpacing), reconstructs the
// layout's markers from `videos` (ReconstructMarkers) and reports the
// quality's BriefReport. Throws what those throw.
mocap::MarkerReconstruction VideoMarkerSource(std::string cameras_file,
                                              std::vector<std::string> videos,
                                              ReconstructionOptions options = {});

// The same from blob detections already made: detections[frame][camera].
ReconstructionResult ReconstructMarkersFromDetections(
    const CameraRig& rig, const std::vector<std::vector<std::vector<Eigen::Vector2d>>>& detections,
    const mocap::MarkerLayout& layout, const ReconstructionOptions& options = {});

}  // namespace ccsrm::cameras
