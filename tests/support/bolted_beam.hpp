#pragma once
// A stand-in for a bolted beam's stepped-sine tables (we have no real ones): a steel cantilever
// 0.4 m × 30 mm × 12 mm, 10 beam elements, 0.3 % modal damping, clamped at node 1, its tip
// (node 11) held by a joint to ground that has, besides k and c, a softening cubic stiffness and
// a cubic damping, as bolted joints do (microslip: the stiffness falls and the damping grows
// with the amplitude). The first mode with the joint is near 75 Hz. Stepped-sine tests around
// it: at each force level a sweep up in frequency, every step solved by harmonic balance from
// the previous step's steady state (a shaker test's sweep follows one branch, and jumps where
// it ends at a fold), force and
// drive-point acceleration only, the fundamentals kept (a table row), each phasor with complex
// Gaussian noise of a given share of its magnitude. The result is a stepped-sine table, as
// `jointid discover` reads it from a CSV file (io::stepped_sine_csv writes it).
#include "fem/model.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"
#include "identify/stepped_sine.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace jointid::test {

inline fem::Model bolted_beam(int elements = 10) {
  fem::Model m;
  m.dimension = 2;
  const double L = 0.4, b = 0.03, t = 0.012;
  m.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  m.sections.push_back({"bar", b * t, b * t * t * t / 12.0, 0.0, 0.0});
  for (int i = 0; i <= elements; ++i)
    m.nodes.push_back({i + 1, Eigen::Vector3d(L * i / elements, 0.0, 0.0)});
  for (int i = 0; i < elements; ++i)
    m.elements.push_back({i + 1, i + 1, i + 2, fem::ElementType::beam, 0, 0});
  m.supports.push_back({1, {fem::Dof::ux, fem::Dof::uy, fem::Dof::rz}});
  m.damping.kind = fem::Damping::Kind::modal;
  m.damping.modal_ratio = 0.003;
  return m;
}

/// The joint at the tip: k, c and further terms with their values.
inline joints::Joint bolt(std::vector<joints::Term> terms, std::vector<double> values) {
  joints::Joint j{"bolt", 11, 0, fem::Dof::uy, std::move(terms), std::move(values), {}, {}};
  j.fixed.assign(j.terms.size(), false);
  return j;
}

/// The truth of the tables: k = 2e4 N/m, c = 2 N s/m, k3 = −3e9 N/m³, c3 = 10 N s³/m³.
inline joints::Joint bolt_truth() {
  using joints::Term;
  return bolt({Term::k, Term::c, Term::k3, Term::c3}, {2e4, 2.0, -3e9, 10.0});
}

/// The starting model discovery is given: k and c, values unknown.
inline joints::Joint bolt_start() {
  joints::Joint j = bolt({joints::Term::k, joints::Term::c}, {0.0, 0.0});
  j.given.assign(2, false);
  return j;
}

struct SteppedSinePlan {
  std::vector<double> levels;      ///< force amplitudes (peak), N
  std::vector<double> frequencies; ///< Hz, ascending: each level's sweep
  double noise = 0.01;             ///< phasor noise, a share of its magnitude (RMS)
  unsigned seed = 1;
};

/// `levels` levels from `low` to `high` N, evenly in ratio, and `count` frequencies from `f0` to
/// `f1` Hz.
inline SteppedSinePlan stepped_sine_plan(int levels, double low, double high, int count, double f0,
                                         double f1) {
  SteppedSinePlan p;
  for (int i = 0; i < levels; ++i)
    p.levels.push_back(low * std::pow(high / low, levels > 1 ? double(i) / (levels - 1) : 0.0));
  for (int i = 0; i < count; ++i)
    p.frequencies.push_back(f0 + (f1 - f0) * (count > 1 ? double(i) / (count - 1) : 0.0));
  return p;
}

/// The table's rows, level by level, each level swept up in frequency (see the top): columns
/// f@11:uy and a@11:uy. Throws std::runtime_error when a step's harmonic balance does not
/// converge.
inline identify::SteppedSineTable stepped_sine_table(const fem::Model& model,
                                                     const joints::Joint& truth,
                                                     const SteppedSinePlan& plan) {
  const frf::Substructure sub(model);
  const int tip = sub.dofs().equation({11, fem::Dof::uy});
  const frf::ModalSynthesis H = sub.synthesis({tip}, 20.0 * plan.frequencies.back());
  std::mt19937 random(plan.seed);
  std::normal_distribution<double> normal(0.0, std::sqrt(0.5)); // a complex unit of variance 1
  auto noisy = [&](std::complex<double> z) {
    return z + plan.noise * std::abs(z) * std::complex<double>(normal(random), normal(random));
  };
  identify::SteppedSineTable table;
  table.channels = {"f@11:uy", "a@11:uy"};
  const auto rows = static_cast<Eigen::Index>(plan.levels.size() * plan.frequencies.size());
  table.values.resize(rows, 2);
  Eigen::Index row = 0;
  for (double level : plan.levels) {
    Eigen::MatrixXcd previous;
    for (double f : plan.frequencies) {
      const frf::HarmonicBalance hb(H, {truth}, sub.dofs(), {tip}, {tip}, f, {.harmonics = 9});
      frf::HarmonicBalanceResult r =
          hb.solve({truth}, frf::sine_force(level), previous.size() > 0 ? &previous : nullptr);
      // Past a fold the sweep jumps: to the branch the linear response leads to, or one found
      // from the last steady state scaled.
      if (!r.status.ok() && previous.size() > 0) r = hb.solve({truth}, frf::sine_force(level));
      for (double scale : {0.5, 2.0, 0.25, 4.0})
        if (!r.status.ok() && previous.size() > 0) {
          const Eigen::MatrixXcd start = scale * previous;
          r = hb.solve({truth}, frf::sine_force(level), &start);
        }
      if (!r.status.ok())
        throw std::runtime_error("bolted beam at " + std::to_string(f) + " Hz, " +
                                 std::to_string(level) + " N: " + r.status.reason);
      previous = r.Y;
      const double w = 2.0 * std::numbers::pi * f;
      table.freq_hz.push_back(f);
      table.values(row, 0) = noisy({0.0, -level}); // F sin ωt = Re(−iF e^{iωt})
      table.values(row, 1) = noisy(-w * w * r.X(1, 0));
      ++row;
    }
  }
  return table;
}

} // namespace jointid::test
