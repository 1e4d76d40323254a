#include "joints/joint.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

namespace jointid::joints {

namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

} // namespace

double Joint::force(double y, double ydot) const {
  double g = 0.0;
  for (std::size_t j = 0; j < terms.size(); ++j) {
    if (is_hysteretic(terms[j]))
      throw std::invalid_argument("joint '" + name + "': the force of term '" +
                                  std::string(term_name(terms[j])) +
                                  "' depends on the history of y, not on (y, ydot) alone");
    if (terms[j] == Term::gap)
      g += gap_force(parameter(j, "delta"), parameter(j, "kg"), y);
    else
      g += values[j] * basis(terms[j], y, ydot);
  }
  return g;
}

std::span<const Parameter> Joint::parameters_of(std::size_t t) const {
  if (t >= parameters.size()) return {};
  return parameters[t];
}

double Joint::parameter(std::size_t t, std::string_view key) const {
  const int i = t < terms.size() ? parameter_index(terms[t], key) : -1;
  const auto list = parameters_of(t);
  if (i < 0 || static_cast<std::size_t>(i) >= list.size())
    throw std::invalid_argument(
        "joint '" + name + "': no parameter '" + std::string(key) + "'" +
        (t < terms.size() ? " of term '" + std::string(term_name(terms[t])) + "'" : std::string()));
  return list[static_cast<std::size_t>(i)].value;
}

void Joint::set_parameters(std::size_t t, const std::vector<double>& list, bool fix) {
  if (t >= terms.size() || !has_parameters(terms[t]))
    throw std::invalid_argument("joint '" + name +
                                "': set_parameters on a term without named "
                                "parameters");
  const std::size_t count = term_info(terms[t]).parameters.size();
  if (list.size() != count)
    throw std::invalid_argument("joint '" + name + "': term '" + std::string(term_name(terms[t])) +
                                "' has " + std::to_string(count) + " parameters (" +
                                parameter_names(terms[t]) + "), got " +
                                std::to_string(list.size()));
  parameters.resize(terms.size());
  parameters[t].clear();
  for (double v : list)
    parameters[t].push_back({v, fix, true});
  values.resize(terms.size(), 0.0);
  fixed.resize(terms.size(), false);
  values[t] = 1.0;
  fixed[t] = fix;
  if (!given.empty()) given[t] = true;
}

bool Joint::has_parametric_terms() const {
  return std::any_of(terms.begin(), terms.end(), [](Term t) { return has_parameters(t); });
}

bool Joint::has_hysteretic_terms() const {
  return std::any_of(terms.begin(), terms.end(), [](Term t) { return is_hysteretic(t); });
}

void check_parameters(const Joint& j) {
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const TermInfo& info = term_info(j.terms[t]);
    const auto list = j.parameters_of(t);
    for (std::size_t p = 0; p < info.parameters.size(); ++p) {
      const ParameterInfo& pi = info.parameters[p];
      std::string key;
      key.append("'").append(info.name).append(".").append(pi.name).append("'");
      if (p >= list.size() || !list[p].given)
        throw std::invalid_argument("joint '" + j.name + "': " + key + " has no value (" +
                                    std::string(pi.meaning) + ", " + std::string(pi.unit) +
                                    "; every parameter of '" + std::string(info.name) +
                                    "' is needed to simulate it)");
      if (!in_range(pi, list[p].value))
        throw std::invalid_argument("joint '" + j.name + "': " + key + " = " +
                                    number(list[p].value) + " is out of range: expected " +
                                    range_text(pi) + " (" + std::string(pi.meaning) + ")");
    }
  }
  if (j.iwan_sliders < 2 && j.term_index(Term::iwan) >= 0)
    throw std::invalid_argument("joint '" + j.name + "': an iwan needs at least 2 sliders, got " +
                                std::to_string(j.iwan_sliders));
}

