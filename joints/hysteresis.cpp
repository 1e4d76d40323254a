#include "joints/hysteresis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jointid::joints {

namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// The smallest cut of the iwan's quadrature grid, relative to φ_max.
constexpr double smallest_cut = 1e-4;

} // namespace

double Sliders::stiffness_sum() const {
  double sum = 0.0;
  for (double k : stiffness)
    sum += k;
  return sum;
}

double Sliders::slip_force_sum() const {
  double sum = 0.0;
  for (std::size_t i = 0; i < stiffness.size(); ++i)
    sum += stiffness[i] * reach[i];
  return sum;
}

void Sliders::append(const Sliders& other) {
  stiffness.insert(stiffness.end(), other.stiffness.begin(), other.stiffness.end());
  reach.insert(reach.end(), other.reach.begin(), other.reach.end());
}

IwanDensity iwan_density(double fs, double kt, double chi, double beta) {
  if (!(fs > 0.0) || !std::isfinite(fs))
    throw std::invalid_argument("iwan: fs must be > 0 N, got " + number(fs));
  if (!(kt > 0.0) || !std::isfinite(kt))
    throw std::invalid_argument("iwan: kt must be > 0 N/m, got " + number(kt));
  if (!(chi > -1.0 && chi <= 0.0))
    throw std::invalid_argument("iwan: chi must be in (-1, 0], got " + number(chi));
  if (!(beta >= 0.0) || !std::isfinite(beta))
    throw std::invalid_argument("iwan: beta must be >= 0, got " + number(beta));
  const double shape = beta + (chi + 1.0) / (chi + 2.0);
  IwanDensity d;
  d.chi = chi;
  d.phi_max = fs * (1.0 + beta) / (kt * shape);
  d.R = fs * (chi + 1.0) / (std::pow(d.phi_max, chi + 2.0) * shape);
  d.S = beta * fs / (d.phi_max * shape);
  return d;
}

Sliders jenkins_sliders(double kt, double fs) {
  if (!(kt > 0.0) || !std::isfinite(kt))
    throw std::invalid_argument("jenkins: kt must be > 0 N/m, got " + number(kt));
  if (!(fs > 0.0) || !std::isfinite(fs))
    throw std::invalid_argument("jenkins: fs must be > 0 N, got " + number(fs));
  return Sliders{{kt}, {fs / kt}};
}

Sliders iwan_sliders(double fs, double kt, double chi, double beta, int sliders) {
  const IwanDensity d = iwan_density(fs, kt, chi, beta);
  const bool dirac = d.S > 0.0;
  const int M = sliders - (dirac ? 1 : 0); // elements of the continuous part
  if (M < 1 || sliders < 2)
    throw std::invalid_argument("iwan: at least 2 sliders, got " + std::to_string(sliders));
  // ∫ R φ^χ and ∫ R φ^{χ+1} from 0 to φ, in φ_max units to keep the powers tame.
  const double p1 = d.chi + 1.0, p2 = d.chi + 2.0;
  const double mass_scale = d.R * std::pow(d.phi_max, p1),
               moment_scale = d.R * std::pow(d.phi_max, p2);
  auto mass = [&](double u) { return u > 0.0 ? mass_scale * std::pow(u, p1) / p1 : 0.0; };
  auto moment = [&](double u) { return u > 0.0 ? moment_scale * std::pow(u, p2) / p2 : 0.0; };
  Sliders s;
  double below = 0.0; // the cut before, relative to φ_max
  const double ratio = M > 1 ? std::pow(1.0 / smallest_cut, 1.0 / (M - 1)) : 1.0;
  for (int i = 1; i <= M; ++i) {
    const double cut = i == M ? 1.0 : std::pow(ratio, i - M);
    const double w = mass(cut) - mass(below);
    const double first = moment(cut) - moment(below);
    s.stiffness.push_back(w);
    s.reach.push_back(first / w);
    below = cut;
  }
  if (dirac) {
    s.stiffness.push_back(d.S);
    s.reach.push_back(d.phi_max);
  }
  return s;
}

