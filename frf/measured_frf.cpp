#include "frf/measured_frf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

namespace {

using Complex = std::complex<double>;

std::string name_of(const MeasuredFunction& f) {
  return fmt::format("FRF {}/{}{}", fem::to_string(f.response), fem::to_string(f.drive),
                     f.source.empty() ? "" : " (" + f.source + ")");
}

// Lagrange interpolation through the lines first … first + count − 1 at freq.
Complex lagrange(const MeasuredFunction& f, std::size_t first, std::size_t count, double freq,
                 std::size_t skip = static_cast<std::size_t>(-1)) {
  Complex sum = 0.0;
  for (std::size_t i = first; i < first + count; ++i) {
    if (i == skip) continue;
    double weight = 1.0;
    for (std::size_t j = first; j < first + count; ++j)
      if (j != i && j != skip)
        weight *= (freq - f.frequencies_hz[j]) / (f.frequencies_hz[i] - f.frequencies_hz[j]);
    sum += weight * f.receptance[i];
  }
  return sum;
}

} // namespace

void MeasuredFrf::validate() const {
  if (dofs.empty()) throw std::invalid_argument("measured FRFs: no DOFs");
  if (functions.empty()) throw std::invalid_argument("measured FRFs: no functions");
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    if (dofs[i].node <= 0)
      throw std::invalid_argument(
          fmt::format("measured FRFs: DOF {} has node id {} (expected > 0; 0 means ground)", i + 1,
                      dofs[i].node));
    for (std::size_t k = 0; k < i; ++k)
      if (dofs[k] == dofs[i])
        throw std::invalid_argument(
            fmt::format("measured FRFs: DOF {} is listed twice", fem::to_string(dofs[i])));
  }
  for (std::size_t n = 0; n < functions.size(); ++n) {
    const MeasuredFunction& f = functions[n];
    const std::string name = name_of(f);
    for (const fem::NodeDof& at : {f.response, f.drive})
      if (std::find(dofs.begin(), dofs.end(), at) == dofs.end())
        throw std::invalid_argument(
            fmt::format("{}: {} is not among the substructure's DOFs", name, fem::to_string(at)));
    if (f.frequencies_hz.size() != f.receptance.size())
      throw std::invalid_argument(fmt::format("{}: {} frequencies but {} values", name,
                                              f.frequencies_hz.size(), f.receptance.size()));
    if (f.frequencies_hz.size() < 2)
      throw std::invalid_argument(
          fmt::format("{}: {} line(s); an FRF needs at least 2 to be interpolated", name,
                      f.frequencies_hz.size()));
    for (std::size_t i = 0; i < f.frequencies_hz.size(); ++i) {
      const double fi = f.frequencies_hz[i];
      if (!std::isfinite(fi) || fi < 0.0)
        throw std::invalid_argument(
            fmt::format("{}: line {} is at {} Hz (expected finite and >= 0)", name, i + 1, fi));
      if (i > 0 && !(fi > f.frequencies_hz[i - 1]))
        throw std::invalid_argument(
            fmt::format("{}: line {} ({} Hz) is not above line {} ({} Hz): the frequencies must "
                        "increase",
                        name, i + 1, fi, i, f.frequencies_hz[i - 1]));
      if (!std::isfinite(f.receptance[i].real()) || !std::isfinite(f.receptance[i].imag()))
        throw std::invalid_argument(
            fmt::format("{}: the value at line {} ({} Hz) is not finite", name, i + 1, fi));
    }
    for (std::size_t k = 0; k < n; ++k)
      if (functions[k].response == f.response && functions[k].drive == f.drive)
        throw std::invalid_argument(
            fmt::format("{}: the same response and drive as {}", name, name_of(functions[k])));
  }
}

MeasuredReceptance::MeasuredReceptance(MeasuredFrf frf) : frf_(std::move(frf)) {
  frf_.validate();
  const std::size_t n = frf_.dofs.size();
  index_.assign(n * n, -1);
  const auto position = [&](const fem::NodeDof& at) {
    return static_cast<std::size_t>(std::find(frf_.dofs.begin(), frf_.dofs.end(), at) -
                                    frf_.dofs.begin());
  };
  for (std::size_t k = 0; k < frf_.functions.size(); ++k)
    index_[position(frf_.functions[k].response) * n + position(frf_.functions[k].drive)] =
        static_cast<int>(k);
}

int MeasuredReceptance::function_for(int row, int col) const {
  const std::size_t n = frf_.dofs.size();
  const int direct = index_[static_cast<std::size_t>(row) * n + static_cast<std::size_t>(col)];
  return direct >= 0 ? direct
                     : index_[static_cast<std::size_t>(col) * n + static_cast<std::size_t>(row)];
}

