// ccsrm cameras rig|render|render-board|calibrate board|calibrate markers|reconstruct
#include <unistd.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ccsrm/cameras/calibration.h"
#include "ccsrm/cameras/camera_model.h"
#include "ccsrm/cameras/reconstruction.h"
#include "ccsrm/cameras/video_io.h"
#include "ccsrm/cameras/virtual_rig.h"
#include "ccsrm/common/atomic_file.h"
#include "ccsrm/common/error.h"
#include "ccsrm/datasets/experiment_file.h"
#include "ccsrm/mocap/c3d.h"
#include "ccsrm/mocap/marker_layout.h"
#include "ccsrm/mocap/rigid_bodies.h"
#include "ccsrm/sim/config.h"
#include "ccsrm/sim/kinematics.h"
#include "ccsrm/sim/model.h"
#include "commands.h"
#include "option_checks.h"
#include "output_kinds.h"

namespace ccsrm::app {
namespace {

namespace fs = std::filesystem;

// "9x6" -> (9, 6); throws InputError naming the option.
std::pair<int, int> ParseBoardSize(const std::string& text, const std::string& option) {
  int x = 0, y = 0;
  char sep = 0;
  if (std::sscanf(text.c_str(), "%d%c%d", &x, &sep, &y) != 3 || (sep != 'x' && sep != 'X') ||
      x < 3 || y < 3) {
    ThrowInputError(option, "",
                    "expected inner corners as COLSxROWS (e.g. 9x6), got '" + text + "'");
  }
  return {x, y};
}

// The board of `size_option` (inner corners) and `square_option` (square
// size [mm]); throws InputError naming the option at fault.
cameras::CheckerboardTarget MakeBoard(const std::string& size, const std::string& size_option,
                                      double square_mm, const std::string& square_option) {
  const auto [x, y] = ParseBoardSize(size, size_option);
  cameras::CheckerboardTarget board{x, y, square_mm * 1e-3};
  std::string reason;
  if (!board.IsValid(&reason)) ThrowInputError(square_option, "", reason);
  return board;
}

// cv::imwrite picks the format from the extension, so the temporary keeps it.
void WritePngAtomically(const std::string& path, const cv::Mat& image) {
  const fs::path target(path);
  const std::string temp = (target.parent_path() / ("." + target.stem().string() + ".tmp-" +
                                                    std::to_string(::getpid()) + ".png"))
                               .string();
  if (!cv::imwrite(temp, image)) {
    std::remove(temp.c_str());
    ThrowInputError(path, "", "cannot write image");
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    ThrowInputError(path, "", "cannot rename temporary image into place");
  }
}

cv::Mat ReadGrayImage(const std::string& path) {
  if (!fs::is_regular_file(path)) ThrowInputError(path, "", "cannot open image (no such file)");
  const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) ThrowInputError(path, "", "cannot decode image");
  return image;
}

cameras::CameraRig RigFromOption(const std::string& path) {
  return path.empty() ? cameras::MakeVirtualRig() : cameras::LoadCameraRig(path);
}

// The marker layout from an arm configuration or an experiment's rigid bodies.
mocap::MarkerLayout LayoutFrom(const std::string& config, const std::string& experiment,
                               double* max_link_spacing_m) {
  if (!config.empty()) {
    const sim::ArmModel model(sim::LoadConfig(config).arm);
    *max_link_spacing_m = cameras::MaxLinkSpacing(model);
    return mocap::DefaultMarkerLayout(model);
  }
  const datasets::ExperimentFile file = datasets::ReadExperimentFile(experiment);
  if (file.rigid_bodies.empty())
    ThrowInputError(experiment, "/mocap/rigid_bodies", "no rigid body");
  return mocap::LayoutFromExperiment(file.rigid_bodies, experiment);
}

void AddRig(CLI::App& cameras) {
  CLI::App* rig = cameras.add_subcommand(
      "rig", "Write the default virtual rig (four cameras above the table) as a camera file");
  auto out = std::make_shared<std::string>();
  rig->add_option("--out", *out, "Camera file to write (OpenCV YAML)")->required();
  rig->callback([out] {
    CheckOut(*out, CameraFileOutput(), {});
    cameras::SaveCameraRig(*out, cameras::MakeVirtualRig());
    std::printf("wrote %s (4 cameras, 1280x1024)\n", out->c_str());
  });
}

void AddRender(CLI::App& cameras) {
  CLI::App* render = cameras.add_subcommand("render",
                                            "Render a run's or an experiment's markers through a "
                                            "camera rig into one lossless video per camera");
  struct Args {
    std::string in, rig, out;
    double noise_px = 0.2;
    double drop = 0.0;
    std::uint64_t seed = 1;
    std::size_t first = 0, stride = 1, frames = 0;
  };
  auto args = std::make_shared<Args>();
  render->add_option("--in", args->in, "ccsrm-run/1 or ccsrm-dataset/1 file")->required();
  render->add_option("--rig", args->rig, "Camera file (default: the virtual rig)");
  // Ranges from MarkerRenderOptions::IsValid, checked while parsing.
  using cameras::MarkerRenderOptions;
  render->add_option("--noise-px", args->noise_px, "Position noise of each spot [px]")
      ->capture_default_str()
      ->check(ValidIn(&MarkerRenderOptions::position_noise_px));
  render->add_option("--drop-probability", args->drop, "Probability that a camera drops a frame")
      ->capture_default_str()
      ->check(ValidIn(&MarkerRenderOptions::dropped_frame_probability));
  render->add_option("--seed", args->seed, "Noise seed")->capture_default_str();
  render->add_option("--first", args->first, "First frame of the input")->capture_default_str();
  render->add_option("--stride", args->stride, "Take every N-th frame")
      ->capture_default_str()
      ->check(AtLeast(1));
  render->add_option("--frames", args->frames, "At most this many frames (0 = all)")
      ->capture_default_str();
  render->add_option("--out", args->out, "Output directory (videos + cameras.yaml)")->required();
  render->callback([args] {
    CheckOut(args->out, RenderFolderOutput(), {args->in, args->rig});
    const cameras::CameraRig rig = RigFromOption(args->rig);
    const cameras::MarkerMotion motion =
        cameras::ReadMarkerMotion(args->in, {args->first, args->stride, args->frames});
    cameras::MarkerRenderOptions options;
    options.position_noise_px = args->noise_px;
    options.dropped_frame_probability = args->drop;
    options.seed = args->seed;
    const cameras::RenderSummary summary = cameras::RenderVideos(rig, motion, options, args->out);
    std::printf("rendered %zu frames of %zu markers at %.3f Hz\n", summary.frames,
                motion.marker_names.size(), motion.rate_hz);
    for (std::size_t c = 0; c < summary.video_paths.size(); ++c) {
      std::printf("  %s: %.1f %% of marker samples in view, %zu dropped frames\n",
                  summary.video_paths[c].c_str(), 100.0 * summary.in_view_fraction[c],
                  summary.dropped_frames[c]);
    }
    std::printf("seen by two or more cameras: %.1f %% of samples\ncamera file: %s\n",
                100.0 * summary.seen_by_two_fraction, summary.camera_file.c_str());
  });
}

void AddRenderBoard(CLI::App& cameras) {
  CLI::App* render = cameras.add_subcommand("render-board",
                                            "Render checkerboard views for calibration: hand-held "
                                            "views per camera and a board lying on the table");
  struct Args {
    std::string rig, out, board = "9x6", world_board = "11x8";
    double square_mm = 40.0, world_square_mm = 80.0;
    int views = 16;
    std::uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  render->add_option("--rig", args->rig, "Camera file (default: the virtual rig)");
  render->add_option("--board", args->board, "Hand-held board, inner corners COLSxROWS")
      ->capture_default_str();
  render->add_option("--square-mm", args->square_mm, "Its square size [mm]")
      ->capture_default_str()
      ->check(Above(0.0, "mm"));
  render->add_option("--views", args->views, "Hand-held views per camera")
      ->capture_default_str()
      ->check(AtLeast(1));
  render->add_option("--world-board", args->world_board, "Board on the table, inner corners")
      ->capture_default_str();
  render->add_option("--world-square-mm", args->world_square_mm, "Its square size [mm]")
      ->capture_default_str()
      ->check(Above(0.0, "mm"));
  render->add_option("--seed", args->seed, "Seed of the poses and noise")->capture_default_str();
  render->add_option("--out", args->out, "Output directory")->required();
  render->callback([args] {
    CheckOut(args->out, BoardImagesFolderOutput(), {args->rig});
    const cameras::CameraRig rig = RigFromOption(args->rig);
    const cameras::CheckerboardTarget board =
        MakeBoard(args->board, "--board", args->square_mm, "--square-mm");
    const cameras::CheckerboardTarget world =
        MakeBoard(args->world_board, "--world-board", args->world_square_mm, "--world-square-mm");
    const auto [R_WG, p_WG] = cameras::DefaultWorldBoardPose(world);
    // The images appear together or not at all, replacing earlier ones.
    AtomicOutputDirectory folder(args->out);
    const fs::path images(folder.temp_path());
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      const cameras::Camera& camera = rig.cameras[c];
      cameras::CheckerboardRenderOptions options;
      int view = 0;
      for (const auto& [R_CG, p_CG] :
           cameras::CalibrationBoardPoses(camera, board, args->views, args->seed + 101 * c)) {
        options.seed = args->seed * 7919 + 1000 * c + view;
        char name[64];
        std::snprintf(name, sizeof name, "%s_view%02d.png", camera.name.c_str(), view++);
        WritePngAtomically((images / name).string(),
                           cameras::RenderCheckerboard(camera, board, R_CG, p_CG, options));
      }
      options.seed = args->seed * 7919 + 1000 * c + 999;
      WritePngAtomically((images / (camera.name + "_world.png")).string(),
                         cameras::RenderCheckerboard(camera, world, camera.R_CW * R_WG,
                                                     camera.R_CW * p_WG + camera.p_CW, options));
      std::printf("%s: %d hand-held views and the world board\n", camera.name.c_str(), view);
    }
    folder.Commit();
    std::printf("world board corner (0, 0) at W (%.4f, %.4f, %.4f) m, its x along +z, y along +y\n",
                p_WG.x(), p_WG.y(), p_WG.z());
  });
}

void AddCalibrate(CLI::App& cameras) {
  CLI::App* calibrate =
      cameras.add_subcommand("calibrate", "Calibrate cameras (prints reprojection errors)");
  calibrate->require_subcommand(1);

  CLI::App* board_cmd = calibrate->add_subcommand(
      "board",
      "Intrinsics of one camera from checkerboard images (cv::calibrateCamera), and its pose in W "
      "when a board on the table is given");
  struct BoardArgs {
    std::string name = "cam1", board = "9x6", world_image, world_board = "11x8", rig, out;
    std::vector<std::string> images;
    double square_mm = 40.0, world_square_mm = 80.0;
    std::vector<double> world_origin;
    bool fit_k3 = false;
  };
  auto b = std::make_shared<BoardArgs>();
  board_cmd->add_option("--name", b->name, "Camera name")->capture_default_str();
  board_cmd->add_option("--images", b->images, "Images of the hand-held board")->required();
  board_cmd->add_option("--board", b->board, "Inner corners COLSxROWS")->capture_default_str();
  board_cmd->add_option("--square-mm", b->square_mm, "Square size [mm]")
      ->capture_default_str()
      ->check(Above(0.0, "mm"));
  board_cmd->add_option("--world-image", b->world_image, "Image of the board lying on the table");
  board_cmd->add_option("--world-board", b->world_board, "Its inner corners")
      ->capture_default_str();
  board_cmd->add_option("--world-square-mm", b->world_square_mm, "Its square size [mm]")
      ->capture_default_str()
      ->check(Above(0.0, "mm"));
  board_cmd
      ->add_option(
          "--world-origin", b->world_origin,
          "Its corner (0, 0) in W [m] (x y z; default: as ccsrm cameras render-board places it)")
      ->expected(3);
  board_cmd->add_flag("--fit-k3", b->fit_k3, "Fit the k3 distortion coefficient too");
  board_cmd->add_option("--rig", b->rig,
                        "Camera file to update (the camera of this name is replaced or added)");
  board_cmd->add_option("--out", b->out, "Camera file to write")->required();
  board_cmd->callback([b] {
    std::vector<std::string> inputs = b->images;
    inputs.push_back(b->world_image);
    inputs.push_back(b->rig);
    CheckOut(b->out, CameraFileOutput(), inputs);
    const cameras::CheckerboardTarget board =
        MakeBoard(b->board, "--board", b->square_mm, "--square-mm");
    std::vector<cv::Mat> images;
    for (const std::string& path : b->images) images.push_back(ReadGrayImage(path));
    cameras::IntrinsicCalibrationOptions options;
    options.fit_k3 = b->fit_k3;
    cameras::IntrinsicCalibration result;
    if (b->world_image.empty()) {
      result = cameras::CalibrateIntrinsics(images, b->images, board, b->name, options);
    } else {
      cameras::WorldBoardView world;
      world.board =
          MakeBoard(b->world_board, "--world-board", b->world_square_mm, "--world-square-mm");
      world.image = ReadGrayImage(b->world_image);
      world.name = b->world_image;
      std::tie(world.R_WG, world.p_WG) = cameras::DefaultWorldBoardPose(world.board);
      if (!b->world_origin.empty()) {
        world.p_WG = Eigen::Vector3d(b->world_origin[0], b->world_origin[1], b->world_origin[2]);
      }
      const auto [intrinsics, pose] =
          cameras::CalibrateCameraInWorld(images, b->images, board, world, b->name, options);
      result = intrinsics;
      const Eigen::Vector3d p_WC = result.camera.p_WC();
      std::printf(
          "world board: reprojection RMS %.3f px over %zu corners; camera centre in W (%.4f, %.4f, "
          "%.4f) m\n",
          pose.rms_reprojection_px, pose.correspondences, p_WC.x(), p_WC.y(), p_WC.z());
    }
    std::printf("%s: reprojection RMS %.3f px over %zu views (%zu without the board)\n",
                b->name.c_str(), result.rms_reprojection_px, result.used_images.size(),
                result.rejected_images.size());
    for (std::size_t i = 0; i < result.used_images.size(); ++i) {
      std::printf("  %-40s %.3f px\n", result.used_images[i].c_str(), result.per_view_rms_px[i]);
    }
    for (const std::string& name : result.rejected_images)
      std::printf("  %-40s board not found\n", name.c_str());
    const cameras::Camera& camera = result.camera;
    std::printf("fx %.2f fy %.2f cx %.2f cy %.2f px; distortion", camera.fx(), camera.fy(),
                camera.K(0, 2), camera.K(1, 2));
    for (double d : camera.distortion) std::printf(" %.5g", d);
    std::printf("\n");
    cameras::CameraRig rig;
    if (!b->rig.empty()) rig = cameras::LoadCameraRig(b->rig);
    bool replaced = false;
    for (cameras::Camera& existing : rig.cameras) {
      if (existing.name == camera.name) {
        existing = camera;
        replaced = true;
      }
    }
    if (!replaced) rig.cameras.push_back(camera);
    cameras::SaveCameraRig(b->out, rig);
    std::printf("wrote %s\n", b->out.c_str());
  });

  CLI::App* markers_cmd =
      calibrate->add_subcommand("markers",
                                "Refine every camera's pose in W from the first frames of its "
                                "video (arm straight at rest, ground markers) with solvePnP");
  struct MarkerArgs {
    std::string cameras, config, out;
    std::vector<std::string> videos;
    int frames = 10;
    bool base_only = false;
  };
  auto m = std::make_shared<MarkerArgs>();
  markers_cmd->add_option("--cameras", m->cameras, "Camera file with intrinsics and rough poses")
      ->required();
  markers_cmd->add_option("--video", m->videos, "One video per camera, in camera-file order")
      ->required();
  markers_cmd->add_option("--config", m->config, "Arm configuration (marker layout, straight arm)")
      ->required();
  markers_cmd->add_option("--frames", m->frames, "Frames at the start to use (arm at rest)")
      ->capture_default_str()
      ->check(AtLeast(1));
  markers_cmd->add_flag("--base-only", m->base_only,
                        "Use only the ground markers (the arm may move)");
  markers_cmd->add_option("--out", m->out, "Camera file to write")->required();
  markers_cmd->callback([m] {
    std::vector<std::string> inputs = m->videos;
    inputs.push_back(m->cameras);
    inputs.push_back(m->config);
    CheckOut(m->out, CameraFileOutput(), inputs);
    cameras::CameraRig rig = cameras::LoadCameraRig(m->cameras);
    if (m->videos.size() != rig.cameras.size()) {
      ThrowInputError(m->cameras, "cameras",
                      std::to_string(rig.cameras.size()) + " cameras but " +
                          std::to_string(m->videos.size()) + " videos");
    }
    const sim::ArmModel model(sim::LoadConfig(m->config).arm);
    const mocap::MarkerLayout layout = mocap::DefaultMarkerLayout(model);
    const sim::JointAngles straight(model.num_joints(), Eigen::Vector2d::Zero());
    std::vector<Eigen::Vector3d> reference =
        mocap::PlaceMarkers(layout, sim::ForwardKinematics(model, straight));
    if (m->base_only)
      reference.resize(
          layout.bodies.empty() || layout.bodies[0].link != 0 ? 0 : layout.bodies[0].p_BM.size());
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      cameras::VideoFrameReader reader(m->videos[c]);
      std::vector<std::vector<Eigen::Vector2d>> frames;
      cv::Mat gray;
      while (static_cast<int>(frames.size()) < m->frames && reader.Read(&gray)) {
        frames.emplace_back();
        for (const cameras::Blob& blob : cameras::DetectBlobs(gray))
          frames.back().push_back(blob.uv_px);
      }
      const Eigen::Vector3d before = rig.cameras[c].p_WC();
      const cameras::ExtrinsicCalibration pose =
          cameras::CalibrateExtrinsicsFromMarkers(rig.cameras[c], reference, frames);
      rig.cameras[c].R_CW = pose.R_CW;
      rig.cameras[c].p_CW = pose.p_CW;
      const Eigen::Vector3d after = rig.cameras[c].p_WC();
      std::printf(
          "%s: reprojection RMS %.3f px over %zu matches; centre (%.4f, %.4f, %.4f) m, moved %.1f "
          "mm\n",
          rig.cameras[c].name.c_str(), pose.rms_reprojection_px, pose.correspondences, after.x(),
          after.y(), after.z(), 1e3 * (after - before).norm());
    }
    cameras::SaveCameraRig(m->out, rig);
    std::printf("wrote %s\n", m->out.c_str());
  });
}