JointLaw::JointLaw(const Joint& j) {
  check_parameters(j);
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const Term term = j.terms[t];
    switch (term) {
    case Term::jenkins:
      sliders_.append(jenkins_sliders(j.parameter(t, "kt"), j.parameter(t, "fs")));
      break;
    case Term::iwan:
      sliders_.append(iwan_sliders(j.parameter(t, "fs"), j.parameter(t, "kt"),
                                   j.parameter(t, "chi"), j.parameter(t, "beta"), j.iwan_sliders));
      break;
    case Term::gap:
      gaps_.push_back({j.parameter(t, "delta"), j.parameter(t, "kg")});
      break;
    case Term::fc: // set-valued: each simulator treats it
      break;
    default:
      if (j.values[t] != 0.0) coefficients_.push_back({term, j.values[t]});
    }
  }
}

void JointLaw::add_memoryless(std::span<const double> y, std::span<const double> v,
                              std::span<double> g, std::span<double> gy,
                              std::span<double> gv) const {
  for (const Coefficient& c : coefficients_)
    add_samples(c.term, c.b, y, v, g, gy, gv);
  for (const Gap& gap : gaps_)
    for (std::size_t i = 0; i < y.size(); ++i) {
      double slope;
      g[i] += gap_force(gap.delta, gap.kg, y[i], &slope);
      gy[i] += slope;
    }
}

void JointLaw::memoryless(double y, double v, double& g, double& gy, double& gv) const {
  g = gy = gv = 0.0;
  add_memoryless({&y, 1}, {&v, 1}, {&g, 1}, {&gy, 1}, {&gv, 1});
}

int Joint::term_index(Term t) const {
  for (std::size_t j = 0; j < terms.size(); ++j)
    if (terms[j] == t) return static_cast<int>(j);
  return -1;
}

void validate_joints(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  std::set<std::string> names;
  for (const auto& j : joints) {
    const std::string which = "joint '" + j.name + "'";
    if (j.name.empty()) throw std::invalid_argument("a joint has no name");
    if (!names.insert(j.name).second)
      throw std::invalid_argument("duplicate joint name '" + j.name + "'");
    if (j.terms.empty()) throw std::invalid_argument(which + " has no terms");
    if (j.values.size() != j.terms.size() || j.fixed.size() != j.terms.size() ||
        (!j.given.empty() && j.given.size() != j.terms.size()))
      throw std::invalid_argument(which + ": values and terms differ in number");
    std::set<Term> seen;
    for (Term t : j.terms)
      if (!seen.insert(t).second)
        throw std::invalid_argument(which + " lists term '" + std::string(term_name(t)) +
                                    "' twice");
    if (!j.parameters.empty() && j.parameters.size() != j.terms.size())
      throw std::invalid_argument(which + ": parameters and terms differ in number");
    for (std::size_t t = 0; t < j.terms.size(); ++t) {
      const std::size_t count = term_info(j.terms[t]).parameters.size();
      if (count == 0 ? !j.parameters_of(t).empty() : j.parameters_of(t).size() != count)
        throw std::invalid_argument(which + ": term '" + std::string(term_name(j.terms[t])) +
                                    "' has " + std::to_string(count) + " named parameters, got " +
                                    std::to_string(j.parameters_of(t).size()));
    }
    if (j.node == j.node_b)
      throw std::invalid_argument(which + " connects node " + std::to_string(j.node) +
                                  " to itself");
    try {
      dofs.equation({j.node, j.dof});
      if (!j.to_ground()) dofs.equation({j.node_b, j.dof});
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(which + ": " + e.what());
    }
  }
}

fem::SparseMatrix joint_coordinates(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto& j = joints[i];
    entries.emplace_back(dofs.equation({j.node, j.dof}), static_cast<int>(i), 1.0);
    if (!j.to_ground())
      entries.emplace_back(dofs.equation({j.node_b, j.dof}), static_cast<int>(i), -1.0);
  }
  fem::SparseMatrix B(dofs.num_equations(), static_cast<int>(joints.size()));
  B.setFromTriplets(entries.begin(), entries.end());
  return B;
}

std::vector<int> joint_dof_set(const std::vector<Joint>& joints, const fem::DofMap& dofs) {
  std::vector<int> set2;
  auto add = [&](int eq) {
    if (std::find(set2.begin(), set2.end(), eq) == set2.end()) set2.push_back(eq);
  };
  for (const auto& j : joints) {
    add(dofs.equation({j.node, j.dof}));
    if (!j.to_ground()) add(dofs.equation({j.node_b, j.dof}));
  }
  return set2;
}

