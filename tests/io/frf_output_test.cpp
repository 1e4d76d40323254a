// FRFs as `jointid frf` writes them: the universal file read back by jointid's own reader (a
// round trip of every field), the CSV table, the units.
#include "io/frf_output.hpp"

#include "io/files.hpp"
#include "io/test_files.hpp"
#include "support/beam_models.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

using namespace jointid;
using fem::Dof;

namespace {

frf::FrfSweep cantilever_sweep(frf::FrfKind kind, std::vector<double> freq,
                               const frf::Substructure& sub) {
  return frf::frf_sweep(sub, sub.dofs().equation({5, Dof::uy}),
                        {sub.dofs().equation({5, Dof::uy}), sub.dofs().equation({3, Dof::rz})},
                        std::move(freq), kind);
}

TEST(FrfOutput, UniversalFileReadsBackEveryField) {
  fem::Model model = test::cantilever(4, {});
  model.damping.kind = fem::Damping::Kind::modal;
  model.damping.modal_ratio = 0.01;
  const frf::Substructure sub(model);
  const frf::FrfSweep s =
      cantilever_sweep(frf::FrfKind::accelerance, {1.0, 1.5, 2.0, 2.5, 3.0}, sub);
  const test::TempDir dir;
  const auto path = dir.path() / "frf.uff";
  io::write_uff58(path, io::frf_uff58(s, sub.dofs()));
  const std::vector<io::Uff58Function> back = io::read_uff58(path);
  ASSERT_EQ(back.size(), 2u);
  for (int c = 0; c < 2; ++c) {
    const io::Uff58Function& f = back[static_cast<std::size_t>(c)];
    EXPECT_EQ(f.function_type, io::uff_function_type::frequency_response);
    EXPECT_EQ(f.ordinate_type, 6);
    EXPECT_EQ(f.reference_node, 5);
    EXPECT_EQ(f.reference_direction, 2); // +Y
    EXPECT_EQ(f.abscissa.data_type, io::uff_data_type::frequency);
    EXPECT_DOUBLE_EQ(f.abscissa_min, 1.0);
    EXPECT_DOUBLE_EQ(f.abscissa_increment, 0.5);
    EXPECT_EQ(f.ordinate.data_type, io::uff_data_type::acceleration);
    EXPECT_EQ(f.denominator.data_type, io::uff_data_type::excitation_force);
    EXPECT_EQ(f.denominator.force_exponent, 1);
    ASSERT_EQ(f.complex_data.size(), 5);
    EXPECT_EQ(f.complex_data, s.values.col(c)) << "double precision reads back exactly";
  }
  EXPECT_EQ(back[0].response_node, 5);
  EXPECT_EQ(back[0].response_direction, 2);
  EXPECT_EQ(back[0].ordinate.length_exponent, 1);
  EXPECT_EQ(back[0].ordinate.units_label, "m/s^2");
  EXPECT_EQ(back[1].response_node, 3);
  EXPECT_EQ(back[1].response_direction, 6); // +RZ
  EXPECT_EQ(back[1].ordinate.length_exponent, 0);
  EXPECT_EQ(back[1].ordinate.units_label, "rad/s^2");
  EXPECT_NE(back[1].id_lines[0].find("accelerance 3:rz/5:uy"), std::string::npos);
}

TEST(FrfOutput, UnevenFrequenciesAreRefusedForTheUniversalFile) {
  const frf::Substructure sub(test::cantilever(4, {}));
  const frf::FrfSweep s = cantilever_sweep(frf::FrfKind::receptance, {1.0, 2.0, 4.0}, sub);
  try {
    io::frf_uff58(s, sub.dofs());
    FAIL() << "no error";
  } catch (const io::Error& e) {
    EXPECT_NE(std::string(e.what()).find("evenly spaced"), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::frf_uff58(cantilever_sweep(frf::FrfKind::receptance, {1.0}, sub), sub.dofs()),
               io::Error);
}

TEST(FrfOutput, CsvHasUnitsAHeaderAndExactNumbers) {
  const frf::Substructure sub(test::cantilever(4, {}));
  const frf::FrfSweep s = cantilever_sweep(frf::FrfKind::mobility, {0.0, 10.0}, sub);
  const std::string csv = io::frf_csv(s, sub.dofs());
  EXPECT_NE(csv.find("# mobility from a force at 5:uy"), std::string::npos) << csv;
  EXPECT_NE(csv.find("# 5:uy: (m/s)/N\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("# 3:rz: (rad/s)/N\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nfreq_hz,5:uy.re,5:uy.im,3:rz.re,3:rz.im\n"), std::string::npos) << csv;
  // The last row: 10 Hz, values that read back as the same doubles.
  std::istringstream rows(csv.substr(csv.rfind("\n10,") + 1));
  std::string cell;
  std::vector<double> values;
  while (std::getline(rows, cell, ','))
    values.push_back(std::stod(cell));
  ASSERT_EQ(values.size(), 5u);
  EXPECT_EQ(values[1], s.values(1, 0).real());
  EXPECT_EQ(values[4], s.values(1, 1).imag());
  EXPECT_EQ(io::frf_unit(frf::FrfKind::receptance, true, true), "rad/(N m)");
  EXPECT_EQ(io::frf_unit(frf::FrfKind::accelerance, false, false), "(m/s^2)/N");
}

} // namespace
