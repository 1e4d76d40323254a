#pragma once
/// Joints: a non-linear connection between one DOF and ground, or between the same DOF of two
/// nodes (translational or rotational). Its deformation is y = u(node) − u(node_b) (or u(node)
/// to ground), and its force g(y, ẏ) = Σ b_j g_j acts as −g on `node` and +g on `node_b`.
#include "fem/assembly.hpp"
#include "fem/time_integration.hpp"
#include "joints/basis.hpp"
#include "joints/hysteresis.hpp"

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace jointid::joints {

/// A named parameter of a parametric term (jenkins, iwan, gap): "<term>.<name>" in values.
struct Parameter {
  double value = 0.0;
  bool fixed = false; ///< known and held, not identified
  bool given = false; ///< given in the model file (else unknown)
};

struct Joint {
  std::string name;
  int node = 0;
  int node_b = 0; ///< 0: the joint goes to ground
  fem::Dof dof = fem::Dof::uy;
  std::vector<Term> terms;
  std::vector<double> values; ///< b_j, same order as terms (known or starting values)
  std::vector<bool> fixed;    ///< true: b_j is known and held, not identified
  /// true where `values` holds a value given in the model file; false: unknown (starts at 0).
  /// Empty: every value is given.
  std::vector<bool> given;
  /// Per term, the named parameters of a parametric term in the order of
  /// term_info(term).parameters (empty for a coefficient term); empty: no parametric term. For a
  /// parametric term t, values[t] is 1 (its force is taken whole), fixed[t] is true when all its
  /// parameters are fixed and given[t] when all are given (set_parameters() keeps them so).
  std::vector<std::vector<Parameter>> parameters{};
  /// Elements of an iwan term's quadrature (joints/hysteresis.hpp).
  int iwan_sliders = default_iwan_sliders;

  bool to_ground() const { return node_b == 0; }
  /// g(y, ẏ) with the joint's values; a hysteretic term is refused (it needs a history:
  /// JointLaw), a gap evaluated.
  double force(double y, double ydot) const;
  /// Index of a term in `terms`, or -1.
  int term_index(Term t) const;
  bool has_value(std::size_t term) const { return given.empty() || given[term]; }
  /// The named parameters of term t (empty for a coefficient term).
  std::span<const Parameter> parameters_of(std::size_t term) const;
  /// The value of parameter `name` of term t; throws std::invalid_argument if it has none.
  double parameter(std::size_t term, std::string_view name) const;
  /// Sets the named parameters of the parametric term t (in the table's order), given, and
  /// fixed or not; values[t], fixed[t] and given[t] follow. Throws for a coefficient term or a
  /// wrong count.
  void set_parameters(std::size_t term, const std::vector<double>& values, bool fixed = true);
  /// True when some term of the joint has named parameters / is hysteretic.
  bool has_parametric_terms() const;
  bool has_hysteretic_terms() const;
};

/// Checks the joints against the model's DOF map (nodes exist, DOFs present and free, names
/// unique, values consistent); throws std::invalid_argument naming the joint.
void validate_joints(const std::vector<Joint>& joints, const fem::DofMap& dofs);

/// Checks that every named parameter of the joint has a value in its range; throws
/// std::invalid_argument naming the joint, the key ("iwan.chi"), the value and the range, or
/// the key without a value. What every simulation needs.
void check_parameters(const Joint& joint);

/// A joint's force as the simulators evaluate it: the coefficient terms but dry friction (set-
/// valued: each simulator treats it exactly), the gaps, and the sliders of its hysteretic terms
/// (all in parallel on one deformation; an iwan as its quadrature). Built once per joint: the
/// constructor checks the parameters (check_parameters()).
class JointLaw {
public:
  explicit JointLaw(const Joint& joint);
  /// Adds g, ∂g/∂y, ∂g/∂ẏ of the memoryless part (coefficient terms but fc, and gaps) at the
  /// samples (all spans of one length).
  void add_memoryless(std::span<const double> y, std::span<const double> ydot, std::span<double> g,
                      std::span<double> gy, std::span<double> gv) const;
  /// The same at one (y, ẏ).
  void memoryless(double y, double ydot, double& g, double& gy, double& gv) const;
  /// The elements of the hysteretic terms (empty: none).
  const Sliders& sliders() const { return sliders_; }
  bool hysteretic() const { return !sliders_.empty(); }

private:
  struct Coefficient {
    Term term;
    double b;
  };
  struct Gap {
    double delta, kg;
  };
  std::vector<Coefficient> coefficients_;
  std::vector<Gap> gaps_;
  Sliders sliders_;
};

/// The joints as local forces for the time integrator (coordinate i = joint i). The state the
/// integrator carries is the positions of the joints' sliders, joint after joint.
class JointForces final : public fem::LocalForces {
public:
  JointForces(std::vector<Joint> joints, const fem::DofMap& dofs);
  const fem::SparseMatrix& coordinates() const override { return B_; }
  void evaluate(const Eigen::VectorXd& y, const Eigen::VectorXd& ydot, Eigen::VectorXd& g,
                Eigen::VectorXd& dg_dy, Eigen::VectorXd& dg_dydot) const override;
  Eigen::VectorXd friction_limits() const override;
  int state_size() const override { return states_; }
  void evaluate_from(std::span<const double> state, const Eigen::VectorXd& y,
                     const Eigen::VectorXd& ydot, Eigen::VectorXd& g, Eigen::VectorXd& dg_dy,
                     Eigen::VectorXd& dg_dydot) const override;
  void advance(std::span<double> state, const Eigen::VectorXd& y) const override;
  bool piecewise_smooth() const override;
  const std::vector<Joint>& joints() const { return joints_; }

private:
  std::vector<Joint> joints_;
  std::vector<JointLaw> laws_;
  std::vector<int> offsets_; ///< per joint, its sliders' first position in the state
  int states_ = 0;
  fem::SparseMatrix B_;
};

/// B (n_eq × n_joints): +1 at a joint's node DOF, −1 at node_b's.
fem::SparseMatrix joint_coordinates(const std::vector<Joint>& joints, const fem::DofMap& dofs);

/// The joints' DOFs (set 2 of the partition), as equation numbers, each once, in joint order.
std::vector<int> joint_dof_set(const std::vector<Joint>& joints, const fem::DofMap& dofs);
/// B restricted to set 2 (|set2| × n_joints): y = Bᵀ x2, and the joints' forces on set 2 are −B g.
Eigen::MatrixXd joint_coordinates_on(const std::vector<Joint>& joints, const fem::DofMap& dofs,
                                     const std::vector<int>& set2);

} // namespace jointid::joints
