#include "joints/hysteresis.hpp"

#include "fem/text.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace jointid::joints {

namespace {

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
    throw std::invalid_argument("iwan: fs must be > 0 N, got " + significant(fs));
  if (!(kt > 0.0) || !std::isfinite(kt))
    throw std::invalid_argument("iwan: kt must be > 0 N/m, got " + significant(kt));
  if (!(chi > -1.0 && chi <= 0.0))
    throw std::invalid_argument("iwan: chi must be in (-1, 0], got " + significant(chi));
  if (!(beta >= 0.0) || !std::isfinite(beta))
    throw std::invalid_argument("iwan: beta must be >= 0, got " + significant(beta));
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
    throw std::invalid_argument("jenkins: kt must be > 0 N/m, got " + significant(kt));
  if (!(fs > 0.0) || !std::isfinite(fs))
    throw std::invalid_argument("jenkins: fs must be > 0 N, got " + significant(fs));
  return Sliders{{kt}, {fs / kt}};
}

Sliders iwan_sliders(double fs, double kt, double chi, double beta, int sliders) {
  const IwanDensity d = iwan_density(fs, kt, chi, beta);
  const bool dirac = d.S > 0.0;
  const int M = sliders - (dirac ? 1 : 0); // elements of the continuous part
  if (M < 1 || sliders < 2)
    throw std::invalid_argument("iwan: at least 2 sliders, got " + std::to_string(sliders));
  // ∫ R φ^χ and ∫ R φ^{χ+1} from 0 to φ, in φ_max units to keep the powers tame. On the
  // geometric grid u_i = r^{i−M} the powers are geometric too, u_i^p = (r^p)^{i−M}: three
  // powers for the whole grid instead of three per element (this runs for every evaluation of
  // a describing function and every joint law built).
  const double p1 = d.chi + 1.0, p2 = d.chi + 2.0;
  const double mass_scale = d.R * std::pow(d.phi_max, p1) / p1,
               moment_scale = d.R * std::pow(d.phi_max, p2) / p2;
  const double ratio = M > 1 ? std::pow(1.0 / smallest_cut, 1.0 / (M - 1)) : 1.0;
  // u^p1 and u^p2 at the smallest cut, then times r^p1, r^p2 per cut.
  const double q1 = std::pow(ratio, p1), q2 = std::pow(ratio, p2);
  double u1 = M > 1 ? std::pow(smallest_cut, p1) : 1.0,
         u2 = M > 1 ? std::pow(smallest_cut, p2) : 1.0;
  Sliders s;
  s.stiffness.reserve(static_cast<std::size_t>(sliders));
  s.reach.reserve(static_cast<std::size_t>(sliders));
  double mass_below = 0.0, moment_below = 0.0; // at the cut before
  for (int i = 1; i <= M; ++i) {
    if (i == M) u1 = u2 = 1.0; // the last cut is φ_max itself
    const double mass = mass_scale * u1, moment = moment_scale * u2;
    const double w = mass - mass_below;
    s.stiffness.push_back(w);
    s.reach.push_back((moment - moment_below) / w);
    mass_below = mass, moment_below = moment;
    u1 *= q1, u2 *= q2;
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

namespace {

// The elements in order of φ (a joint's terms appended may not be), with prefix sums; kept
// from the last call with the same sliders.
void order(const Sliders& s, LoopWork& w) {
  if (w.from_stiffness == s.stiffness && w.from_reach == s.reach &&
      w.K.size() == s.stiffness.size() + 1)
    return;
  w.from_stiffness = s.stiffness;
  w.from_reach = s.reach;
  const std::size_t n = s.stiffness.size();
  w.k = s.stiffness;
  w.phi = s.reach;
  if (!std::is_sorted(w.phi.begin(), w.phi.end())) {
    std::vector<std::size_t> index(n);
    for (std::size_t i = 0; i < n; ++i)
      index[i] = i;
    std::stable_sort(index.begin(), index.end(),
                     [&s](std::size_t a, std::size_t b) { return s.reach[a] < s.reach[b]; });
    for (std::size_t i = 0; i < n; ++i)
      w.k[i] = s.stiffness[index[i]], w.phi[i] = s.reach[index[i]];
  }
  w.K.assign(n + 1, 0.0);
  w.P.assign(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    w.K[i + 1] = w.K[i] + w.k[i];
    w.P[i + 1] = w.P[i] + w.k[i] * w.phi[i];
  }
}

double position(const LoopWork::Group& g, double phi) {
  return g.virgin ? 0.0 : g.e - g.s * phi;
}

// Every element's position (for the closure test).
void positions(const LoopWork& w, std::vector<double>& x) {
  x.resize(w.phi.size());
  for (const auto& g : w.groups)
    for (int i = g.lo; i < g.hi; ++i)
      x[static_cast<std::size_t>(i)] = position(g, w.phi[static_cast<std::size_t>(i)]);
}

} // namespace

bool steady_loop(const Sliders& s, std::span<const double> y, bool antisymmetric,
                 std::span<double> g, std::vector<LoopEntry>* derivative, LoopWork& w,
                 int max_passes) {
  const int N = static_cast<int>(y.size());
  if (g.size() != y.size())
    throw std::invalid_argument("steady_loop: the force and deformation samples differ in number");
  const int full = antisymmetric ? 2 * N : N;
  const int n = s.size();
  order(s, w);
  w.groups.assign(1, LoopWork::Group{0, n, true, -1, 0.0, 0.0});
  if (n == 0) w.groups.clear();
  auto value = [&](int i) {
    return i < N ? y[static_cast<std::size_t>(i)] : -y[static_cast<std::size_t>(i - N)];
  };
  const auto phi = [&w](int i) { return w.phi[static_cast<std::size_t>(i)]; };
  // The first pass (from rest) only moves the elements: a loop closes at the earliest in the
  // second, and only the last pass's forces are kept. A pass that closes after one that did not
  // write them is followed by one that does (the same pass again).
  const int passes = std::max(1, max_passes);
  bool closed = false, written = false;
  positions(w, w.x);
  const int limit = passes == 1 ? 1 : passes + 1;
  for (int pass = 0; pass < limit && !(closed && written); ++pass) {
    const bool write = pass > 0 || passes == 1;
    w.x_start = w.x;
    if (derivative) derivative->clear();
    for (int t = 0; t < full; ++t) {
      const double yt = value(t);
      bool moved = false; // the last run was dragged at this sample
      // Which way the elements of smallest φ are dragged, if at all: by the ordering, every
      // element that slides then is in a prefix, and a run slides whole up to the first that
      // does not.
      if (!w.groups.empty()) {
        const double x0 = position(w.groups.back(), phi(0)), d0 = yt - x0;
        const double dir = d0 > phi(0) ? 1.0 : (d0 < -phi(0) ? -1.0 : 0.0);
        if (dir != 0.0) {
          const auto slides = [&](const LoopWork::Group& grp, int i) {
            const double d = yt - position(grp, phi(i));
            return dir > 0.0 ? d > phi(i) : d < -phi(i);
          };
          int p = 0; // elements [0, p) slide
          while (!w.groups.empty()) {
            LoopWork::Group& top = w.groups.back();
            if (slides(top, top.hi - 1)) {
              p = top.hi;
              w.groups.pop_back();
              continue;
            }
            int lo = top.lo, hi = top.hi - 1; // the first that does not slide, in [lo, hi]
            while (lo < hi) {
              const int mid = lo + (hi - lo) / 2;
              if (slides(top, mid))
                lo = mid + 1;
              else
                hi = mid;
            }
            p = lo;
            top.lo = p;
            if (top.lo == top.hi) w.groups.pop_back();
            break;
          }
          if (p > 0) w.groups.push_back({0, p, false, t, yt, dir}), moved = true;
        }
      }
      if (t >= N || !write) continue; // a sample whose force is not written
      double force = 0.0, stuck = 0.0;
      const std::size_t first = derivative ? derivative->size() : 0;
      if (derivative) derivative->push_back({t, t, 0.0});
      for (std::size_t r = 0; r < w.groups.size(); ++r) {
        const LoopWork::Group& grp = w.groups[r];
        const double K =
            w.K[static_cast<std::size_t>(grp.hi)] - w.K[static_cast<std::size_t>(grp.lo)];
        if (grp.virgin) {
          force += K * yt;
          stuck += K;
          continue;
        }
        const double P =
            w.P[static_cast<std::size_t>(grp.hi)] - w.P[static_cast<std::size_t>(grp.lo)];
        force += K * (yt - grp.e) + grp.s * P;
        if (moved && r + 1 == w.groups.size()) continue; // sliding: ±f, no derivative
        stuck += K;
        // ∂g_t/∂y_a = −k where a is the sample of the elements' last slide (a sample of the
        // second half is −y of the first: the sign turns)
        if (derivative)
          derivative->push_back(grp.anchor < N ? LoopEntry{t, grp.anchor, -K}
                                               : LoopEntry{t, grp.anchor - N, K});
      }
      g[static_cast<std::size_t>(t)] = force;
      if (derivative) {
        if (stuck != 0.0)
          (*derivative)[first].value = stuck;
        else
          derivative->erase(derivative->begin() + static_cast<std::ptrdiff_t>(first));
      }
    }
    positions(w, w.x);
    closed = w.x == w.x_start;
    written = write;
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
