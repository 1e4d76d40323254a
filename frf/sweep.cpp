#include "frf/sweep.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>

namespace jointid::frf {

namespace {

constexpr std::array<std::pair<FrfKind, std::string_view>, 3> kinds{
    {{FrfKind::receptance, "receptance"},
     {FrfKind::mobility, "mobility"},
     {FrfKind::accelerance, "accelerance"}}};

} // namespace

std::string_view frf_kind_name(FrfKind kind) {
  for (const auto& [k, name] : kinds)
    if (k == kind) return name;
  throw std::logic_error("frf_kind_name: unknown kind");
}

FrfKind parse_frf_kind(std::string_view name) {
  for (const auto& [k, n] : kinds)
    if (n == name) return k;
  throw std::invalid_argument("unknown FRF kind '" + std::string(name) +
                              "' (expected receptance, mobility or accelerance)");
}

FrfSweep frf_sweep(const Substructure& sub, int drive, std::vector<int> responses,
                   std::vector<double> freq_hz, FrfKind kind) {
  if (responses.empty()) throw std::invalid_argument("FRF: no response DOF");
  if (std::set<int>(responses.begin(), responses.end()).size() != responses.size())
    throw std::invalid_argument("FRF: a response DOF is listed twice");
  if (freq_hz.empty()) throw std::invalid_argument("FRF: no frequency");
  for (double f : freq_hz)
    if (!(std::isfinite(f) && f >= 0.0))
      throw std::invalid_argument("FRF: frequencies must be finite and >= 0 Hz, got " +
                                  std::to_string(f));
  std::vector<int> dofs = responses;
  if (std::find(dofs.begin(), dofs.end(), drive) == dofs.end()) dofs.push_back(drive);
  const double f_max = *std::max_element(freq_hz.begin(), freq_hz.end());
  FrfSweep out;
  out.kind = kind;
  out.drive = drive;
  // synthesis() checks the equations; its band covers harmonic 1 up to f_max.
  const ModalSynthesis H =
      sub.synthesis(dofs, synthesis_band_hz(std::max(f_max, 1e-3), 1), &out.notes);
  if (!H.status().ok()) {
    out.status = H.status();
    return out;
  }
  out.values.resize(static_cast<Eigen::Index>(freq_hz.size()),
                    static_cast<Eigen::Index>(responses.size()));
  const std::array<int, 1> column{drive};
  for (std::size_t i = 0; i < freq_hz.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * freq_hz[i];
    const std::complex<double> factor = kind == FrfKind::receptance ? 1.0
                                        : kind == FrfKind::mobility
                                            ? std::complex<double>(0.0, w)
                                            : std::complex<double>(-w * w, 0.0);
    const CMatrix column_values = H.receptance(w, responses, column);
    out.values.row(static_cast<Eigen::Index>(i)) = factor * column_values.col(0).transpose();
  }
  out.responses = std::move(responses);
  out.freq_hz = std::move(freq_hz);
  return out;
}

std::vector<double> evenly_spaced_hz(double f0_hz, double f1_hz, int points) {
  if (points < 2 || !std::isfinite(f0_hz) || !std::isfinite(f1_hz))
    throw std::invalid_argument(fmt::format(
        "frequencies: expected at least 2 points between finite ends, got {} from {} to {} Hz",
        points, f0_hz, f1_hz));
  std::vector<double> freq(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i)
    freq[static_cast<std::size_t>(i)] =
        i + 1 == points ? f1_hz : f0_hz + (f1_hz - f0_hz) * i / (points - 1.0);
  return freq;
}

} // namespace jointid::frf
