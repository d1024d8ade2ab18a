#pragma once
// Runs as bytes: the requests and results of a SimulationBackend, numbers
// copied as they are, so that they arrive (MPI) or come back (the run
// journal) bit for bit.
#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/simulation_backend.h"

namespace ccsrm::identify::internal {

class Packer {
 public:
  template <typename T>
  void Put(const T& value) {
    Append(&value, sizeof(T));
  }
  void PutString(const std::string& s) {
    Put<std::uint64_t>(s.size());
    Append(s.data(), s.size());
  }
  void PutMatrix(const Eigen::MatrixXd& m) {
    Put<std::int64_t>(m.rows());
    Put<std::int64_t>(m.cols());
    Append(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
  }
  void Append(const void* p, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, p, n);
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  std::vector<char> bytes_;
};

class Unpacker {
 public:
  explicit Unpacker(const std::vector<char>& bytes) : p_(bytes.data()), end_(p_ + bytes.size()) {}
  template <typename T>
  T Get() {
    T value;
    Take(&value, sizeof(T));
    return value;
  }
  std::string GetString() {
    std::string s(Get<std::uint64_t>(), '\0');
    Take(s.data(), s.size());
    return s;
  }
  Eigen::MatrixXd GetMatrix() {
    const auto rows = Get<std::int64_t>();
    const auto cols = Get<std::int64_t>();
    Eigen::MatrixXd m(rows, cols);
    Take(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
    return m;
  }

 private:
  void Take(void* out, std::size_t n) {
    CCSRM_CHECK(static_cast<std::size_t>(end_ - p_) >= n);  // a message of this build
    std::memcpy(out, p_, n);
    p_ += n;
  }
  const char* p_;
  const char* end_;
};

void PutParameters(const sim::ArmParameters& p, Packer* out);
sim::ArmParameters GetParameters(Unpacker* in);
void PutSummary(const sim::SimulationSummary& s, Packer* out);
sim::SimulationSummary GetSummary(Unpacker* in);
// A request without its trajectory flag (runs that keep trajectories are
// neither sent nor recorded), and a result without its trajectory.
void PutRequest(const RunRequest& q, Packer* out);
RunRequest GetRequest(Unpacker* in);
void PutResult(const RunResult& r, Packer* out);
RunResult GetResult(Unpacker* in);

}  // namespace ccsrm::identify::internal
