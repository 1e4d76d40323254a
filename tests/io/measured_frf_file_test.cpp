// A substructure given by measured FRFs ([frf] in the model file): universal files (dataset 58,
// function type 4) and CSV tables read against hand-checked files and round trips of the finite
// element route's FRFs in every kind and unit; their errors; and the identification through
// measured FRFs against the finite element route on the same structure.
#include "io/measured_frf_file.hpp"

#include "frf/sweep.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"
#include "identify/sine_tests.hpp"
#include "io/cantilever_toml.hpp"
#include "io/files.hpp"
#include "io/frf_output.hpp"
#include "io/model_file.hpp"
#include "io/test_files.hpp"
#include "io/uff58.hpp"
#include "support/error_of.hpp"
#include "support/numbers.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

using namespace jointid;
using fem::Dof;
namespace fs = std::filesystem;
using test::error_of;

namespace {

using jointid::test::two_pi;

// The cantilever of DESIGN.md (joint at 7:uy) by finite elements, and its FRFs from a force at
// 7:uy to 7:uy and 4:uy at lines 0, h, 2h, … f_max.
struct Cantilever {
  test::TempDir dir;
  io::ModelFile fe;
  frf::Substructure sub;
  int tip, mid;
  Cantilever()
      : fe([this] {
          test::write_text(dir / "fe.toml", test::cantilever_toml());
          return io::read_model(dir / "fe.toml");
        }()),
        sub(fe.substructure()), tip(sub.dofs().equation({7, Dof::uy})),
        mid(sub.dofs().equation({4, Dof::uy})) {}
  frf::FrfSweep sweep(frf::FrfKind kind, double h, double f_max) const {
    std::vector<double> f;
    for (int i = 0; i * h <= f_max + 1e-9; ++i)
      f.push_back(i * h);
    return frf::frf_sweep(sub, tip, {tip, mid}, f, kind);
  }
  std::complex<double> H(int response, double freq) const {
    const int r[] = {response}, c[] = {tip};
    return sub.synthesis({tip, mid}, 100.0).receptance(two_pi * freq, r, c)(0, 0);
  }
  // "[frf] files = [...]" with the cantilever's joint.
  static std::string model(const std::string& files, const std::string& extra = "") {
    return "[model]\ndimension = 2\n\n[frf]\nfiles = " + files + "\n" + extra +
           "\n[[joints]]\nname = \"tip\"\nnode = 7\ndof = \"uy\"\n"
           "terms = [\"k\", \"c\", \"k3\"]\nvalues = { k = 4800.0, c = 20.0, k3 = 1.6e8 }\n";
  }
};

} // namespace

TEST(MeasuredFrfFile, EveryKindReadsBackAsTheReceptance) {
  // Receptance, mobility and accelerance written by `jointid frf` (universal file and CSV) read
  // back as the receptance at every line: to rounding (1e-13 of the peak), the mobility's and
  // accelerance's 0 Hz line dropped.
  const Cantilever c;
  for (const frf::FrfKind kind :
       {frf::FrfKind::receptance, frf::FrfKind::mobility, frf::FrfKind::accelerance}) {
    const frf::FrfSweep s = c.sweep(kind, 0.25, 30.0);
    const fs::path uff = c.dir / "h.uff", csv = c.dir / "h.csv";
    io::write_uff58(uff, io::frf_uff58(s, c.sub.dofs()), kind == frf::FrfKind::mobility);
    io::write_file_atomically(csv, io::frf_csv(s, c.sub.dofs()));
    for (const fs::path& path : {uff, csv}) {
      const frf::MeasuredFrf m = io::read_measured_frf({path});
      ASSERT_EQ(m.functions.size(), 2u) << path;
      EXPECT_EQ(m.dofs, (std::vector<fem::NodeDof>{{7, Dof::uy}, {4, Dof::uy}}));
      for (const frf::MeasuredFunction& f : m.functions) {
        EXPECT_EQ(f.drive, (fem::NodeDof{7, Dof::uy}));
        const std::size_t skipped = kind == frf::FrfKind::receptance ? 0 : 1;
        ASSERT_EQ(f.frequencies_hz.size() + skipped, s.freq_hz.size()) << path;
        const int response = c.sub.dofs().equation(f.response);
        double peak = 0.0, worst = 0.0;
        for (std::size_t i = 0; i < f.frequencies_hz.size(); ++i) {
          EXPECT_EQ(f.frequencies_hz[i], s.freq_hz[i + skipped]);
          const std::complex<double> truth = c.H(response, f.frequencies_hz[i]);
          peak = std::max(peak, std::abs(truth));
          worst = std::max(worst, std::abs(f.receptance[i] - truth));
        }
        EXPECT_LE(worst, 1e-13 * peak) << path << " " << frf::frf_kind_name(kind);
      }
    }
  }
}

