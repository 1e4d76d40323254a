#include "frf/modal_model.hpp"

#include "fem/text.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jointid::frf {

namespace {

std::string size_text(Eigen::Index rows, Eigen::Index cols) {
  return std::to_string(rows) + " × " + std::to_string(cols);
}

// The shortest text that reads back as `value` (1e-07, 80.3).
// Mode r, 1-based in messages as in tables of modes.
std::string mode(Eigen::Index r) {
  return "mode " + std::to_string(r + 1);
}

} // namespace

void ModalModel::validate() const {
  const Eigen::Index n = num_dofs(), m = num_modes();
  auto fail = [](const std::string& what) { throw std::invalid_argument("modal model: " + what); };
  if (n == 0) fail("no DOFs");
  if (m == 0) fail("no modes (frequencies_hz is empty)");
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    if (dofs[i].node <= 0)
      fail("DOF " + fem::to_string(dofs[i]) + ": node ids must be > 0 (0 means ground)");
    for (std::size_t k = 0; k < i; ++k)
      if (dofs[k] == dofs[i])
        fail("DOF " + fem::to_string(dofs[i]) + " is listed twice (entries " +
             std::to_string(k + 1) + " and " + std::to_string(i + 1) + ")");
  }
  if (damping.size() != m)
    fail(std::to_string(damping.size()) + " damping ratios for " + std::to_string(m) +
         " frequencies (expected one per mode)");
  if (shapes.rows() != m || shapes.cols() != n)
    fail("shapes are " + size_text(shapes.rows(), shapes.cols()) + ", expected " + size_text(m, n) +
         " (one row per mode, one column per DOF)");
  for (Eigen::Index r = 0; r < m; ++r) {
    if (!std::isfinite(frequencies_hz(r)) || frequencies_hz(r) < 0.0)
      fail(mode(r) + ": expected a frequency >= 0 Hz, got " + shortest(frequencies_hz(r)));
    if (!std::isfinite(damping(r)) || damping(r) < 0.0)
      fail(mode(r) + ": expected a damping ratio >= 0, got " + shortest(damping(r)));
    for (Eigen::Index i = 0; i < n; ++i)
      if (!std::isfinite(shapes(r, i)))
        fail(mode(r) + ": the shape at " + fem::to_string(dofs[i]) + " is not finite");
  }
  const Eigen::MatrixXd& R = residual_flexibility;
  if (R.size() == 0) return;
  if (R.rows() != n || R.cols() != n)
    fail("the residual flexibility is " + size_text(R.rows(), R.cols()) + ", expected " +
         size_text(n, n) + " (one row and column per DOF)");
  if (!R.allFinite()) fail("the residual flexibility has a non-finite entry");
  const double tolerance = 1e-9 * R.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j)
      if (std::abs(R(i, j) - R(j, i)) > tolerance)
        fail("the residual flexibility is not symmetric: (" + fem::to_string(dofs[i]) + ", " +
             fem::to_string(dofs[j]) + ") = " + shortest(R(i, j)) + " but (" +
             fem::to_string(dofs[j]) + ", " + fem::to_string(dofs[i]) + ") = " + shortest(R(j, i)) +
             " m/N");
}

} // namespace jointid::frf
