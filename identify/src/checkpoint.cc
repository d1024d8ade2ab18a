#include <cmath>
#include <limits>

#include "ccsrm/common/error.h"
#include "ccsrm/identify/identification.h"

namespace ccsrm::identify {
namespace {

// Row by row; JSON has no NaN, so an unmeasured entry is null.
nlohmann::json MatrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json values = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      values.push_back(std::isfinite(m(r, c)) ? nlohmann::json(m(r, c)) : nlohmann::json());
    }
  }
  return {{"rows", m.rows()}, {"cols", m.cols()}, {"values", values}};
}

Eigen::MatrixXd MatrixFromJson(const nlohmann::json& j) {
  const auto rows = j.at("rows").get<Eigen::Index>();
  const auto cols = j.at("cols").get<Eigen::Index>();
  const nlohmann::json& values = j.at("values");
  if (rows < 0 || cols < 0 || values.size() != static_cast<std::size_t>(rows * cols)) {
    throw std::runtime_error("a matrix's values do not match its rows and cols");
  }
  Eigen::MatrixXd m(rows, cols);
  std::size_t k = 0;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c, ++k) {
      m(r, c) =
          values[k].is_null() ? std::numeric_limits<double>::quiet_NaN() : values[k].get<double>();
    }
  }
  return m;
}

}  // namespace

nlohmann::json ToJson(const FitCheckpoint& c) {
  nlohmann::json start = nlohmann::json::array();
  for (const Eigen::MatrixXd& m : c.start_angles_rad) start.push_back(MatrixJson(m));
  return {{"iterations", c.iterations},
          {"u", c.u},
          {"values", c.values},
          {"trust_region_radius", c.trust_region_radius},
          {"min_lm_diagonal", c.min_lm_diagonal},
          {"jacobi_scaling", c.jacobi_scaling},
          {"simulations", c.simulations},
          {"cost_history", c.cost_history},
          {"start_angles_rad", start}};
}

FitCheckpoint FitCheckpointFromJson(const nlohmann::json& j, const std::string& file) {
  FitCheckpoint c;
  const char* field = "";
  try {
    field = "iterations";
    c.iterations = j.at(field).get<int>();
    field = "u";
    c.u = j.at(field).get<std::vector<double>>();
    field = "values";
    c.values = j.at(field).get<std::vector<double>>();
    field = "trust_region_radius";
    c.trust_region_radius = j.at(field).get<double>();
    field = "min_lm_diagonal";
    c.min_lm_diagonal = j.at(field).get<double>();
    field = "jacobi_scaling";
    c.jacobi_scaling = j.at(field).get<bool>();
    field = "simulations";
    c.simulations = j.at(field).get<std::int64_t>();
    field = "cost_history";
    c.cost_history = j.at(field).get<std::vector<double>>();
    field = "start_angles_rad";
    for (const nlohmann::json& m : j.at(field)) c.start_angles_rad.push_back(MatrixFromJson(m));
  } catch (const std::exception& e) {
    ThrowInputError(file, field, std::string("cannot be read: ") + e.what());
  }
  if (!(c.trust_region_radius > 0.0) || c.iterations < 0) {
    ThrowInputError(file, "trust_region_radius", "not a state a fit stops in");
  }
  return c;
}

}  // namespace ccsrm::identify