TEST(MeasuredFrfFile, UnitsAndDirectionsOfAHandCheckedUniversalFile) {
  // One FRF, 3 lines (10, 10.5, 11 Hz), accelerance in g/lbf from +Y at node 2 to −Z at node 5:
  // H = A g_n / lbf × (−1) / (−ω²).
  const test::TempDir dir;
  test::write_text(
      dir / "a.uff",
      "    -1\n    58\nhand\nNONE\nNONE\nNONE\nNONE\n"
      "    4         1    0         0 NONE               5  -3 NONE               2   2\n"
      "         5         3         1  1.00000E+01  5.00000E-01  0.00000E+00\n"
      "        18    0    0    0 Frequency            Hz\n"
      "        12    1    0    0 Acceleration         g\n"
      "        13    0    1    0 Force                lbf\n"
      "         0    0    0    0 NONE                 NONE\n"
      "  1.00000E+00  2.00000E+00  3.00000E+00  0.00000E+00  0.00000E+00 -1.00000E+00\n"
      "    -1\n");
  const frf::MeasuredFrf m = io::read_measured_frf({dir / "a.uff"});
  ASSERT_EQ(m.functions.size(), 1u);
  const frf::MeasuredFunction& f = m.functions[0];
  EXPECT_EQ(f.response, (fem::NodeDof{5, Dof::uz}));
  EXPECT_EQ(f.drive, (fem::NodeDof{2, Dof::uy}));
  const double scale = 9.80665 / 4.4482216152605;
  const std::complex<double> a[] = {{1.0, 2.0}, {3.0, 0.0}, {0.0, -1.0}};
  for (int i = 0; i < 3; ++i) {
    const double freq = 10.0 + 0.5 * i, w = two_pi * freq;
    EXPECT_EQ(f.frequencies_hz[static_cast<std::size_t>(i)], freq);
    const std::complex<double> expected = a[i] * scale * -1.0 / (-w * w);
    EXPECT_NEAR(std::abs(f.receptance[static_cast<std::size_t>(i)] - expected), 0.0,
                1e-15 * std::abs(expected))
        << i;
  }
}

TEST(MeasuredFrfFile, HandWrittenCsvWithDriveAndKindComments) {
  const test::TempDir dir;
  test::write_text(dir / "m.csv", "\xEF\xBB\xBF# from the rig, 2026-11-30\n# drive = 3:uy\n"
                                  "# kind = mobility\nfreq_hz,3:uy.re,3:uy.im\n0,0,0\n"
                                  "2,0.5,0.25\n4,0,1\n");
  const frf::MeasuredFrf m = io::read_measured_frf({dir / "m.csv"});
  ASSERT_EQ(m.functions.size(), 1u);
  const frf::MeasuredFunction& f = m.functions[0];
  ASSERT_EQ(f.frequencies_hz, (std::vector<double>{2.0, 4.0})); // 0 Hz: no receptance from Y
  EXPECT_EQ(f.receptance[0], std::complex<double>(0.5, 0.25) / std::complex<double>(0, two_pi * 2));
  EXPECT_EQ(f.receptance[1], std::complex<double>(0.0, 1.0) / std::complex<double>(0, two_pi * 4));
}

