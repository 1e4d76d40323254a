// Joint force basis functions: the METHOD.md table, derivatives against finite differences.
#include "joints/basis.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

using namespace jointid::joints;

namespace {

// g(y, ẏ) written out from the METHOD.md table, independently of the library.
double table(Term t, double y, double v) {
  switch (t) {
  case Term::k:
    return y;
  case Term::c:
    return v;
  case Term::k2:
    return y * y;
  case Term::k3:
    return std::pow(y, 3);
  case Term::c2:
    return v * std::fabs(v);
  case Term::c3:
    return std::pow(v, 3);
  case Term::fc:
    return v == 0.0 ? 0.0 : std::copysign(1.0, v);
  case Term::jenkins: // parametric: no g(y, ẏ)
  case Term::iwan:
  case Term::gap:
    break;
  }
  return NAN;
}

const std::vector<double> samples{-1.3, -0.4, -0.013, 0.002, 0.37, 1.9};

std::string error_of(std::string_view name) {
  try {
    parse_term(name);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(Basis, ValuesFollowTheMethodTable) {
  for (Term t : coefficient_terms)
    for (double y : samples)
      for (double v : samples)
        EXPECT_DOUBLE_EQ(basis(t, y, v), table(t, y, v)) << term_name(t) << " " << y << " " << v;
  // Coulomb friction is 0 at rest (the identification basis), odd in ẏ elsewhere.
  EXPECT_EQ(basis(Term::fc, 0.3, 0.0), 0.0);
  EXPECT_EQ(basis(Term::fc, 0.3, -1e-300), -1.0);
}

TEST(Basis, DerivativesMatchCentralDifferences) {
  // Central differences with step δ = 1e-5 (1 + |x|): truncation δ²|g'''|/6 ≤ 1e-10 (1+|x|)²·
  // (at most 6 for the cubics), cancellation eps|g|/δ ≈ 1e-10; 1e-7 (1 + |g'|) leaves margin
  // while a wrong factor (e.g. 2y for 3y²) is off by order 1.
  for (Term t : coefficient_terms)
    for (double y : samples)
      for (double v : samples) {
        const double dy = 1e-5 * (1 + std::abs(y)), dv = 1e-5 * (1 + std::abs(v));
        const double fd_y = (basis(t, y + dy, v) - basis(t, y - dy, v)) / (2 * dy);
        const double fd_v = (basis(t, y, v + dv) - basis(t, y, v - dv)) / (2 * dv);
        const double gy = basis_dy(t, y, v), gv = basis_dydot(t, y, v);
        EXPECT_NEAR(gy, fd_y, 1e-7 * (1 + std::abs(gy)))
            << term_name(t) << " y=" << y << " v=" << v;
        EXPECT_NEAR(gv, fd_v, 1e-7 * (1 + std::abs(gv)))
            << term_name(t) << " y=" << y << " v=" << v;
      }
  // At ẏ = 0, ẏ|ẏ| is still differentiable (slope 0) and the FD agrees.
  EXPECT_NEAR(basis_dydot(Term::c2, 0.1, 0.0), 0.0, 1e-12);
  // The sign function's derivative is taken as 0 (set-valued friction is handled elsewhere).
  EXPECT_EQ(basis_dydot(Term::fc, 0.1, 0.0), 0.0);
}

TEST(Basis, SamplesAddTheTableValuesAndDerivativesTimesTheCoefficient) {
  // add_samples() is the vectorised form of basis(), basis_dy() and basis_dydot(): on every pair
  // of the samples (ẏ = 0 included, where friction and ẏ|ẏ| are special) it must add exactly
  // b times their values to what the arrays held.
  std::vector<double> y, v;
  for (double a : samples)
    for (double b : samples)
      y.push_back(a), v.push_back(b);
  y.push_back(0.5), v.push_back(0.0);
  const std::size_t n = y.size();
  for (Term t : coefficient_terms) {
    const double b = -2.75;
    std::vector<double> g(n, 1.0), gy(n, 2.0), gv(n, 3.0);
    add_samples(t, b, y, v, g, gy, gv);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_DOUBLE_EQ(g[i], 1.0 + b * basis(t, y[i], v[i])) << term_name(t) << " " << i;
      EXPECT_DOUBLE_EQ(gy[i], 2.0 + b * basis_dy(t, y[i], v[i])) << term_name(t) << " " << i;
      EXPECT_DOUBLE_EQ(gv[i], 3.0 + b * basis_dydot(t, y[i], v[i])) << term_name(t) << " " << i;
    }
  }
  std::vector<double> g(2), gy(2), gv(3);
  EXPECT_THROW(add_samples(Term::k, 1.0, std::vector<double>(2), std::vector<double>(2), g, gy, gv),
               std::invalid_argument);
}

TEST(Basis, NamesEffectsAndUnitsFollowTheMethodTable) {
  // Name, key words of the effect column, and the unit of b such that b·g is a force (N): g
  // has the units of y^p ẏ^q.
  struct Row {
    Term term;
    std::string name;
    std::vector<std::string> effect_words;
    std::string unit;
  };
  const std::vector<Row> rows{
      {Term::k, "k", {"linear", "stiffness"}, "N/m"},
      {Term::c, "c", {"viscous", "damping"}, "N s/m"},
      {Term::k2, "k2", {"quadratic", "stiffness"}, "N/m^2"},
      {Term::k3, "k3", {"cubic", "stiffness"}, "N/m^3"},
      {Term::c2, "c2", {"velocity-squared", "damping"}, "N s^2/m^2"},
      {Term::c3, "c3", {"cubic", "damping"}, "N s^3/m^3"},
      {Term::fc, "fc", {"Coulomb", "friction"}, "N"},
  };
  ASSERT_EQ(rows.size(), coefficient_terms.size());
  for (const auto& row : rows) {
    EXPECT_EQ(term_name(row.term), row.name);
    EXPECT_EQ(parse_term(row.name), row.term);
    const std::string effect(term_effect(row.term));
    for (const auto& word : row.effect_words)
      EXPECT_NE(effect.find(word), std::string::npos) << row.name << ": '" << effect << "'";
    EXPECT_EQ(term_unit(row.term), row.unit) << row.name;
    EXPECT_EQ(is_dry_friction(row.term), row.term == Term::fc);
  }
}

TEST(Basis, ParseTermRejectsUnknownNames) {
  for (std::string_view bad : {"k4", "", "K", "fc ", "friction"}) {
    const std::string message = error_of(bad);
    ASSERT_FALSE(message.empty()) << "'" << bad << "' was accepted";
    std::string quoted(1, '\'');
    quoted.append(bad).push_back('\'');
    EXPECT_NE(message.find(quoted), std::string::npos) << message;
    EXPECT_NE(message.find("k, c, k2, k3, c2, c3, fc"), std::string::npos) << message;
  }
}

TEST(Basis, TableEntriesAreInEnumOrder) {
  for (Term t : all_terms) {
    EXPECT_EQ(term_info(t).term, t);
    EXPECT_EQ(&term_info(t), &term_table()[static_cast<std::size_t>(t)]);
  }
}

// The properties the table declares (degree, parity, nature) are checked on g itself, so a
// wrong entry — which would mislead discovery's diagnosis — fails here.
TEST(Basis, DeclaredPropertiesHoldForTheForceLaw) {
  for (Term t : coefficient_terms) {
    const TermInfo& info = term_info(t);
    for (double y : samples)
      for (double v : samples) {
        const double g = basis(t, y, v);
        // Homogeneity: g(s y, s v) = s^degree g(y, v).
        for (double s : {0.5, 3.0})
          EXPECT_NEAR(basis(t, s * y, s * v), std::pow(s, info.degree) * g,
                      1e-12 * (1 + std::abs(g)) * std::pow(s, info.degree))
              << info.name << " s=" << s;
        // Parity: even terms are unchanged by (y, v) → (−y, −v), the others change sign.
        EXPECT_DOUBLE_EQ(basis(t, -y, -v), info.even ? g : -g) << info.name;
        // Nature: a conservative force ignores ẏ, a dissipative one ignores y.
        if (info.nature == Nature::conservative)
          EXPECT_EQ(basis(t, y, 2.0 * v + 1.0), g) << info.name;
        else
          EXPECT_EQ(basis(t, 2.0 * y + 1.0, v), g) << info.name;
      }
    EXPECT_EQ(is_linear(t), t == Term::k || t == Term::c) << info.name;
    EXPECT_FALSE(info.rotational_unit.empty()) << info.name;
  }
}

TEST(Basis, NameListComesFromTheTable) {
  EXPECT_EQ(term_names(), "k, c, k2, k3, c2, c3, fc, jenkins, iwan, gap");
}

TEST(Basis, ParametricTermsNameTheirParametersUnitsAndRanges) {
  // The rows of issue 32: jenkins (kt, fs), iwan (fs, kt, chi, beta), gap (delta, kg), each
  // with the SI unit of a translational joint and the range a value must lie in.
  struct Row {
    Term term;
    std::string name;
    std::vector<std::string> parameters, units;
    bool hysteretic;
  };
  const std::vector<Row> rows{
      {Term::jenkins, "jenkins", {"kt", "fs"}, {"N/m", "N"}, true},
      {Term::iwan, "iwan", {"fs", "kt", "chi", "beta"}, {"N", "N/m", "1", "1"}, true},
      {Term::gap, "gap", {"delta", "kg"}, {"m", "N/m"}, false},
  };
  ASSERT_EQ(rows.size(), parametric_terms.size());
  for (const Row& row : rows) {
    EXPECT_EQ(term_name(row.term), row.name);
    EXPECT_EQ(parse_term(row.name), row.term);
    EXPECT_TRUE(has_parameters(row.term));
    EXPECT_EQ(is_hysteretic(row.term), row.hysteretic);
    const TermInfo& info = term_info(row.term);
    ASSERT_EQ(info.parameters.size(), row.parameters.size()) << row.name;
    for (std::size_t p = 0; p < row.parameters.size(); ++p) {
      EXPECT_EQ(info.parameters[p].name, row.parameters[p]);
      EXPECT_EQ(info.parameters[p].unit, row.units[p]) << row.parameters[p];
      EXPECT_EQ(parameter_index(row.term, row.parameters[p]), static_cast<int>(p));
    }
    // no basis function: basis() refuses, naming the term
    try {
      basis(row.term, 0.1, 0.2);
      ADD_FAILURE() << row.name << ": basis() accepted a parametric term";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("'" + row.name + "'"), std::string::npos);
    }
    EXPECT_EQ(info.degree, -1) << row.name; // not homogeneous: a slip force or a gap sets a scale
    EXPECT_FALSE(info.even) << row.name;    // odd: no even harmonics under a symmetric load
  }
  for (Term t : coefficient_terms)
    EXPECT_FALSE(has_parameters(t)) << term_name(t);
  EXPECT_EQ(parameter_index(Term::iwan, "k"), -1);
  // The ranges the model reader enforces (docs/formats/model_file.md).
  auto range = [](Term t, const char* name) {
    return term_info(t).parameters[static_cast<std::size_t>(parameter_index(t, name))];
  };
  EXPECT_TRUE(in_range(range(Term::iwan, "chi"), 0.0));
  EXPECT_TRUE(in_range(range(Term::iwan, "chi"), -0.99));
  EXPECT_FALSE(in_range(range(Term::iwan, "chi"), -1.0));
  EXPECT_FALSE(in_range(range(Term::iwan, "chi"), 0.01));
  EXPECT_EQ(range_text(range(Term::iwan, "chi")), "in (-1, 0]");
  EXPECT_FALSE(in_range(range(Term::iwan, "fs"), 0.0));
  EXPECT_EQ(range_text(range(Term::iwan, "fs")), "> 0");
  EXPECT_TRUE(in_range(range(Term::iwan, "beta"), 0.0));
  EXPECT_FALSE(in_range(range(Term::jenkins, "kt"), -1.0));
  EXPECT_TRUE(in_range(range(Term::gap, "delta"), 0.0));
  EXPECT_FALSE(in_range(range(Term::gap, "delta"), -1e-6));
  EXPECT_EQ(range_text(range(Term::gap, "delta")), ">= 0");
  EXPECT_FALSE(in_range(range(Term::gap, "kg"), std::nan("")));
}