void AddReconstruct(CLI::App& cameras) {
  CLI::App* reconstruct = cameras.add_subcommand(
      "reconstruct",
      "Reconstruct labelled 3D markers from calibrated videos and write them as C3D");
  struct Args {
    std::string cameras, config, rigid_bodies, out;
    std::vector<std::string> videos;
    std::size_t first = 0, frames = 0;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  reconstruct->add_option("--cameras", args->cameras, "Camera file")->required();
  reconstruct->add_option("--video", args->videos, "One video per camera, in camera-file order")
      ->required();
  auto* config = reconstruct->add_option("--config", args->config,
                                         "Arm configuration (default marker layout)");
  auto* bodies =
      reconstruct->add_option("--rigid-bodies", args->rigid_bodies,
                              "ccsrm-dataset/1 file whose /mocap/rigid_bodies give the layout");
  config->excludes(bodies);
  reconstruct->add_option("--first", args->first, "First frame")->capture_default_str();
  reconstruct->add_option("--frames", args->frames, "At most this many frames (0 = all)")
      ->capture_default_str();
  reconstruct->add_flag("--quiet", args->quiet, "No progress line");
  reconstruct->add_option("--out", args->out, "Marker file to write (.c3d)")->required();
  reconstruct->callback([args] {
    if (args->config.empty() && args->rigid_bodies.empty()) {
      ThrowInputError("--config", "",
                      "give --config or --rigid-bodies (the marker layout to label)");
    }
    std::string extension = fs::path(args->out).extension().string();
    for (char& ch : extension) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (extension != ".c3d")
      ThrowInputError(args->out, "", "unsupported output format (expected .c3d)");
    std::vector<std::string> inputs = args->videos;
    inputs.push_back(args->cameras);
    inputs.push_back(args->config);
    inputs.push_back(args->rigid_bodies);
    CheckOut(args->out, mocap::C3dFileOutput(), inputs);
    const cameras::CameraRig rig = cameras::LoadCameraRig(args->cameras);
    cameras::ReconstructionOptions options;
    const mocap::MarkerLayout layout =
        LayoutFrom(args->config, args->rigid_bodies, &options.labelling.max_link_spacing_m);
    options.first_frame = args->first;
    options.max_frames = args->frames;
    if (!args->quiet) {
      options.progress = [](std::size_t done, std::size_t total) {
        if (done % 25 == 0 || done == total) {
          std::fprintf(stderr, "\rframe %zu / %zu", done, total);
          if (done == total) std::fprintf(stderr, "\n");
        }
      };
    }
    const cameras::ReconstructionResult result =
        cameras::ReconstructMarkers(rig, args->videos, layout, options);
    mocap::WriteC3d(args->out, result.markers);
    std::printf("%swrote %s (%zu frames, %zu markers)\n", result.quality.BriefReport().c_str(),
                args->out.c_str(), result.markers.frames(), result.markers.markers());
  });
}

}  // namespace

void AddCamerasCommands(CLI::App& root) {
  CLI::App* cameras = root.add_subcommand(
      "cameras", "Camera front end: virtual rig, rendering, calibration, 3D marker reconstruction");
  cameras->require_subcommand(1);
  AddRig(*cameras);
  AddRender(*cameras);
  AddRenderBoard(*cameras);
  AddCalibrate(*cameras);
  AddReconstruct(*cameras);
}

}  // namespace ccsrm::app
