#pragma once
// Small models built in code for the fem/, joints/ and frf/ tests: uniform beams along x and a
// single-DOF spring–mass oscillator. Analytic references for these live in the tests.
#include "fem/assembly.hpp"
#include "fem/modal.hpp"
#include "fem/model.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <vector>

namespace jointid::test {

// Every mode of an assembled system (the dense engine): the modal references of the tests.
inline fem::Modes all_modes(const fem::Assembled& s) {
  fem::ModalOptions o;
  o.num_modes = 0;
  o.engine = fem::ModalEngine::dense;
  return fem::modal_analysis(s, o);
}

/// Uniform beam properties (SI).
struct BeamProperties {
  double E = 210e9;             ///< Pa
  double rho = 7850.0;          ///< kg/m^3
  double length = 2.0;          ///< m
  double width = 0.25;          ///< m
  double thickness = 0.0143623; ///< m (paper cantilever: first mode 3.0 Hz)
  double A() const { return width * thickness; }
  double I() const { return width * thickness * thickness * thickness / 12.0; }
  /// sqrt(EI / (ρ A L⁴)): ω = (βL)² times this for a uniform Euler–Bernoulli beam.
  double omega_scale() const { return std::sqrt(E * I() / (rho * A() * std::pow(length, 4))); }
};

/// `elements` equal elements of `type` along +x, nodes 1 … elements+1, no supports, no damping.
inline fem::Model uniform_beam(int elements, const BeamProperties& p = {},
                               fem::ElementType type = fem::ElementType::beam) {
  fem::Model m;
  m.dimension = 2;
  m.materials.push_back({"steel", p.E, p.rho, 0.3});
  m.sections.push_back({"strip", p.A(), p.I(), 0.0, 0.0});
  for (int i = 0; i <= elements; ++i)
    m.nodes.push_back({i + 1, Eigen::Vector3d(p.length * i / elements, 0.0, 0.0)});
  for (int i = 0; i < elements; ++i)
    m.elements.push_back({i + 1, i + 1, i + 2, type, 0, 0});
  return m;
}

/// Cantilever clamped at node 1 (beam elements), free end at node elements+1.
inline fem::Model cantilever(int elements, const BeamProperties& p = {}) {
  fem::Model m = uniform_beam(elements, p);
  m.supports.push_back({1, {fem::Dof::ux, fem::Dof::uy, fem::Dof::rz}});
  return m;
}

/// One node with a grounded spring k on ux and a point mass m: a single-DOF oscillator in a
/// 2D model without elements.
inline fem::Model oscillator(double mass, double stiffness) {
  fem::Model m;
  m.dimension = 2;
  m.nodes.push_back({1, Eigen::Vector3d::Zero()});
  m.masses.push_back({1, mass, Eigen::Vector3d::Zero()});
  m.springs.push_back({1, 0, fem::Dof::ux, stiffness});
  return m;
}

inline std::vector<int> all_equations(const fem::Assembled& s) {
  std::vector<int> out(s.dofs.num_equations());
  for (int i = 0; i < s.dofs.num_equations(); ++i)
    out[i] = i;
  return out;
}

/// Dense K⁻¹ by an LU of the dense matrix, independent of the library's sparse solvers.
inline Eigen::MatrixXd dense_flexibility(const fem::Assembled& s) {
  return Eigen::MatrixXd(s.K).fullPivLu().inverse();
}

} // namespace jointid::test
