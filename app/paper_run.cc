#include "paper_run.h"

#include "ccsrm/common/error.h"
#include "ccsrm/sim/config.h"

namespace ccsrm::app {

PaperRun PreparePaperRun(const PaperRunArgs& a) {
  sim::Config config = sim::LoadConfig(a.config_path);
  if (a.case_number != 0) sim::ApplyPaperCase(a.case_number, &config);
  if (!std::isnan(a.amplitude_deg)) config.protocol.amplitude_rad = a.amplitude_deg * M_PI / 180.0;
  if (!std::isnan(a.output_rate_hz)) config.solver.output_rate_hz = a.output_rate_hz;
  sim::Validate(config);
  const double duration = std::isnan(a.duration_s) ? config.protocol.duration_s() : a.duration_s;
  if (!(duration > 0.0)) ThrowInputError("--duration", "", "must be > 0 s");
  sim::ArmModel model(config);
  sim::CableInputs inputs =
      sim::PlanCableInputs(model, sim::PaperTrajectory(model, config.protocol), duration);
  return PaperRun{std::move(model), std::move(inputs), duration};
}

}  // namespace ccsrm::app
