// Recording edges are not physics (issue 44). The residual of the right
// model is the measurement's noise alone. The zero-lag low-pass leaves more
// of it at a recording's ends, where it sits on a pivot fitted to half a
// cutoff period, so the raw residual rises there; weighed by the noise the
// filter leaves at each frame (Experiment::NoiseDeg), as fits, the verdict
// and the loop weigh it, it is as large in the first and last second as in
// the middle. Recordings: the bundled loop sample (its truth, backlash
// included) and three generated ones of the paper's case 2.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "ccsrm/identify/experiment.h"
#include "ccsrm/identify/prediction.h"
#include "ccsrm/mocap/generate.h"

namespace ccsrm::identify {
namespace {

namespace fs = std::filesystem;

const std::string kSample = std::string(CCSRM_SOURCE_DIR) + "/datasets/samples/loop/";

// RMS of the residual (predicted - measured) pooled over every recording,
// joint and axis, in the first second, the last second, the last 0.1 s and
// the middle (the rest); `weighed`: each frame over its relative noise.
struct EdgeRms {
  double first = 0.0, middle = 0.0, last = 0.0, last_tenth = 0.0;
};

EdgeRms Edges(const std::vector<Experiment>& recordings, const PredictionSummary& prediction,
              bool weighed) {
  double sq[4] = {0, 0, 0, 0}, n[4] = {0, 0, 0, 0};
  for (std::size_t e = 0; e < recordings.size(); ++e) {
    const Experiment& x = recordings[e];
    const Eigen::MatrixXd& predicted = prediction.recordings[e].predicted_rad;
    const double start = x.sample_time_s.front(), end = x.sample_time_s.back();
    for (Eigen::Index f = 0; f < x.measured.rows(); ++f) {
      const double t = x.sample_time_s[static_cast<std::size_t>(f)];
      const int zone = t - start < 1.0 ? 0 : end - t < 1.0 ? 2 : 1;
      for (Eigen::Index c = 0; c < x.measured.cols(); ++c) {
        double r = (predicted(f, c) - x.measured(f, c)) * 180.0 / M_PI;
        if (!std::isfinite(r)) continue;
        if (weighed) r *= x.noise_deg[static_cast<std::size_t>(c / 2)] / x.NoiseDeg(f, c);
        sq[zone] += r * r;
        n[zone] += 1.0;
        if (end - t < 0.1) sq[3] += r * r, n[3] += 1.0;
      }
    }
  }
  return {std::sqrt(sq[0] / n[0]), std::sqrt(sq[1] / n[1]), std::sqrt(sq[2] / n[2]),
          std::sqrt(sq[3] / n[3])};
}

void ExpectEdgesLikeTheMiddle(const std::vector<Experiment>& recordings,
                              const PredictionSummary& prediction) {
  ASSERT_TRUE(prediction.completed) << prediction.message;
  const EdgeRms raw = Edges(recordings, prediction, false);
  const EdgeRms weighed = Edges(recordings, prediction, true);
  std::printf("raw: first %.3f last %.3f last 0.1 s %.3f of the middle (%.4f deg)\n",
              raw.first / raw.middle, raw.last / raw.middle, raw.last_tenth / raw.middle,
              raw.middle);
  std::printf("weighed: first %.3f last %.3f last 0.1 s %.3f of the middle (%.4f deg)\n",
              weighed.first / weighed.middle, weighed.last / weighed.middle,
              weighed.last_tenth / weighed.middle, weighed.middle);
  // The bound: the first and last second within 1.2x the middle.
  // Pooled over the recordings' channels, each second holds some hundred
  // independent samples at a 1 Hz low-pass, an RMS known to about 7 %: 1.2
  // is three sigma from equal.
  EXPECT_LT(weighed.first / weighed.middle, 1.2);
  EXPECT_LT(weighed.last / weighed.middle, 1.2);
  EXPECT_GT(weighed.first / weighed.middle, 1.0 / 1.2);
  EXPECT_GT(weighed.last / weighed.middle, 1.0 / 1.2);
  // What the weighing answers is there: the last 0.1 s, on the pivot, far
  // noisier than the middle unweighed (a line's end over 50 frames, 2/sqrt(50)
  // of the raw noise, against the interior's filtered noise).
  EXPECT_GT(raw.last_tenth / raw.middle, 1.4);
}

TEST(RecordingEdges, TheLoopSamplesEndsAreAsNoisyAsItsMiddleOnceWeighed) {
  std::vector<Experiment> recordings;
  for (const char* name : {"train1", "train2", "holdout"}) {
    recordings.push_back(LoadExperiment(kSample + name + ".h5", {}));
  }
  // Every recording shares the truth's parameters and effects.
  const PredictionModel truth = LoadPredictionModel(kSample + "truth/train1.truth.yaml");
  PredictionOptions options;
  options.threads = 2;
  ExpectEdgesLikeTheMiddle(recordings, Predict(recordings, truth, options));
}

TEST(RecordingEdges, GeneratedRecordingsEndsAreAsNoisyAsTheirMiddleOnceWeighed) {
  const fs::path dir = fs::temp_directory_path() / "ccsrm_recording_edges_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<Experiment> recordings;
  std::string truth_file;
  for (unsigned seed : {1u, 2u, 3u}) {
    mocap::GenerateOptions g;
    g.run.config_path = std::string(CCSRM_SOURCE_DIR) + "/configs/paper.yaml";
    g.run.case_number = 2;
    g.run.duration_s = 10.0;
    g.recording.seed = seed;
    g.out = (dir / ("seed" + std::to_string(seed) + ".h5")).string();
    const mocap::GeneratedExperiment generated = mocap::GenerateExperiment(g);
    ASSERT_TRUE(generated.simulation.completed()) << generated.simulation.message;
    recordings.push_back(LoadExperiment(generated.experiment_path, {}));
    truth_file = generated.truth_yaml_path;
  }
  PredictionOptions options;
  options.threads = 2;
  ExpectEdgesLikeTheMiddle(recordings,
                           Predict(recordings, LoadPredictionModel(truth_file), options));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ccsrm::identify
