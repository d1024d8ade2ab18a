#pragma once
// The kinds of output the ccsrm commands write (the jobs' folders are
// identify/job.h's), for the one output policy
// (common/output_policy.h, docs/conventions.md "Outputs"): each says how an
// earlier output of its kind is recognised, so that a command replaces its
// own outputs and refuses to replace anything else.
#include <string>
#include <vector>

#include "ccsrm/common/output_policy.h"

namespace ccsrm::app {

OutputKind RunFileOutput();         // simulate: HDF5, schema ccsrm-run/1
OutputKind ExperimentFileOutput();  // generate, mocap process: ccsrm-dataset/1
OutputKind C3dFileOutput();         // mocap export, cameras reconstruct
// A YAML file whose top level has `schema: <schema>` (rigid bodies, camera
// files, the truth of generate).
OutputKind YamlFileOutput(const std::string& schema, const std::string& description);
OutputKind CameraFileOutput();       // cameras rig, calibrate: ccsrm-cameras/1
OutputKind DerivativesJsonOutput();  // derivatives --json
// cameras render: cameras.yaml (ccsrm-cameras/1) with its videos.
OutputKind RenderFolderOutput();
// cameras render-board: the checkerboard images (PNG files only).
OutputKind BoardImagesFolderOutput();

// CheckOutputPath with option "--out".
void CheckOut(const std::string& path, const OutputKind& kind,
              const std::vector<std::string>& inputs);

}  // namespace ccsrm::app
