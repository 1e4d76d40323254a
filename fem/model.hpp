#pragma once
/// The linear substructure: nodes, elements, materials, sections, supports, point masses,
/// grounded springs and the substructure's own damping. SI units (m, kg, N, Pa, s).
#include "fem/dof.hpp"

#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace jointid::fem {

struct Node {
  int id = 0;
  Eigen::Vector3d x = Eigen::Vector3d::Zero(); ///< position, m
};

struct Material {
  std::string name;
  double E = 0.0;   ///< Young's modulus, Pa
  double rho = 0.0; ///< density, kg/m^3
  double nu = 0.3;  ///< Poisson's ratio (shear modulus G = E / (2 (1 + nu)))
};

struct Section {
  std::string name;
  double A = 0.0;  ///< area, m^2
  double Iz = 0.0; ///< second moment of area for bending in the x–y plane, m^4
  double Iy = 0.0; ///< second moment for bending out of plane (3D frames), m^4
  double J = 0.0;  ///< torsion constant (3D frames), m^4
};

/// beam: planar Euler–Bernoulli (uy, rz per node); frame2d: planar frame (ux, uy, rz);
/// frame3d: spatial frame (all six).
enum class ElementType { beam, frame2d, frame3d };

struct Element {
  int id = 0;
  int node_a = 0;
  int node_b = 0;
  ElementType type = ElementType::beam;
  int material = 0; ///< index into Model::materials
  int section = 0;  ///< index into Model::sections
  /// 3D frames: a vector in the element's local x–y plane (fixes the section axes). Not given:
  /// fem::frame3d_default_up — global +z, or +x for a member parallel to z.
  std::optional<Eigen::Vector3d> up = std::nullopt;
};

struct Support {
  int node = 0;
  std::vector<Dof> fixed; ///< DOFs held at zero (a DOF the node does not have is ignored)
};

/// A lumped mass at a node: m on the translations, inertia on the rotations.
struct PointMass {
  int node = 0;
  double mass = 0.0;                                 ///< kg
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero(); ///< kg·m^2 about x, y, z
};

/// A linear spring from one node DOF to ground (node_b == 0) or to another node's same DOF.
struct Spring {
  int node = 0;
  int node_b = 0; ///< 0: to ground
  Dof dof = Dof::uy;
  double stiffness = 0.0; ///< N/m or N·m/rad
};

/// Damping of the linear substructure. Modal: the same ratio for every mode (the modal
/// synthesis uses it directly; the time integrator uses C = M Φ diag(2 ζ_r ω_r) Φᵀ M over all
/// modes). Rayleigh: C = alpha M + beta K, i.e. ζ_r = alpha / (2 ω_r) + beta ω_r / 2.
struct Damping {
  enum class Kind { none, modal, rayleigh };
  Kind kind = Kind::none;
  double modal_ratio = 0.0;
  double alpha = 0.0; ///< 1/s
  double beta = 0.0;  ///< s
  /// ζ of a mode with circular frequency omega (rad/s).
  double ratio(double omega) const;
};

struct MassOptions {
  bool lumped = false; ///< lumped (diagonal, HRZ) instead of consistent element mass
};

struct Model {
  int dimension = 2; ///< 2: planar (ux uy rz), 3: spatial
  std::vector<Node> nodes;
  std::vector<Material> materials;
  std::vector<Section> sections;
  std::vector<Element> elements;
  std::vector<Support> supports;
  std::vector<PointMass> masses;
  std::vector<Spring> springs;
  Damping damping;
  MassOptions mass_options;

  /// Index of the node with this id in `nodes` (a linear search: for one-off look-ups; use
  /// node_positions() in loops); throws std::out_of_range naming the id.
  int node_index(int id) const;
  /// Node id → index in `nodes`, built once (O(n)); throws std::invalid_argument on a
  /// duplicate id.
  std::unordered_map<int, int> node_positions() const;
  bool has_node(int id) const;
  /// Checks ids, references and physical values; throws std::invalid_argument on the first
  /// problem, naming the item.
  void validate() const;
};

} // namespace jointid::fem
