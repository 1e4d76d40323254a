#include "fem/elements.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

namespace jointid::fem {

Matrix4 beam_stiffness(double EI, double L) {
  Matrix4 k;
  k << 12, 6 * L, -12, 6 * L,              //
      6 * L, 4 * L * L, -6 * L, 2 * L * L, //
      -12, -6 * L, 12, -6 * L,             //
      6 * L, 2 * L * L, -6 * L, 4 * L * L;
  return k * (EI / (L * L * L));
}

Matrix4 beam_consistent_mass(double rho_A, double L) {
  Matrix4 m;
  m << 156, 22 * L, 54, -13 * L,             //
      22 * L, 4 * L * L, 13 * L, -3 * L * L, //
      54, 13 * L, 156, -22 * L,              //
      -13 * L, -3 * L * L, -22 * L, 4 * L * L;
  return m * (rho_A * L / 420.0);
}

Matrix4 beam_lumped_mass(double rho_A, double L) {
  const double m = rho_A * L;
  return Eigen::Vector4d(m / 2, m * L * L / 78.0, m / 2, m * L * L / 78.0).asDiagonal();
}

namespace {

// Local planar frame matrices, DOFs [u_a, v_a, θ_a, u_b, v_b, θ_b].
Matrix6 frame2d_local_stiffness(double EA, double EI, double L) {
  Matrix6 k = Matrix6::Zero();
  k(0, 0) = k(3, 3) = EA / L;
  k(0, 3) = k(3, 0) = -EA / L;
  const Matrix4 kb = beam_stiffness(EI, L);
  const int map[4] = {1, 2, 4, 5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      k(map[i], map[j]) = kb(i, j);
  return k;
}

Matrix6 frame2d_local_mass(double rho_A, double L, bool lumped) {
  Matrix6 m = Matrix6::Zero();
  const double total = rho_A * L;
  if (lumped) {
    m(0, 0) = m(3, 3) = total / 2;
  } else {
    m(0, 0) = m(3, 3) = total / 3;
    m(0, 3) = m(3, 0) = total / 6;
  }
  const Matrix4 mb = lumped ? beam_lumped_mass(rho_A, L) : beam_consistent_mass(rho_A, L);
  const int map[4] = {1, 2, 4, 5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      m(map[i], map[j]) = mb(i, j);
  return m;
}

Matrix6 frame2d_rotation(const Eigen::Vector2d& xa, const Eigen::Vector2d& xb) {
  const Eigen::Vector2d d = xb - xa;
  const double L = d.norm();
  const double c = d.x() / L, s = d.y() / L;
  Eigen::Matrix3d r;
  r << c, s, 0, -s, c, 0, 0, 0, 1; // local = r * global
  Matrix6 T = Matrix6::Zero();
  T.block<3, 3>(0, 0) = r;
  T.block<3, 3>(3, 3) = r;
  return T;
}

} // namespace

Matrix6 frame2d_stiffness(double EA, double EI, const Eigen::Vector2d& xa,
                          const Eigen::Vector2d& xb) {
  const Matrix6 T = frame2d_rotation(xa, xb);
  return T.transpose() * frame2d_local_stiffness(EA, EI, (xb - xa).norm()) * T;
}

Matrix6 frame2d_mass(double rho_A, const Eigen::Vector2d& xa, const Eigen::Vector2d& xb,
                     bool lumped) {
  const Matrix6 T = frame2d_rotation(xa, xb);
  return T.transpose() * frame2d_local_mass(rho_A, (xb - xa).norm(), lumped) * T;
}

Eigen::Vector3d frame3d_default_up(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb) {
  const Eigen::Vector3d ex = (xb - xa).normalized();
  return ex.cross(Eigen::Vector3d::UnitZ()).norm() < 1e-6 ? Eigen::Vector3d::UnitX()
                                                          : Eigen::Vector3d::UnitZ();
}

namespace {

// Rows of the 3x3 direction-cosine matrix: local x, y, z expressed in global axes.
Eigen::Matrix3d frame3d_axes(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb,
                             const Eigen::Vector3d& up) {
  const Eigen::Vector3d ex = (xb - xa).normalized();
  Eigen::Vector3d ez = ex.cross(up);
  if (ez.norm() < 1e-9 * up.norm())
    throw std::invalid_argument("frame3d element: the 'up' vector is parallel to the element axis");
  ez.normalize();
  const Eigen::Vector3d ey = ez.cross(ex);
  Eigen::Matrix3d r;
  r.row(0) = ex;
  r.row(1) = ey;
  r.row(2) = ez;
  return r;
}

Matrix12 frame3d_transform(const Eigen::Matrix3d& r) {
  Matrix12 T = Matrix12::Zero();
  for (int b = 0; b < 4; ++b)
    T.block<3, 3>(3 * b, 3 * b) = r;
  return T;
}

// Local DOF order [u v w θx θy θz] at a, then at b.
Matrix12 frame3d_local_stiffness(const Material& mat, const Section& sec, double L) {
  Matrix12 k = Matrix12::Zero();
  const double EA = mat.E * sec.A, G = mat.E / (2.0 * (1.0 + mat.nu)), GJ = G * sec.J;
  auto put_pair = [&](int i, int j, double v) {
    k(i, i) += v, k(j, j) += v, k(i, j) -= v, k(j, i) -= v;
  };
  put_pair(0, 6, EA / L);
  put_pair(3, 9, GJ / L);
  // Bending in the local x–y plane: [v_a, θz_a, v_b, θz_b] with EIz.
  const Matrix4 kz = beam_stiffness(mat.E * sec.Iz, L);
  const int mz[4] = {1, 5, 7, 11};
  // Bending in the local x–z plane: [w_a, -θy_a, w_b, -θy_b] with EIy (θy = -dw/dx).
  const Matrix4 ky = beam_stiffness(mat.E * sec.Iy, L);
  const int my[4] = {2, 4, 8, 10};
  const double sy[4] = {1, -1, 1, -1};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      k(mz[i], mz[j]) += kz(i, j);
      k(my[i], my[j]) += sy[i] * sy[j] * ky(i, j);
    }
  return k;
}

Matrix12 frame3d_local_mass(const Material& mat, const Section& sec, double L, bool lumped) {
  Matrix12 m = Matrix12::Zero();
  const double rho_A = mat.rho * sec.A, total = rho_A * L;
  const double polar = mat.rho * (sec.Iy + sec.Iz) * L; // torsional inertia of the element
  if (lumped) {
    for (int i : {0, 1, 2, 6, 7, 8})
      m(i, i) = total / 2;
    m(3, 3) = m(9, 9) = polar / 2;
    for (int i : {4, 5, 10, 11})
      m(i, i) = total * L * L / 78.0;
    return m;
  }
  m(0, 0) = m(6, 6) = total / 3;
  m(0, 6) = m(6, 0) = total / 6;
  m(3, 3) = m(9, 9) = polar / 3;
  m(3, 9) = m(9, 3) = polar / 6;
  const Matrix4 mb = beam_consistent_mass(rho_A, L);
  const int mz[4] = {1, 5, 7, 11};
  const int my[4] = {2, 4, 8, 10};
  const double sy[4] = {1, -1, 1, -1};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      m(mz[i], mz[j]) += mb(i, j);
      m(my[i], my[j]) += sy[i] * sy[j] * mb(i, j);
    }
  return m;
}

} // namespace

Matrix12 frame3d_stiffness(const Material& material, const Section& section,
                           const Eigen::Vector3d& xa, const Eigen::Vector3d& xb,
                           const Eigen::Vector3d& up) {
  const Matrix12 T = frame3d_transform(frame3d_axes(xa, xb, up));
  return T.transpose() * frame3d_local_stiffness(material, section, (xb - xa).norm()) * T;
}

Matrix12 frame3d_mass(const Material& material, const Section& section, const Eigen::Vector3d& xa,
                      const Eigen::Vector3d& xb, const Eigen::Vector3d& up, bool lumped) {
  const Matrix12 T = frame3d_transform(frame3d_axes(xa, xb, up));
  return T.transpose() * frame3d_local_mass(material, section, (xb - xa).norm(), lumped) * T;
}

std::span<const Dof> element_dofs(ElementType type) {
  static constexpr Dof beam[] = {Dof::uy, Dof::rz};
  static constexpr Dof frame2d[] = {Dof::ux, Dof::uy, Dof::rz};
  switch (type) {
  case ElementType::beam:
    return beam;
  case ElementType::frame2d:
    return frame2d;
  case ElementType::frame3d:
    return all_dofs;
  }
  return {};
}

ElementMatrices element_matrices(const Model& model, const Element& e) {
  return element_matrices(model, e, model.nodes[model.node_index(e.node_a)].x,
                          model.nodes[model.node_index(e.node_b)].x);
}

ElementMatrices element_matrices(const Model& model, const Element& e, const Eigen::Vector3d& xa,
                                 const Eigen::Vector3d& xb) {
  const Material& mat = model.materials.at(e.material);
  const Section& sec = model.sections.at(e.section);
  const bool lumped = model.mass_options.lumped;
  const double rho_A = mat.rho * sec.A;
  switch (e.type) {
  case ElementType::beam: {
    const Eigen::Vector3d d = xb - xa;
    if (std::abs(d.y()) > 1e-9 * d.norm() || std::abs(d.z()) > 1e-9 * d.norm() || d.x() <= 0.0)
      throw std::invalid_argument("element " + std::to_string(e.id) +
                                  ": a 'beam' element must run along +x from node a to node b "
                                  "(use type 'frame2d' for inclined members)");
    const double L = d.x();
    return {beam_stiffness(mat.E * sec.Iz, L),
            lumped ? beam_lumped_mass(rho_A, L) : beam_consistent_mass(rho_A, L)};
  }
  case ElementType::frame2d: {
    if (std::abs(xa.z()) > 0.0 || std::abs(xb.z()) > 0.0)
      throw std::invalid_argument("element " + std::to_string(e.id) +
                                  ": a 'frame2d' element must lie in the x–y plane (z = 0)");
    const Eigen::Vector2d a = xa.head<2>(), b = xb.head<2>();
    return {frame2d_stiffness(mat.E * sec.A, mat.E * sec.Iz, a, b),
            frame2d_mass(rho_A, a, b, lumped)};
  }
  case ElementType::frame3d: {
    const Eigen::Vector3d up = e.up.value_or(frame3d_default_up(xa, xb));
    return {frame3d_stiffness(mat, sec, xa, xb, up), frame3d_mass(mat, sec, xa, xb, up, lumped)};
  }
  }
  throw std::logic_error("unknown element type");
}

} // namespace jointid::fem
