#include "io/frf_output.hpp"

#include "io/files.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace jointid::io {

std::string frf_unit(frf::FrfKind kind, bool response_rotation, bool drive_rotation) {
  const std::string motion = response_rotation ? "rad" : "m";
  const std::string numerator = kind == frf::FrfKind::receptance ? motion
                                : kind == frf::FrfKind::mobility ? "(" + motion + "/s)"
                                                                 : "(" + motion + "/s^2)";
  return numerator + (drive_rotation ? "/(N m)" : "/N");
}

std::string frf_csv(const frf::FrfSweep& sweep, const fem::DofMap& dofs) {
  const fem::NodeDof drive = dofs.node_dof(sweep.drive);
  std::string out = fmt::format(
      "# {} from a {} at {}: x(t) = Re(H F e^(i w t)), mobility i w H, accelerance -w^2 H (SI)\n",
      frf::frf_kind_name(sweep.kind), fem::is_rotation(drive.dof) ? "moment" : "force",
      fem::to_string(drive));
  for (int r : sweep.responses) {
    const fem::NodeDof at = dofs.node_dof(r);
    out += fmt::format("# {}: {}\n", fem::to_string(at),
                       frf_unit(sweep.kind, fem::is_rotation(at.dof), fem::is_rotation(drive.dof)));
  }
  for (const std::string& note : sweep.notes)
    out += "# note: " + note + "\n";
  out += "freq_hz";
  for (int r : sweep.responses) {
    const std::string name = fem::to_string(dofs.node_dof(r));
    out += "," + name + ".re," + name + ".im";
  }
  out += "\n";
  for (std::size_t i = 0; i < sweep.freq_hz.size(); ++i) {
    out += fmt::format("{}", sweep.freq_hz[i]);
    for (Eigen::Index c = 0; c < sweep.values.cols(); ++c) {
      const std::complex<double> h = sweep.values(static_cast<Eigen::Index>(i), c);
      out += fmt::format(",{},{}", h.real(), h.imag());
    }
    out += "\n";
  }
  return out;
}

std::vector<Uff58Function> frf_uff58(const frf::FrfSweep& sweep, const fem::DofMap& dofs) {
  const std::size_t n = sweep.freq_hz.size();
  if (n < 2)
    throw Error(fmt::format("FRF as dataset 58: {} frequenc{}, expected at least 2", n,
                            n == 1 ? "y" : "ies"));
  const double step = (sweep.freq_hz.back() - sweep.freq_hz.front()) / static_cast<double>(n - 1);
  if (!(step > 0.0))
    throw Error("FRF as dataset 58: the frequencies must increase (evenly spaced)");
  for (std::size_t i = 1; i < n; ++i)
    if (std::abs(sweep.freq_hz[i] - sweep.freq_hz[i - 1] - step) > 1e-9 * step)
      throw Error(fmt::format("FRF as dataset 58: the step {} Hz at frequency {} differs from the "
                              "mean step {} Hz: dataset 58 is written evenly spaced",
                              sweep.freq_hz[i] - sweep.freq_hz[i - 1], i + 1, step));
  const fem::NodeDof drive = dofs.node_dof(sweep.drive);
  const identify::Quantity quantity =
      sweep.kind == frf::FrfKind::receptance ? identify::Quantity::displacement
      : sweep.kind == frf::FrfKind::mobility ? identify::Quantity::velocity
                                             : identify::Quantity::acceleration;
  std::vector<Uff58Function> functions;
  for (std::size_t c = 0; c < sweep.responses.size(); ++c) {
    const fem::NodeDof at = dofs.node_dof(sweep.responses[c]);
    Uff58Function f;
    f.id_lines[0] = fmt::format("{} {}/{}", frf::frf_kind_name(sweep.kind), fem::to_string(at),
                                fem::to_string(drive));
    f.id_lines[1] = "jointid frf: modal synthesis of the linear substructure";
    f.function_type = uff_function_type::frequency_response;
    f.function_id = static_cast<int>(c + 1);
    f.response_node = at.node;
    f.response_direction = static_cast<int>(at.dof) + 1;
    f.reference_node = drive.node;
    f.reference_direction = static_cast<int>(drive.dof) + 1;
    f.ordinate_type = 6;
    f.even = true;
    f.abscissa_min = sweep.freq_hz.front();
    f.abscissa_increment = step;
    f.abscissa = {uff_data_type::frequency, 0, 0, 0, "Frequency", "Hz"};
    f.ordinate = uff58_axis(quantity, fem::is_rotation(at.dof));
    f.denominator = uff58_axis(identify::Quantity::force, fem::is_rotation(drive.dof));
    f.complex_data = sweep.values.col(static_cast<Eigen::Index>(c));
    functions.push_back(std::move(f));
  }
  return functions;
}

} // namespace jointid::io