Complex MeasuredReceptance::value(const MeasuredFunction& f, double freq) const {
  const std::vector<double>& x = f.frequencies_hz;
  const std::size_t n = x.size();
  const double spacing_tol = 1e-9 * (x.back() - x.front()) / static_cast<double>(n - 1);
  if (freq == 0.0 && x.front() > 0.0) return f.receptance.front(); // quasi-static
  if (freq < x.front() - spacing_tol || freq > x.back() + spacing_tol)
    throw std::invalid_argument(fmt::format(
        "{}: {:.6g} Hz is outside the measured band {:.6g}–{:.6g} Hz: measure a wider band, or "
        "ask for fewer harmonics or other test frequencies",
        name_of(f), freq, x.front(), x.back()));
  // The interval [x[k], x[k+1]] holding freq.
  std::size_t k = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), freq) - x.begin());
  k = k == 0 ? 0 : std::min(k - 1, n - 2);
  const double h = x[k + 1] - x[k];
  if (std::abs(freq - x[k]) <= 1e-9 * h) return f.receptance[k];
  if (std::abs(freq - x[k + 1]) <= 1e-9 * h) return f.receptance[k + 1];
  const std::size_t count = std::min<std::size_t>(4, n);
  std::size_t first = k == 0 ? 0 : k - 1;
  first = std::min(first, n - count);
  return lagrange(f, first, count, freq);
}

Eigen::MatrixXcd MeasuredReceptance::receptance(double omega, std::span<const int> rows,
                                                std::span<const int> cols) const {
  const int n = static_cast<int>(frf_.dofs.size());
  const double freq = omega / (2.0 * std::numbers::pi);
  Eigen::MatrixXcd H(static_cast<Eigen::Index>(rows.size()),
                     static_cast<Eigen::Index>(cols.size()));
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j) {
      const int r = rows[i], c = cols[j];
      if (r < 0 || r >= n || c < 0 || c >= n)
        throw std::invalid_argument(
            fmt::format("measured FRFs: equation {} is outside the substructure ({} DOFs)",
                        r < 0 || r >= n ? r : c, n));
      const int k = function_for(r, c);
      if (k < 0)
        throw std::invalid_argument(fmt::format(
            "measured FRFs: neither the FRF from {} to {} nor the one from {} to {} was "
            "measured (drive to response), and the analysis needs it: add one of them",
            fem::to_string(frf_.dofs[static_cast<std::size_t>(c)]),
            fem::to_string(frf_.dofs[static_cast<std::size_t>(r)]),
            fem::to_string(frf_.dofs[static_cast<std::size_t>(r)]),
            fem::to_string(frf_.dofs[static_cast<std::size_t>(c)])));
      H(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
          value(frf_.functions[static_cast<std::size_t>(k)], freq);
    }
  return H;
}

namespace {

bool among(const MeasuredFrf& frf, std::span<const int> equations, const fem::NodeDof& at) {
  for (int e : equations)
    if (e >= 0 && e < static_cast<int>(frf.dofs.size()) &&
        frf.dofs[static_cast<std::size_t>(e)] == at)
      return true;
  return false;
}

} // namespace

double MeasuredReceptance::band_top_hz(std::span<const int> equations) const {
  double top = std::numeric_limits<double>::infinity();
  for (const MeasuredFunction& f : frf_.functions)
    if (among(frf_, equations, f.response) && among(frf_, equations, f.drive))
      top = std::min(top, f.frequencies_hz.back());
  return top;
}

double MeasuredReceptance::interpolation_error(std::span<const int> equations,
                                               std::string* where) const {
  double worst = 0.0;
  for (const MeasuredFunction& f : frf_.functions) {
    if (!among(frf_, equations, f.response) || !among(frf_, equations, f.drive)) continue;
    const std::size_t n = f.frequencies_hz.size();
    if (n < 5) continue;
    double peak = 0.0;
    for (const Complex& v : f.receptance)
      peak = std::max(peak, std::abs(v));
    if (!(peak > 0.0)) continue;
    for (std::size_t i = 2; i + 2 < n; ++i) {
      // The cubic through i−2, i−1, i+1, i+2 (without line i) at line i errs by h⁴ H⁗ 4/24; the
      // cubic through four lines errs mid-interval by h⁴ H⁗ (9/16)/24: 64/9 times less.
      const double e = std::abs(lagrange(f, i - 2, 5, f.frequencies_hz[i], i) - f.receptance[i]) *
                       (9.0 / 64.0) / peak;
      if (e > worst) {
        worst = e;
        if (where) *where = fmt::format("{} near {:.6g} Hz", name_of(f), f.frequencies_hz[i]);
      }
    }
  }
  return worst;
}

} // namespace jointid::frf