Eigen::MatrixXd joint_coordinates_on(const std::vector<Joint>& joints, const fem::DofMap& dofs,
                                     const std::vector<int>& set2) {
  auto position = [&](int node, fem::Dof dof) {
    const auto it = std::find(set2.begin(), set2.end(), dofs.equation({node, dof}));
    if (it == set2.end())
      throw std::invalid_argument("joint DOF " + fem::to_string({node, dof}) + " is not in set 2");
    return static_cast<int>(it - set2.begin());
  };
  Eigen::MatrixXd B =
      Eigen::MatrixXd::Zero(static_cast<int>(set2.size()), static_cast<int>(joints.size()));
  for (std::size_t i = 0; i < joints.size(); ++i) {
    B(position(joints[i].node, joints[i].dof), i) = 1.0;
    if (!joints[i].to_ground()) B(position(joints[i].node_b, joints[i].dof), i) = -1.0;
  }
  return B;
}

JointForces::JointForces(std::vector<Joint> joints, const fem::DofMap& dofs)
    : joints_(std::move(joints)) {
  validate_joints(joints_, dofs);
  for (const auto& j : joints_) {
    const int i = j.term_index(Term::fc);
    if (i >= 0 && j.values[i] < 0.0)
      throw std::invalid_argument("joint '" + j.name +
                                  "': Coulomb friction fc must be >= 0 N to simulate");
    laws_.emplace_back(j);
    offsets_.push_back(states_);
    states_ += laws_.back().sliders().size();
  }
  B_ = joint_coordinates(joints_, dofs);
}

// Without a state: the sliders at rest at zero deformation (x = 0).
void JointForces::evaluate(const Eigen::VectorXd& y, const Eigen::VectorXd& ydot,
                           Eigen::VectorXd& g, Eigen::VectorXd& dg_dy,
                           Eigen::VectorXd& dg_dydot) const {
  const std::vector<double> rest(static_cast<std::size_t>(states_), 0.0);
  evaluate_from(rest, y, ydot, g, dg_dy, dg_dydot);
}

void JointForces::evaluate_from(std::span<const double> state, const Eigen::VectorXd& y,
                                const Eigen::VectorXd& ydot, Eigen::VectorXd& g,
                                Eigen::VectorXd& dg_dy, Eigen::VectorXd& dg_dydot) const {
  const int n = static_cast<int>(joints_.size());
  g.setZero(n);
  dg_dy.setZero(n);
  dg_dydot.setZero(n);
  for (int i = 0; i < n; ++i) {
    const JointLaw& law = laws_[static_cast<std::size_t>(i)];
    law.memoryless(y(i), ydot(i), g(i), dg_dy(i), dg_dydot(i));
    if (!law.hysteretic()) continue;
    double tangent = 0.0;
    g(i) +=
        slide_trial(law.sliders(),
                    state.subspan(static_cast<std::size_t>(offsets_[static_cast<std::size_t>(i)]),
                                  static_cast<std::size_t>(law.sliders().size())),
                    y(i), &tangent);
    dg_dy(i) += tangent;
  }
}

bool JointForces::piecewise_smooth() const {
  return std::any_of(joints_.begin(), joints_.end(),
                     [](const Joint& j) { return j.has_parametric_terms(); });
}

void JointForces::advance(std::span<double> state, const Eigen::VectorXd& y) const {
  for (std::size_t i = 0; i < laws_.size(); ++i)
    if (laws_[i].hysteretic())
      slide(laws_[i].sliders(),
            state.subspan(static_cast<std::size_t>(offsets_[i]),
                          static_cast<std::size_t>(laws_[i].sliders().size())),
            y(static_cast<Eigen::Index>(i)));
}

Eigen::VectorXd JointForces::friction_limits() const {
  Eigen::VectorXd F = Eigen::VectorXd::Zero(static_cast<int>(joints_.size()));
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const int t = joints_[i].term_index(Term::fc);
    if (t >= 0) F(i) = joints_[i].values[t];
  }
  return F;
}

} // namespace jointid::joints