TEST(MeasuredFrfFile, MalformedFilesNameTheFileLineAndWhatWasExpected) {
  const test::TempDir dir;
  const auto csv = [&](const std::string& text) {
    test::write_text(dir / "e.csv", text);
    return error_of([&] { (void)io::read_measured_frf({dir / "e.csv"}); });
  };
  const std::string p = (dir / "e.csv").string();
  EXPECT_EQ(csv("freq_hz,7:uy.re,7:uy.im\n1,0,0\n2,0,0\n"),
            p + ":1: no drive given before the header: add a comment line '# drive = NODE:DOF' "
                "(e.g. '# drive = 7:uy'), as `jointid frf` writes it");
  EXPECT_EQ(csv("# drive = 7:uy\n# drive = 4:uy\nfreq_hz,7:uy.re,7:uy.im\n"),
            p + ":2: the drive is given twice (line 1 and here)");
  EXPECT_EQ(csv("# drive = 7:uy\nfreq_hz,7:uy.re,4:uy.im\n1,0,0\n"),
            p + ":2: columns 2 and 3 ('7:uy.re', '4:uy.im'): expected NODE:DOF.re and "
                "NODE:DOF.im of the same DOF");
  EXPECT_EQ(csv("# drive = 7:uy\nfreq_hz,7:uy.re,7:uy.im\n1,0,0\n2,0\n"),
            p + ":4: expected 3 values (freq_hz and 1 pairs), got 2");
  EXPECT_EQ(csv("# drive = 7:uy\nfreq_hz,7:uy.re,7:uy.im\n1,0,0\n2,nan,0\n"),
            p + ":4: column 2: expected a finite number, got 'nan'");
  EXPECT_EQ(csv("# drive = 7:uy\nfreq_hz,7:uy.re,7:uy.im\n2,0,0\n1,0,0\n"),
            p + ":4: freq_hz 1 is not above the previous row's");
  EXPECT_EQ(csv("# drive = 7:uy\n# kind = inertance\nfreq_hz,7:uy.re,7:uy.im\n"),
            p + ":2: unknown FRF kind 'inertance' (expected receptance, mobility or "
                "accelerance)");
  // Found by fuzz_frf_csv (fuzz/corpus/fuzz_frf_csv/found_ground_drive.csv): a drive at node 0
  // passed the reader and was refused only later, by the substructure's validation.
  EXPECT_EQ(csv("# accelerance from a force at 0:uy: x(t)\nfreq_hz,7:uy.re,7:uy.im\n1,0,0\n"),
            p + ":1: the drive 0:uy has node id 0: expected > 0 (0 means ground)");
  EXPECT_EQ(csv("# drive = 7:uy\nfreq_hz,0:uy.re,0:uy.im\n1,0,0\n"),
            p + ":2: column 2 ('0:uy.re'): node id 0: expected > 0 (0 means ground)");
  EXPECT_EQ(csv("# drive = 7:uy\n# kind = accelerance\nfreq_hz,7:uy.re,7:uy.im\n1e-300,1,0\n"),
            p + ":4: columns 2 and 3: 1 0 at 1e-300 Hz is not a finite receptance (H = A / −ω²)");
  // A universal file's time response is a test record, not an FRF: the message says so, naming
  // the dataset by its position, line and ID line 1 (the channel, as jointid writes it).
  const Cantilever c;
  identify::Record r;
  r.t = Eigen::VectorXd::LinSpaced(8, 0.0, 0.7);
  r.channels.push_back({identify::Quantity::force, {7, Dof::uy}, Eigen::VectorXd::Ones(8)});
  io::write_uff58(dir / "t.uff", io::uff58_from_record(r));
  EXPECT_EQ(error_of([&] { (void)io::read_measured_frf({dir / "t.uff"}); }),
            (dir / "t.uff").string() +
                ": dataset 1 (line 1), ID line 1 \"f@7:uy\": record 6 field 1 (function type) is 1 "
                "(time response): the substructure's FRFs are frequency response functions (4); a "
                "time response is a test record (give it to identify, discover or modal-fit)");
  // The same FRF in two files.
  const frf::FrfSweep s = c.sweep(frf::FrfKind::receptance, 0.5, 5.0);
  io::write_file_atomically(dir / "a.csv", io::frf_csv(s, c.sub.dofs()));
  io::write_uff58(dir / "a.uff", io::frf_uff58(s, c.sub.dofs()));
  EXPECT_EQ(error_of([&] {
              (void)io::read_measured_frf({dir / "a.csv", dir / "a.uff"});
            }),
            (dir / "a.uff").string() +
                ": dataset 1 (line 1): the FRF 7:uy/7:uy (response/drive) "
                "is also in " +
                (dir / "a.csv").string());
}