double iwan_dissipation(const IwanDensity& d, double a) {
  if (!(a >= 0.0) || a > d.phi_max * (1.0 + 1e-12))
    throw std::invalid_argument("iwan_dissipation: the amplitude must be in [0, phi_max]");
  return 4.0 * d.R * std::pow(a, d.chi + 3.0) / ((d.chi + 2.0) * (d.chi + 3.0));
}

double slide(const Sliders& s, std::span<double> x, double y, double* tangent) {
  double force = 0.0, stuck = 0.0;
  const std::size_t n = s.stiffness.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double phi = s.reach[i], d = y - x[i];
    if (d > phi)
      x[i] = y - phi;
    else if (d < -phi)
      x[i] = y + phi;
    else
      stuck += s.stiffness[i];
    force += s.stiffness[i] * (y - x[i]);
  }
  if (tangent) *tangent = stuck;
  return force;
}

double slide_trial(const Sliders& s, std::span<const double> x, double y, double* tangent) {
  double force = 0.0, stuck = 0.0;
  const std::size_t n = s.stiffness.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double phi = s.reach[i], d = y - x[i];
    if (d > phi) {
      force += s.stiffness[i] * phi;
    } else if (d < -phi) {
      force -= s.stiffness[i] * phi;
    } else {
      stuck += s.stiffness[i];
      force += s.stiffness[i] * d;
    }
  }
  if (tangent) *tangent = stuck;
  return force;
}

bool steady_loop(const Sliders& s, std::span<const double> y, bool antisymmetric,
                 std::span<double> g, std::vector<LoopEntry>* derivative, LoopWork& w,
                 int max_passes) {
  const int N = static_cast<int>(y.size());
  if (g.size() != y.size())
    throw std::invalid_argument("steady_loop: the force and deformation samples differ in number");
  const int full = antisymmetric ? 2 * N : N;
  const std::size_t n = s.stiffness.size();
  w.x.assign(n, 0.0);
  w.anchor.assign(n, -1);
  auto value = [&](int i) {
    return i < N ? y[static_cast<std::size_t>(i)] : -y[static_cast<std::size_t>(i - N)];
  };
  bool closed = false;
  for (int pass = 0; pass < std::max(1, max_passes) && !closed; ++pass) {
    w.x_start = w.x;
    if (derivative) derivative->clear();
    for (int t = 0; t < full; ++t) {
      const double yt = value(t);
      double force = 0.0, stuck = 0.0;
      const bool kept = t < N; // a sample whose force is written
      w.groups.clear();
      for (std::size_t i = 0; i < n; ++i) {
        const double phi = s.reach[i], d = yt - w.x[i], k = s.stiffness[i];
        if (d > phi) {
          w.x[i] = yt - phi, w.anchor[i] = t;
        } else if (d < -phi) {
          w.x[i] = yt + phi, w.anchor[i] = t;
        } else {
          stuck += k;
          const int a = w.anchor[i];
          if (derivative && kept && a >= 0) {
            // ∂g_t/∂y_a = −k where a is the sample of the element's last slide
            auto it = std::find_if(w.groups.begin(), w.groups.end(),
                                   [a](const LoopEntry& e) { return e.m == a; });
            if (it == w.groups.end())
              w.groups.push_back({t, a, -k});
            else
              it->value -= k;
          }
        }
        force += k * (yt - w.x[i]);
      }
      if (!kept) continue;
      g[static_cast<std::size_t>(t)] = force;
      if (!derivative) continue;
      if (stuck != 0.0) derivative->push_back({t, t, stuck});
      for (const LoopEntry& e : w.groups) // a sample of the second half is −y of the first
        derivative->push_back(e.m < N ? e : LoopEntry{t, e.m - N, -e.value});
    }
    closed = w.x == w.x_start;
  }
  return closed;
}

double gap_force(double delta, double kg, double y, double* slope) {
  if (y > delta) {
    if (slope) *slope = kg;
    return kg * (y - delta);
  }
  if (y < -delta) {
    if (slope) *slope = kg;
    return kg * (y + delta);
  }
  if (slope) *slope = 0.0;
  return 0.0;
}

} // namespace jointid::joints
