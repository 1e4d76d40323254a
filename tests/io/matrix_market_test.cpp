// MatrixMarket K and M with a DOF table ([matrices] in the model file): the reader against
// hand-checked files and round trips, its errors, and the substructure it gives against the
// finite element route on the same structure (modes, receptance, identification).
#include "io/matrix_market.hpp"

#include "fem/modal.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/sine_tests.hpp"
#include "io/cantilever_toml.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "io/test_files.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

using namespace jointid;
namespace fs = std::filesystem;

namespace {

template <class F> std::string error_of(F&& f) {
  try {
    f();
  } catch (const io::Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The cantilever's model file with its finite element tables replaced by [matrices] (K, M and
// the DOF table written from its own assembly), the same [damping] and joint.
struct Exported {
  test::TempDir dir;
  io::ModelFile fe;
  fs::path model;
  Exported() {
    const fs::path fe_path = dir / "fe.toml";
    test::write_text(fe_path, test::cantilever_toml());
    fe = io::read_model(fe_path);
    const fem::Assembled system = fem::assemble(fe.model);
    io::write_matrix_market(dir / "k.mtx", system.K);
    io::write_matrix_market(dir / "m.mtx", system.M);
    std::string table = "# the rows of k.mtx and m.mtx\n";
    for (int e = 0; e < system.dofs.num_equations(); ++e)
      table += fem::to_string(system.dofs.node_dof(e)) + "\n";
    test::write_text(dir / "dofs.txt", table);
    model = dir / "matrices.toml";
    test::write_text(model, text());
  }
  static std::string text(const std::string& extra = "") {
    return "[model]\ndimension = 2\n\n[matrices]\nK = \"k.mtx\"\nM = \"m.mtx\"\n"
           "dofs = \"dofs.txt\"\n" +
           extra +
           "\n[damping]\nmodal = 0.01\n\n[[joints]]\nname = \"tip\"\nnode = 7\ndof = \"uy\"\n"
           "terms = [\"k\", \"c\", \"k3\"]\nvalues = { k = 4800.0, c = 20.0, k3 = 1.6e8 }\n";
  }
};

} // namespace

TEST(MatrixMarket, ReadsAHandCheckedFile) {
  // A general file with a comment, a repeated entry (added, as element-by-element exports
  // write them) and integer and exponent values; a symmetric file given by its upper triangle.
  test::TempDir dir;
  test::write_text(dir / "g.mtx", "%%MatrixMarket matrix coordinate real general\n"
                                  "% a comment\n"
                                  "3 3 5\n"
                                  "1 1 2\n"
                                  "2 2 1.5e3\n"
                                  "1 1 0.5\n"
                                  "3 1 -4\n"
                                  "1 3 -4\n");
  const Eigen::MatrixXd G(io::read_matrix_market(dir / "g.mtx"));
  Eigen::MatrixXd expected(3, 3);
  expected << 2.5, 0, -4, 0, 1500, 0, -4, 0, 0;
  EXPECT_EQ(G, expected);
  test::write_text(dir / "s.mtx", "%%MatrixMarket matrix coordinate real symmetric\n"
                                  "2 2 3\n1 1 4\n1 2 -1\n2 2 3\n");
  const Eigen::MatrixXd S(io::read_matrix_market(dir / "s.mtx"));
  Eigen::MatrixXd s(2, 2);
  s << 4, -1, -1, 3;
  EXPECT_EQ(S, s);
}

TEST(MatrixMarket, RoundTripIsExact) {
  // A random symmetric sparse matrix with values of every magnitude reads back bit for bit.
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < 200; ++k) {
    const int i = static_cast<int>(gen() % 40), j = static_cast<int>(gen() % 40);
    const double v = u(gen) * std::pow(10.0, static_cast<int>(gen() % 30) - 15);
    t.emplace_back(i, j, v);
    if (i != j) t.emplace_back(j, i, v);
  }
  Eigen::SparseMatrix<double> A(40, 40);
  A.setFromTriplets(t.begin(), t.end());
  test::TempDir dir;
  io::write_matrix_market(dir / "a.mtx", A);
  const Eigen::SparseMatrix<double> B = io::read_matrix_market(dir / "a.mtx");
  EXPECT_EQ(Eigen::MatrixXd(A), Eigen::MatrixXd(B));
  // A non-symmetric matrix is not written as symmetric.
  Eigen::SparseMatrix<double> N = A;
  N.coeffRef(0, 1) += 1e-6 * Eigen::MatrixXd(A).cwiseAbs().maxCoeff();
  EXPECT_NE(error_of([&] { io::write_matrix_market(dir / "n.mtx", N); }).find("not symmetric"),
            std::string::npos);
}

TEST(MatrixMarket, MalformedFilesNameTheLineAndWhatWasExpected) {
  test::TempDir dir;
  const std::string head = "%%MatrixMarket matrix coordinate real symmetric\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {"%%MatrixMarket matrix array real general\n2 2\n1\n0\n0\n1\n",
       ":1: expected the 'coordinate'"},
      {"%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n",
       ":1: expected a 'real'"},
      {"%%MatrixMarket matrix coordinate pattern general\n1 1 1\n1 1\n", ":1: expected a 'real'"},
      {"P 2 2 1\n", ":1: expected the header"},
      {head + "2 2\n", ":2: expected the size line"},
      {head + "2 3 1\n1 1 1\n", "must be square"},
      {head + "2 2 2\n1 1 1\n3 1 5\n", ":4: entry (3, 1) is outside the 2 x 2 matrix"},
      {head + "2 2 2\n1 1 1\n2 2 x\n", ":4: expected a finite number as the value, got 'x'"},
      {head + "2 2 2\n1 1 nan\n2 2 1\n", ":3: expected a finite number"},
      {head + "2 2 3\n1 1 1\n2 2 1\n", "announces 3 entries, the file has 2"},
      {head + "2 2 1\n1 1 1\n2 2 1\n", ":4: more entries than the 1"},
      {head + "2 2 3\n1 2 1\n2 1 1\n2 2 1\n", "has entries above (line 3) and below (line 4)"},
      {"", ":1: empty file"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = dir / ("bad" + std::to_string(i) + ".mtx");
    test::write_text(p, cases[i].first);
    const std::string e = error_of([&] { io::read_matrix_market(p); });
    EXPECT_NE(e.find(p.filename().string()), std::string::npos) << e;
    EXPECT_NE(e.find(cases[i].second), std::string::npos) << i << ": " << e;
  }
  EXPECT_NE(error_of([&] { io::read_matrix_market(dir / "missing.mtx"); }).find("missing.mtx"),
            std::string::npos);
}

