#include "run_codec.h"

#include "ccsrm/sim/parameters.h"

namespace ccsrm::identify::internal {

void PutParameters(const sim::ArmParameters& p, Packer* out) {
  for (const sim::ParameterInfo& info : sim::Parameters()) out->Put<double>(p.*(info.field));
  out->Put<std::int32_t>(p.arm.joints);
  out->Put<std::int32_t>(p.arm.cables);
  out->Put<std::uint64_t>(p.effects_on.size());
  for (const std::string& e : p.effects_on) out->PutString(e);
  out->Put<std::uint64_t>(p.effect_values.size());
  for (const auto& [name, value] : p.effect_values) {
    out->PutString(name);
    out->Put<double>(value);
  }
  // Declared-value corrections (the loop's declared candidates): a rank or
  // a journal without them would run the arm as declared.
  out->Put<std::uint64_t>(p.declared_deltas.size());
  for (const auto& [name, value] : p.declared_deltas) {
    out->PutString(name);
    out->Put<double>(value);
  }
}

sim::ArmParameters GetParameters(Unpacker* in) {
  sim::ArmParameters p;
  for (const sim::ParameterInfo& info : sim::Parameters()) p.*(info.field) = in->Get<double>();
  p.arm.joints = in->Get<std::int32_t>();
  p.arm.cables = in->Get<std::int32_t>();
  for (auto n = in->Get<std::uint64_t>(); n > 0; --n) p.effects_on.insert(in->GetString());
  for (auto n = in->Get<std::uint64_t>(); n > 0; --n) {
    std::string name = in->GetString();
    p.effect_values[name] = in->Get<double>();
  }
  for (auto n = in->Get<std::uint64_t>(); n > 0; --n) {
    std::string name = in->GetString();
    p.declared_deltas[name] = in->Get<double>();
  }
  return p;
}

void PutSummary(const sim::SimulationSummary& s, Packer* out) {
  out->Put<std::int32_t>(static_cast<std::int32_t>(s.status));
  out->PutString(s.message);
  out->Put(s.simulated_s);
  out->Put(s.wall_time_s);
  out->Put(s.real_time_factor);
  out->Put(s.steps);
  out->Put(s.rejected_steps);
  out->Put(s.rhs_evaluations);
  out->Put(s.stick_slip_switches);
  out->Put(s.failed_releases);
  out->Put(s.largest_threshold_raise_n);
  out->Put(s.max_constraint_violation);
  out->Put<std::uint64_t>(s.slack.size());
  for (const sim::SlackInterval& i : s.slack) out->Put(i);
}

sim::SimulationSummary GetSummary(Unpacker* in) {
  sim::SimulationSummary s;
  s.status = static_cast<sim::SimulationStatus>(in->Get<std::int32_t>());
  s.message = in->GetString();
  s.simulated_s = in->Get<double>();
  s.wall_time_s = in->Get<double>();
  s.real_time_factor = in->Get<double>();
  s.steps = in->Get<std::int64_t>();
  s.rejected_steps = in->Get<std::int64_t>();
  s.rhs_evaluations = in->Get<std::int64_t>();
  s.stick_slip_switches = in->Get<std::int64_t>();
  s.failed_releases = in->Get<std::int64_t>();
  s.largest_threshold_raise_n = in->Get<double>();
  s.max_constraint_violation = in->Get<double>();
  s.slack.resize(in->Get<std::uint64_t>());
  for (sim::SlackInterval& i : s.slack) i = in->Get<sim::SlackInterval>();
  return s;
}

void PutRequest(const RunRequest& q, Packer* out) {
  out->Put<std::uint64_t>(q.experiment);
  PutParameters(q.parameters, out);
  out->Put<std::uint64_t>(q.measurement_variants.size());
  for (const sim::ArmParameters& v : q.measurement_variants) PutParameters(v, out);
  out->Put<std::uint8_t>(q.every_frame ? 1 : 0);
}

RunRequest GetRequest(Unpacker* in) {
  RunRequest q;
  q.experiment = in->Get<std::uint64_t>();
  q.parameters = GetParameters(in);
  q.measurement_variants.resize(in->Get<std::uint64_t>());
  for (sim::ArmParameters& v : q.measurement_variants) v = GetParameters(in);
  q.every_frame = in->Get<std::uint8_t>() != 0;
  return q;
}

void PutResult(const RunResult& r, Packer* out) {
  PutSummary(r.summary, out);
  out->PutMatrix(r.simulated);
  out->Put<std::uint64_t>(r.variant_simulated.size());
  for (const Eigen::MatrixXd& v : r.variant_simulated) out->PutMatrix(v);
}

RunResult GetResult(Unpacker* in) {
  RunResult r;
  r.summary = GetSummary(in);
  r.simulated = in->GetMatrix();
  r.variant_simulated.resize(in->Get<std::uint64_t>());
  for (Eigen::MatrixXd& v : r.variant_simulated) v = in->GetMatrix();
  return r;
}

}  // namespace ccsrm::identify::internal
