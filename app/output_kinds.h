#pragma once
// The kinds of output only the ccsrm commands write (the jobs' folders are
// identify/job.h's, the data files datasets/output_kinds.h's, C3D mocap/c3d.h's), for the one
// output policy (common/output_policy.h, docs/conventions.md "Outputs"): each says how an earlier
// output of its kind is recognised, so that a command replaces its own outputs and refuses to
// replace anything else.
#include <string>
#include <vector>

#include "ccsrm/common/output_policy.h"
#include "ccsrm/datasets/output_kinds.h"  // the data files
#include "ccsrm/mocap/c3d.h"              // C3dFileOutput

namespace ccsrm::app {

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