TEST(MeasuredFrfFile, ModelFileErrorsNameTheCulprit) {
  const Cantilever c;
  io::write_uff58(c.dir / "h.uff",
                  io::frf_uff58(c.sweep(frf::FrfKind::receptance, 0.5, 5.0), c.sub.dofs()));
  const auto model = [&](const std::string& text) {
    test::write_text(c.dir / "m.toml", text);
    return error_of([&] { (void)io::read_model(c.dir / "m.toml"); });
  };
  const std::string m = (c.dir / "m.toml").string();
  EXPECT_EQ(model(Cantilever::model("[\"h.uff\"]")), "(no error)");
  EXPECT_EQ(model(Cantilever::model("[\"h.uff\"]", "\n[damping]\nmodal = 0.01\n")),
            m + ":7: key 'damping': not used with [frf]: the substructure is given by measured "
                "FRFs");
  EXPECT_EQ(model("[modal]\ndofs = [\"7:uy\"]\nfrequencies_hz = [3.0]\ndamping = [0.01]\n"
                  "shapes = [[1.0]]\n\n" +
                  Cantilever::model("[\"h.uff\"]").substr(23)),
            m + ":7: [frf]: give the substructure one way only: by its modes ([modal]), its "
                "matrices ([matrices]), measured FRFs ([frf]) or as several ([[substructures]]); "
                "this file has [modal] and [frf]");
  std::string on_5 = Cantilever::model("[\"h.uff\"]");
  on_5.replace(on_5.find("node = 7"), 8, "node = 5");
  EXPECT_EQ(model(on_5),
            m + ":9: [[joints]] 'tip': key 'node': node 5 has no measured FRF in [frf]");
  EXPECT_EQ(model(Cantilever::model("[\"none.uff\"]")),
            (c.dir / "none.uff").string() + ": cannot open for reading: No such file or directory");
}

TEST(MeasuredFrfFile, IdentificationThroughMeasuredFrfsMatchesTheFiniteElements) {
  // Sine tests simulated on the finite element model (harmonic balance), identified through the
  // model file and through its FRFs written by `jointid frf` (universal file, 0.01 Hz lines up
  // to 70 Hz). At test frequencies on the lines (harmonics 1 and 3 too) H is the measured value
  // itself and the two routes agree to rounding (1e-9). Between lines H is interpolated: the
  // parameters then differ by the interpolation error (measured: 2.1e-6 at most): within 2e-5.
  const Cantilever c;
  io::write_uff58(c.dir / "h.uff",
                  io::frf_uff58(c.sweep(frf::FrfKind::receptance, 0.01, 70.0), c.sub.dofs()));
  test::write_text(c.dir / "m.toml", Cantilever::model("\"h.uff\""));
  const io::ModelFile measured = io::read_model(c.dir / "m.toml");
  ASSERT_TRUE(measured.measured.has_value());
  const frf::Substructure b = measured.substructure();
  for (const double offset : {0.0, 0.0037}) {
    std::vector<identify::SineTestPlan> plans;
    for (double f : {15.0, 17.0, 19.0, 21.0})
      plans.push_back({f + offset, 40.0});
    identify::SimulationOptions so;
    so.method = identify::SimulationMethod::harmonic_balance;
    so.periods = 2;
    so.steps_per_period = 256;
    std::vector<identify::Measurement> tests;
    for (const auto& t : identify::simulate_sine_tests(c.sub, c.fe.joints, {7, Dof::uy}, plans, so))
      tests.push_back(identify::measure(t.record, {.harmonics = 3}));
    std::vector<joints::Joint> start = c.fe.joints;
    start[0].fixed.assign(start[0].terms.size(), false);
    const identify::FitResult fa = identify::fit(c.sub, start, tests, {.harmonics = {1, 3}});
    const identify::FitResult fb = identify::fit(b, start, tests, {.harmonics = {1, 3}});
    const double tolerance = offset == 0.0 ? 1e-9 : 2e-5;
    for (std::size_t t = 0; t < fa.joints[0].terms.size(); ++t) {
      const double va = fa.joints[0].terms[t].value, vb = fb.joints[0].terms[t].value;
      EXPECT_NEAR(vb, va, tolerance * std::abs(va)) << t << " offset " << offset;
      std::printf("offset %.4f Hz, term %zu: FE %.10g, measured FRFs %.10g (relative %.2g)\n",
                  offset, t, va, vb, std::abs(vb - va) / std::abs(va));
    }
  }
}