// Fuzzing regressions (docs/fuzzing.md): a size line alone asked for gigabytes, the matrix's
// column index for its size and the entries' storage for the count it announced.
TEST(MatrixMarket, SizeLineDoesNotAllocateWhatTheFileCannotHold) {
  test::TempDir dir;
  const std::string head = "%%MatrixMarket matrix coordinate real general\n";
  const std::vector<std::pair<std::string, std::string>> cases{
      {head + "1000000000 1000000000 0\n",
       ":2: 1000000000 x 1000000000 is larger than jointid handles (at most 10000000 rows and "
       "columns)"},
      {head + "2 10000001 0\n", ":2: 2 x 10000001 is larger than jointid handles"},
      {head + "1 1 100000000\n1 1 1\n", ":3: the size line announces 100000000 entries, the "
                                        "file has 1"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = dir / ("big" + std::to_string(i) + ".mtx");
    test::write_text(p, cases[i].first);
    const std::string e = error_of([&] { io::read_matrix_market(p); });
    EXPECT_NE(e.find(p.filename().string() + cases[i].second), std::string::npos) << i << ": " << e;
  }
}

TEST(MatrixMarket, DofTableErrors) {
  test::TempDir dir;
  test::write_text(dir / "d1.txt", "1:uy\n1:rz # ok\n\n1:uy\n");
  EXPECT_NE(error_of([&] {
              io::read_dof_table(dir / "d1.txt");
            }).find("d1.txt:4: 1:uy is already on line 1"),
            std::string::npos);
  test::write_text(dir / "d2.txt", "1:uy\n2:uw\n");
  EXPECT_NE(
      error_of([&] { io::read_dof_table(dir / "d2.txt"); }).find("d2.txt:2: expected NODE:DOF"),
      std::string::npos);
  test::write_text(dir / "d4.txt", "1:uy\n0:uy\n");
  EXPECT_EQ(error_of([&] { io::read_dof_table(dir / "d4.txt"); }),
            (dir / "d4.txt").string() + ":2: node ids must be > 0, got '0:uy'");
  test::write_text(dir / "d3.txt", "# nothing\n");
  EXPECT_NE(error_of([&] { io::read_dof_table(dir / "d3.txt"); }).find("no DOFs"),
            std::string::npos);
}

TEST(MatrixMarket, MatricesGiveTheSameSubstructureAsTheFiniteElements) {
  // The same structure by two routes: its model file, and K, M exported to MatrixMarket with
  // the DOF table. The matrices are written with the shortest round-trip text, so they are
  // identical, and the modes (dense engine), the receptance and an identification must agree to
  // rounding (1e-12 relative).
  const Exported x;
  const io::ModelFile mm = io::read_model(x.model);
  ASSERT_TRUE(mm.matrices.has_value());
  const frf::Substructure a = x.fe.substructure(), b = mm.substructure();
  ASSERT_EQ(a.dofs().num_equations(), b.dofs().num_equations());
  const fem::ModalOptions dense{.num_modes = 0, .engine = fem::ModalEngine::dense};
  const fem::Modes ma = fem::modal_analysis(*a.system(), dense),
                   mb = fem::modal_analysis(*b.system(), dense);
  ASSERT_EQ(ma.num_modes(), mb.num_modes());
  for (int r = 0; r < ma.num_modes(); ++r)
    EXPECT_NEAR(mb.frequency_hz(r), ma.frequency_hz(r), 1e-12 * ma.frequency_hz(r)) << r;
  const int tip = a.dofs().equation({7, fem::Dof::uy}), mid = a.dofs().equation({4, fem::Dof::uy});
  ASSERT_EQ(tip, b.dofs().equation({7, fem::Dof::uy}));
  const std::vector<int> dofs{tip, mid};
  const frf::ModalSynthesis Ha = a.synthesis(dofs, 100.0), Hb = b.synthesis(dofs, 100.0);
  for (double f : {1.0, 3.0, 19.0, 55.0}) {
    const Eigen::MatrixXcd ra = Ha.receptance(2 * std::numbers::pi * f, dofs, dofs),
                           rb = Hb.receptance(2 * std::numbers::pi * f, dofs, dofs);
    EXPECT_LE((ra - rb).norm(), 1e-12 * ra.norm()) << f;
  }
  // Tests simulated on the finite element model, identified on each route.
  std::vector<identify::SineTestPlan> plans;
  for (double f : {1.5, 2.5, 3.5, 4.5})
    plans.push_back({f, 40.0});
  identify::SimulationOptions so;
  so.method = identify::SimulationMethod::harmonic_balance;
  so.periods = 2;
  so.steps_per_period = 256;
  std::vector<identify::Measurement> measured;
  for (const auto& t : identify::simulate_sine_tests(a, x.fe.joints, {7, fem::Dof::uy}, plans, so))
    measured.push_back(identify::measure(t.record, {.harmonics = 3}));
  std::vector<joints::Joint> start = x.fe.joints;
  start[0].fixed.assign(start[0].terms.size(), false);
  const identify::FitResult fa = identify::fit(a, start, measured, {.harmonics = {1, 3}});
  const identify::FitResult fb = identify::fit(b, mm.joints, measured, {.harmonics = {1, 3}});
  for (std::size_t t = 0; t < fa.joints[0].terms.size(); ++t)
    EXPECT_NEAR(fb.joints[0].terms[t].value, fa.joints[0].terms[t].value,
                1e-9 * std::abs(fa.joints[0].terms[t].value))
        << t;
}

TEST(MatrixMarket, ModelFileErrorsNameTheCulprit) {
  const Exported x;
  auto error_with = [&](const std::string& text) {
    test::write_text(x.model, text);
    return error_of([&] { io::read_model(x.model); });
  };
  // A DOF table one row short of the matrices.
  std::string rows = test::read_text(x.dir / "dofs.txt");
  rows = rows.substr(0, rows.rfind('\n', rows.size() - 2) + 1);
  test::write_text(x.dir / "short.txt", rows);
  std::string e = error_with(test::replaced(Exported::text(), "dofs.txt", "short.txt"));
  const int n = fem::assemble(x.fe.model).dofs.num_equations(); // 12: uy and rz of 6 nodes
  EXPECT_NE(e.find(fmt::format("matrices.toml:4: [matrices] (k.mtx, m.mtx, {} DOFs): K is {} x {}, "
                               "expected {} x {}",
                               n - 1, n, n, n - 1, n - 1)),
            std::string::npos)
      << e;
  // A joint on a DOF the table does not have.
  e = error_with(test::replaced(Exported::text(), "node = 7", "node = 9"));
  EXPECT_NE(e.find("node 9 is not in the [matrices] DOF table"), std::string::npos) << e;
  // Finite element tables with [matrices].
  e = error_with(Exported::text() + "\n[[supports]]\nnode = 1\nfix = [\"uy\"]\n");
  EXPECT_NE(e.find("not used with [matrices]"), std::string::npos) << e;
  // A missing matrix file.
  e = error_with(test::replaced(Exported::text(), "m.mtx", "nothere.mtx"));
  EXPECT_NE(e.find("nothere.mtx"), std::string::npos) << e;
  // An unsymmetric K.
  test::write_text(
      x.dir / "u.mtx", fmt::format("%%MatrixMarket matrix coordinate real "
                                   "general\n{} {} {}\n",
                                   n, n, n + 1) +
                           [n] {
                             std::string s;
                             for (int i = 1; i <= n; ++i)
                               s += std::to_string(i) + " " + std::to_string(i) + " 1\n";
                             return s;
                           }() +
                           "1 2 5\n");
  e = error_with(test::replaced(Exported::text(), "k.mtx", "u.mtx"));
  EXPECT_NE(e.find("K is not symmetric: entries (2, 1) and (1, 2) differ by"), std::string::npos)
      << e;
}

TEST(MatrixMarket, NonFiniteSumsAndNegativeMassesAreNamed) {
  const Exported x;
  const int n = fem::assemble(x.fe.model).dofs.num_equations();
  // A diagonal matrix with `first` at (1, 1): entries given twice are added.
  auto diagonal = [n](const std::string& first) {
    std::string s = first;
    int entries = 0;
    for (char c : first)
      entries += c == '\n';
    for (int i = 2; i <= n; ++i, ++entries)
      s += fmt::format("{} {} 1\n", i, i);
    return fmt::format("%%MatrixMarket matrix coordinate real general\n{} {} {}\n", n, n, entries) +
           s;
  };
  auto error_with = [&](const std::string& from, const std::string& to) {
    test::write_text(x.model, test::replaced(Exported::text(), from, to));
    return error_of([&] { io::read_model(x.model); });
  };
  // Each value is finite, their sum is not.
  test::write_text(x.dir / "huge.mtx", diagonal("1 1 1e308\n1 1 1e308\n"));
  std::string e = error_with("k.mtx", "huge.mtx");
  EXPECT_NE(e.find(fmt::format("matrices.toml:4: [matrices] (huge.mtx, m.mtx, {} DOFs): K: entry "
                               "(1, 1) is not finite",
                               n)),
            std::string::npos)
      << e;
  // The first row of the table is 2:uy (node 1 is clamped).
  test::write_text(x.dir / "negative.mtx", diagonal("1 1 -0.5\n"));
  e = error_with("m.mtx", "negative.mtx");
  EXPECT_NE(e.find(fmt::format("matrices.toml:4: [matrices] (k.mtx, negative.mtx, {} DOFs): M: "
                               "diagonal entry 1 (2:uy) is negative: -0.5",
                               n)),
            std::string::npos)
      << e;
}

// A K that is not positive definite (issue 31): a 0 Hz first mode or an imaginary one, refused
// naming the DOF where its factorisation breaks down, rather than analysed.
TEST(MatrixMarket, AStiffnessThatIsNotPositiveDefiniteIsRefused) {
  const Exported x;
  const int n = fem::assemble(x.fe.model).dofs.num_equations();
  auto diagonal = [n](const std::string& first) {
    std::string s =
        fmt::format("%%MatrixMarket matrix coordinate real general\n{} {} {}\n{}", n, n, n, first);
    for (int i = 2; i <= n; ++i)
      s += fmt::format("{} {} 1\n", i, i);
    return s;
  };
  auto error_with = [&](const std::string& k_text) {
    test::write_text(x.dir / "k_bad.mtx", k_text);
    test::write_text(x.model, test::replaced(Exported::text(), "k.mtx", "k_bad.mtx"));
    return error_of([&] { io::read_model(x.model); });
  };
  // The first row of the table is 2:uy: stiffness 0 there (free to move: a 0 Hz mode), then -1.
  std::string e = error_with(diagonal("1 1 0\n"));
  EXPECT_NE(e.find(fmt::format("matrices.toml:4: [matrices] (k_bad.mtx, m.mtx, {} DOFs): K is not "
                               "positive definite: its factorisation breaks down at 2:uy (pivot 0, "
                               "diagonal 0): a rigid-body motion or a mechanism (a 0 Hz mode) "
                               "there",
                               n)),
            std::string::npos)
      << e;
  e = error_with(diagonal("1 1 -1\n"));
  EXPECT_NE(e.find("K is not positive definite: its factorisation breaks down at 2:uy (pivot -1, "
                   "diagonal -1): a negative stiffness there"),
            std::string::npos)
      << e;
  // Singular without a zero on the diagonal: two DOFs tied by a spring alone (rows 1 and 2 of
  // [[1, -1], [-1, 1]]): a rigid-body motion of the pair, found whichever row it reaches last.
  e = error_with(
      fmt::format("%%MatrixMarket matrix coordinate real symmetric\n{} {} {}\n1 1 1\n2 1 "
                  "-1\n2 2 1\n",
                  n, n, n + 1) +
      [&] {
        std::string s;
        for (int i = 3; i <= n; ++i)
          s += fmt::format("{} {} 1\n", i, i);
        return s;
      }());
  EXPECT_NE(e.find("K is not positive definite: its factorisation breaks down at "),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("a rigid-body motion or a mechanism (a 0 Hz mode) there"), std::string::npos)
      << e;
}
