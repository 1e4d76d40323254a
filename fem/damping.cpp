#include "fem/damping.hpp"

#include <stdexcept>

namespace jointid::fem {

SparseMatrix damping_matrix(const Assembled& s, const Damping& d, const Modes* all_modes) {
  const int n = s.dofs.num_equations();
  switch (d.kind) {
  case Damping::Kind::none:
    return SparseMatrix(n, n);
  case Damping::Kind::rayleigh:
    return d.alpha * s.M + d.beta * s.K;
  case Damping::Kind::modal: {
    if (all_modes == nullptr || all_modes->num_modes() != n)
      throw std::invalid_argument("a modal damping matrix needs all " + std::to_string(n) +
                                  " modes of the model; for large models use Rayleigh damping");
    const Eigen::MatrixXd MPhi = s.M * all_modes->phi;
    Eigen::VectorXd c(n);
    for (int r = 0; r < n; ++r)
      c(r) = 2.0 * d.ratio(all_modes->omega(r)) * all_modes->omega(r);
    const Eigen::MatrixXd C = MPhi * c.asDiagonal() * MPhi.transpose();
    return C.sparseView(1e-14 * C.cwiseAbs().maxCoeff(), 1.0);
  }
  }
  throw std::logic_error("unknown damping kind");
}

} // namespace jointid::fem
