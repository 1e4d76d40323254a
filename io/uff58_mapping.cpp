// The functions of a universal file mapped into jointid's data: time responses into sine-test
// records, FRFs into a substructure's measured receptance, and records into functions to write
// (io/uff58.hpp). Units and quantities come from io/uff_units.hpp.
#include "io/uff58.hpp"

#include "io/files.hpp"
#include "io/uff_format.hpp"
#include "io/uff_units.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>

namespace jointid::io {

using namespace detail;

namespace {

// The function's place: "a.uff: dataset 3 (line 14)" (an FRF's source).
std::string where(const std::filesystem::path& path, const Uff58Function& f) {
  return f.dataset > 0 ? fmt::format("{}: dataset {} (line {})", path.string(), f.dataset, f.line)
                       : path.string();
}

// The function's place and its description, for messages that refuse it:
// "a.uff: dataset 3 (line 14), ID line 1 "Accel 7+Y"".
std::string culprit(const std::filesystem::path& path, const Uff58Function& f) {
  const std::string_view id = trim(f.id_lines[0]);
  if (id.empty() || id == "NONE" || id == "none") return where(path, f);
  return fmt::format("{}, ID line 1 {}", where(path, f), shown(id));
}

// What a universal file's functions can be in jointid, for refusals: time responses are test
// records, FRFs describe a substructure.
constexpr std::string_view uses =
    "jointid reads time responses (function type 1, or 0 with a time abscissa) as test records, "
    "and frequency response functions (function type 4) in a model file's [frf] section or with "
    "jointid modal-fit";

// Why a function that is not a time response cannot be a test record (record 6 field 1).
std::string not_a_time_response(const Uff58Function& f) {
  const int type = f.function_type;
  const std::string is = fmt::format("record 6 field 1 (function type) is {} ({})", type,
                                     uff_function_type_name(type));
  switch (type) {
  case uff_function_type::frequency_response:
  case 5: // transmissibility
    return fmt::format("{}, not a test record: give FRFs to the model file's [frf] section "
                       "(file = \"...\") or to jointid modal-fit; a test record is a time "
                       "response (function type 1, or 0 with a time abscissa)",
                       is);
  case 2:  // auto spectrum
  case 3:  // cross spectrum
  case 9:  // power spectral density
  case 10: // energy spectral density
  case 12: // spectrum
    return fmt::format("{}: a spectrum has lost the time history (an auto spectrum also the "
                       "phase) that a test needs; export the time responses from the test system "
                       "instead: {}",
                       is, uses);
  default:
    return fmt::format("{}, which jointid does not use: {}", is, uses);
  }
}

// The channel a time response holds, and the factor (sign included) that makes its values SI.
struct ChannelOf {
  identify::Quantity quantity = identify::Quantity::force;
  fem::NodeDof at;
  double factor = 1.0;
  double time_factor = 1.0;
  std::optional<double> excitation_hz;
  int excitation_line = 0; ///< the ID line (1–5) that gave it
};

// What an ordinate axis (record 9, or the denominator's record 10) holds, and the factor that
// makes its values SI: the quantity from the specific data type, the unit from the axis units
// label or, without one, from the file's dataset 164. `rotation`: at a rotational DOF.
struct AxisScale {
  identify::Quantity quantity = identify::Quantity::force;
  double factor = 1.0;
};

// The data types jointid reads, for messages.
constexpr std::string_view quantities =
    "13 (excitation force), 8 (displacement), 11 (velocity) or 12 (acceleration)";

// `dof_field`: the record 6 field that gives the axis' DOF, as "record 6 field 7 (response
// direction) is 2 (+Y)", for a units label of the other kind of DOF.
template <class Error>
AxisScale axis_scale(const Uff58Function& f, const Uff58Axis& o, int record, bool rotation,
                     const std::string& dof_field, const Error& error) {
  // The quantity from the specific data type; for 0 (unknown) or 1 (general), as data
  // acquisition systems write it, from the units label.
  const char* axis = record == 9 ? "ordinate" : "denominator";
  const bool unspecified =
      o.data_type == uff_data_type::unknown || o.data_type == uff_data_type::general;
  const bool labelled = !uff_no_units_label(o.units_label);
  std::optional<UffAxisQuantity> q = uff_axis_quantity(o.data_type, rotation);
  if (!q && unspecified && labelled) {
    q = uff_label_quantity(o.units_label, rotation);
    if (!q && uff_label_quantity(o.units_label, !rotation))
      throw error(fmt::format("record {} field 6 (axis units label) '{}' is a unit of a {}, but "
                              "{}, a {}",
                              record, trim(o.units_label), rotation ? "translation" : "rotation",
                              dof_field, rotation ? "rotation" : "translation"));
    if (!q)
      throw error(fmt::format(
          "cannot tell the quantity: record {} field 1 ({} specific data type) is {} ({}) and "
          "field 6 (axis units label) '{}' is not a unit jointid reads; set field 1 to {}, or "
          "field 6 to a unit of one of them ({}; {}; {}; {})",
          record, axis, o.data_type, uff_data_type_name(o.data_type), trim(o.units_label),
          quantities, uff_unit_list(rotation ? UffUnitKind::moment : UffUnitKind::force),
          uff_unit_list(rotation ? UffUnitKind::angle : UffUnitKind::length),
          uff_unit_list(rotation ? UffUnitKind::angular_velocity : UffUnitKind::velocity),
          uff_unit_list(rotation ? UffUnitKind::angular_acceleration : UffUnitKind::acceleration)));
  }
  if (!q && unspecified)
    throw error(fmt::format("cannot tell the quantity: record {} field 1 ({} specific data type) "
                            "is {} ({}) and field 6 (axis units label) gives no unit; set field 1 "
                            "to {}, or field 6 to the unit (e.g. {})",
                            record, axis, o.data_type, uff_data_type_name(o.data_type), quantities,
                            rotation ? "N m, rad, rad/s, rad/s^2" : "N, m, m/s, m/s^2, g"));
  if (!q)
    throw error(fmt::format("record {} field 1 ({} specific data type) is {} ({}): jointid reads "
                            "{} (or 0 and 1 with a units label that names one of them)",
                            record, axis, o.data_type, uff_data_type_name(o.data_type),
                            quantities));

  // Unit exponents: not given (0 0 0), or those of the standard's Addendum A.
  const bool none = o.length_exponent == 0 && o.force_exponent == 0 && o.temperature_exponent == 0;
  const bool addendum = o.length_exponent == q->length_exponent &&
                        o.force_exponent == q->force_exponent && o.temperature_exponent == 0;
  if (!none && !addendum)
    throw error(fmt::format(
        "record {} fields 2–4 (length, force, temperature units exponents) are {} {} "
        "{}, which do not fit {} at a {} DOF (expected {} {} 0 as in the standard's "
        "Addendum A, or 0 0 0)",
        record, o.length_exponent, o.force_exponent, o.temperature_exponent, uff_unit_noun(q->kind),
        rotation ? "rotational" : "translational", q->length_exponent, q->force_exponent));

  // Scale to SI: the units label says the unit; without one, the unit system of dataset 164.
  AxisScale c{q->quantity, 1.0};
  if (!uff_no_units_label(o.units_label)) {
    const std::optional<double> factor = uff_unit_to_si(q->kind, o.units_label);
    if (!factor)
      throw error(
          fmt::format("record {} field 6 (axis units label) '{}' is not a unit of {} that jointid "
                      "reads ({}); convert the data to one of these or to SI",
                      record, trim(o.units_label), uff_unit_noun(q->kind), uff_unit_list(q->kind)));
    c.factor = *factor;
  } else if (f.units) {
    c.factor = uff164_to_si(*f.units, q->length_exponent, q->force_exponent);
  }
  return c;
}

// A time abscissa: data type 17 (time), or a units label of time (s, ms, "Time").
bool time_abscissa(const Uff58Axis& a) {
  return a.data_type == uff_data_type::time ||
         (!uff_no_units_label(a.units_label) && uff_unit_to_si(UffUnitKind::time, a.units_label));
}

ChannelOf channel_of(const Uff58Function& f, const std::filesystem::path& path) {
  const std::string at = culprit(path, f);
  const auto error = [&](const std::string& what) {
    return Error(fmt::format("{}: {}", at, what));
  };
  // A time response: function type 1, or 0 (general or unknown, as test systems write time
  // data) whose abscissa is time.
  if (f.function_type == uff_function_type::general && !time_abscissa(f.abscissa))
    throw error(fmt::format(
        "record 6 field 1 (function type) is 0 (general or unknown) and record 8 (abscissa) does "
        "not say time (field 1, specific data type, is {} ({}); field 6, axis units label, is "
        "'{}'): for a time response set record 8 field 1 to 17 (time) or field 6 to s, or record "
        "6 field 1 to 1 (time response); {}",
        f.abscissa.data_type, uff_data_type_name(f.abscissa.data_type),
        trim(f.abscissa.units_label), uses));
  if (f.function_type != uff_function_type::time_response &&
      f.function_type != uff_function_type::general)
    throw error(not_a_time_response(f));
  if (f.is_complex())
    throw error(
        fmt::format("record 7 field 1 (ordinate data type) is {} ({}): a time response must be "
                    "real (2 or 4)",
                    f.ordinate_type, ordinate_type_text(f.ordinate_type)));
  if (!f.even)
    throw error("record 7 field 3 (abscissa spacing) is 0 (uneven): a time record must be evenly "
                "sampled (1)");
  if (!(std::isfinite(f.abscissa_min) && std::isfinite(f.abscissa_increment) &&
        f.abscissa_increment > 0.0))
    throw error(fmt::format("record 7 fields 4–5 (abscissa minimum, increment) are {} and {}: a "
                            "time record needs a finite start and a step > 0",
                            f.abscissa_min, f.abscissa_increment));
  if (f.data.size() < 4)
    throw error(
        fmt::format("record 7 field 2 (number of points) is {}: a time record needs at least 4 "
                    "samples",
                    f.data.size()));
  for (Eigen::Index i = 0; i < f.data.size(); ++i)
    if (!std::isfinite(f.data(i)))
      throw error(
          fmt::format("record 12 (data values) value {} is {}: a time record must be finite", i + 1,
                      f.data(i)));

  ChannelOf c;
  if (f.response_node <= 0)
    throw error(fmt::format("record 6 field 6 (response node) is {}: expected a node id > 0",
                            f.response_node));
  if (f.response_direction == 0 || std::abs(f.response_direction) > 6)
    throw error(
        fmt::format("record 6 field 7 (response direction) is {}: a channel needs a direction "
                    "±1…6 (X, Y, Z, RX, RY, RZ)",
                    direction_text(f.response_direction)));
  c.at = {f.response_node,
          fem::all_dofs[static_cast<std::size_t>(std::abs(f.response_direction) - 1)]};
  const bool rotation = fem::is_rotation(c.at.dof);

  const AxisScale scale = axis_scale(f, f.ordinate, 9, rotation,
                                     fmt::format("record 6 field 7 (response direction) is {}",
                                                 direction_text(f.response_direction)),
                                     error);
  c.quantity = scale.quantity;
  c.factor = scale.factor;
  if (f.response_direction < 0) c.factor = -c.factor;

  // The abscissa: time in s (the unit systems of dataset 164 do not scale time).
  const Uff58Axis& a = f.abscissa;
  if (a.data_type != uff_data_type::time && a.data_type != uff_data_type::unknown &&
      a.data_type != uff_data_type::general)
    throw error(
        fmt::format("record 8 field 1 (abscissa specific data type) is {} ({}): a time response's "
                    "abscissa is time (17, or 0 or 1 with the unit s)",
                    a.data_type, uff_data_type_name(a.data_type)));
  if (!uff_no_units_label(a.units_label)) {
    const std::optional<double> factor = uff_unit_to_si(UffUnitKind::time, a.units_label);
    if (!factor)
      throw error(fmt::format("record 8 field 6 (axis units label) '{}' is not a unit of time that "
                              "jointid reads (s, ms)",
                              trim(a.units_label)));
    c.time_factor = *factor;
  }

  // `excitation_hz = <Hz>` in an ID line.
  for (std::size_t r = 0; r < 5; ++r) {
    const std::string_view text = trim(f.id_lines[r]);
    if (!text.starts_with("excitation_hz")) continue;
    const std::string_view after = trim(text.substr(std::string_view("excitation_hz").size()));
    if (after.empty() || after.front() != '=') continue;
    const std::string_view value_text = trim(after.substr(1));
    const auto value = parse_real(value_text);
    if (!value || !std::isfinite(*value) || !(*value > 0.0))
      throw error(
          fmt::format("record {} (ID line {}): excitation_hz: expected a frequency > 0 Hz, got {}",
                      r + 1, r + 1, shown(value_text)));
    if (c.excitation_hz && *c.excitation_hz != *value)
      throw error(
          fmt::format("excitation_hz given twice ({} Hz in ID line {}, {} Hz in ID line {})",
                      *c.excitation_hz, c.excitation_line, *value, r + 1));
    c.excitation_hz = *value;
    c.excitation_line = static_cast<int>(r + 1);
  }
  return c;
}

} // namespace

std::vector<identify::SineTest> uff58_tests(const std::vector<Uff58Function>& functions,
                                            const std::filesystem::path& path) {
  if (functions.empty())
    throw Error(fmt::format("{}: no dataset 58 (function at nodal DOF) in the file; expected the "
                            "time responses of a test (function type 1, or 0 with a time "
                            "abscissa)",
                            path.string()));
  struct Group {
    double t0, dt;
    Eigen::Index n;
    identify::Record record;
    std::vector<const Uff58Function*> members;
    const Uff58Function* excitation_from = nullptr;
  };
  std::vector<Group> groups;
  for (const Uff58Function& f : functions) {
    const ChannelOf c = channel_of(f, path);
    const double t0 = f.abscissa_min * c.time_factor, dt = f.abscissa_increment * c.time_factor;
    const Eigen::Index n = f.data.size();
    auto group = std::find_if(groups.begin(), groups.end(),
                              [&](const Group& g) { return g.t0 == t0 && g.dt == dt && g.n == n; });
    if (group == groups.end()) {
      Group g{t0, dt, n, {}, {}, nullptr};
      g.record.source = fmt::format("{}#{}", path.string(), f.dataset);
      g.record.t.resize(n);
      for (Eigen::Index i = 0; i < n; ++i)
        g.record.t(i) = t0 + static_cast<double>(i) * dt;
      // The sample times must stay finite, increasing and uniform in double precision: an
      // increment lost against a large minimum, or times beyond the range of a double, are not.
      const auto& t = g.record.t;
      const double mean_step = (t(n - 1) - t(0)) / static_cast<double>(n - 1);
      for (Eigen::Index i = 1; i < n; ++i) {
        const double step = t(i) - t(i - 1);
        if (!std::isfinite(t(i)) || !(step > 0.0) || !std::isfinite(mean_step) ||
            std::abs(step - mean_step) > 1e-6 * mean_step)
          throw Error(fmt::format(
              "{}: record 7 fields 4–5 (abscissa minimum, increment) are {} and {} s: the {} "
              "sample times are not finite, increasing and uniform in double precision (sample "
              "{} is at {} s); a time record starts near 0 with a step that is not lost against "
              "its start",
              culprit(path, f), t0, dt, n, i + 1, t(i)));
      }
      groups.push_back(std::move(g));
      group = groups.end() - 1;
    }
    identify::Channel channel{c.quantity, c.at,
                              c.factor == 1.0 ? f.data : Eigen::VectorXd(c.factor * f.data)};
    for (Eigen::Index i = 0; i < n; ++i)
      if (!std::isfinite(channel.samples(i)))
        throw Error(fmt::format("{}: record 12 (data values) value {} is {}, which is {} in SI "
                                "units (factor {}): not a finite number",
                                culprit(path, f), i + 1, f.data(i), channel.samples(i), c.factor));
    for (std::size_t k = 0; k < group->record.channels.size(); ++k)
      if (group->record.channels[k].name() == channel.name()) {
        const Uff58Function& other = *group->members[k];
        throw Error(fmt::format(
            "{}: channel {} is given twice in one record (datasets {} at line {} and {} at line "
            "{}, with the same abscissa: {} s + {} s × {} points); each test needs its own file "
            "or abscissa",
            path.string(), channel.name(), other.dataset, other.line, f.dataset, f.line, t0, dt,
            n));
      }
    if (c.excitation_hz) {
      if (group->record.excitation_hz && *group->record.excitation_hz != *c.excitation_hz)
        throw Error(fmt::format("{}: excitation_hz differs within one record: {} Hz (dataset {} "
                                "at line {}) and {} Hz (dataset {} at line {})",
                                path.string(), *group->record.excitation_hz,
                                group->excitation_from->dataset, group->excitation_from->line,
                                *c.excitation_hz, f.dataset, f.line));
      group->record.excitation_hz = c.excitation_hz;
      group->excitation_from = &f;
    }
    group->record.channels.push_back(std::move(channel));
    group->members.push_back(&f);
  }
  std::vector<identify::SineTest> tests;
  tests.reserve(groups.size());
  for (Group& g : groups)
    tests.emplace_back(std::move(g.record));
  return tests;
}

Uff58Axis uff58_axis(identify::Quantity quantity, bool rotation) {
  switch (quantity) {
  case identify::Quantity::force:
    return rotation ? Uff58Axis{uff_data_type::excitation_force, 1, 1, 0, "Moment", "N m"}
                    : Uff58Axis{uff_data_type::excitation_force, 0, 1, 0, "Force", "N"};
  case identify::Quantity::displacement:
    return rotation ? Uff58Axis{uff_data_type::displacement, 0, 0, 0, "Rotation", "rad"}
                    : Uff58Axis{uff_data_type::displacement, 1, 0, 0, "Displacement", "m"};
  case identify::Quantity::velocity:
    return rotation ? Uff58Axis{uff_data_type::velocity, 0, 0, 0, "Angular velocity", "rad/s"}
                    : Uff58Axis{uff_data_type::velocity, 1, 0, 0, "Velocity", "m/s"};
  case identify::Quantity::acceleration:
    return rotation
               ? Uff58Axis{uff_data_type::acceleration, 0, 0, 0, "Angular acceleration", "rad/s^2"}
               : Uff58Axis{uff_data_type::acceleration, 1, 0, 0, "Acceleration", "m/s^2"};
  }
  throw std::logic_error("uff58_axis: unknown quantity");
}

std::vector<Uff58Function> uff58_from_record(const identify::Record& record) {
  const std::string name = record.source.empty() ? std::string("record") : record.source;
  const Eigen::Index n = record.t.size();
  if (n < 2)
    throw Error(fmt::format("{}: {} sample{}, expected at least 2", name, n, n == 1 ? "" : "s"));
  if (!record.t.allFinite()) throw Error(name + ": t has NaN or infinite values");
  const double dt = record.dt();
  if (!(dt > 0.0)) throw Error(fmt::format("{}: time does not increase (step {} s)", name, dt));
  for (Eigen::Index i = 1; i < n; ++i) {
    const double step = record.t(i) - record.t(i - 1);
    if (std::abs(step - dt) > 1e-6 * dt)
      throw Error(fmt::format("{}: time step {} s at sample {} differs from the mean step {} s by "
                              "more than 1e-6 (relative): dataset 58 needs uniform sampling",
                              name, step, i + 1, dt));
  }
  if (record.excitation_hz && !(std::isfinite(*record.excitation_hz) && *record.excitation_hz > 0))
    throw Error(
        fmt::format("{}: excitation_hz {} is not a frequency > 0", name, *record.excitation_hz));

  std::vector<Uff58Function> functions;
  for (std::size_t c = 0; c < record.channels.size(); ++c) {
    const identify::Channel& channel = record.channels[c];
    if (channel.samples.size() != n)
      throw Error(fmt::format("{}: channel {} has {} samples but t has {}", name, channel.name(),
                              channel.samples.size(), n));
    if (!channel.samples.allFinite())
      throw Error(fmt::format("{}: channel {} has NaN or infinite values", name, channel.name()));
    const bool rotation = fem::is_rotation(channel.at.dof);
    Uff58Function f;
    f.id_lines[0] = channel.name();
    if (record.excitation_hz)
      f.id_lines[1] = fmt::format("excitation_hz = {}", *record.excitation_hz);
    f.function_type = uff_function_type::time_response;
    f.function_id = static_cast<int>(c + 1);
    f.response_node = channel.at.node;
    f.response_direction = static_cast<int>(channel.at.dof) + 1;
    f.ordinate_type = 4;
    f.even = true;
    f.abscissa_min = record.t(0);
    f.abscissa_increment = dt;
    f.abscissa = {uff_data_type::time, 0, 0, 0, "Time", "s"};
    f.ordinate = uff58_axis(channel.quantity, rotation);
    f.data = channel.samples;
    functions.push_back(std::move(f));
  }
  return functions;
}

namespace {

// One FRF (function type 4) as the receptance in SI, its source `source`; `at` names it in
// messages.
frf::MeasuredFunction frf_of(const Uff58Function& f, const std::string& source,
                             const std::string& at) {
  const auto error = [&](const std::string& what) {
    return Error(fmt::format("{}: {}", at, what));
  };
  if (f.function_type != uff_function_type::frequency_response)
    throw error(fmt::format(
        "record 6 field 1 (function type) is {} ({}): the substructure's FRFs are frequency "
        "response functions (4){}",
        f.function_type, uff_function_type_name(f.function_type),
        f.function_type == uff_function_type::time_response ||
                (f.function_type == uff_function_type::general && time_abscissa(f.abscissa))
            ? "; a time response is a test record (give it to identify, discover or modal-fit)"
            : ""));
  if (!f.is_complex())
    throw error(fmt::format("record 7 field 1 (ordinate data type) is {} ({}): an FRF must be "
                            "complex (5 or 6)",
                            f.ordinate_type, ordinate_type_text(f.ordinate_type)));
  frf::MeasuredFunction m;
  m.source = source;
  const auto dof_of = [&](int node, int direction, int field, const char* what) {
    if (node <= 0)
      throw error(fmt::format("record 6 field {} ({} node) is {}: expected a node id > 0", field,
                              what, node));
    if (direction == 0 || std::abs(direction) > 6)
      throw error(fmt::format("record 6 field {} ({} direction) is {}: an FRF needs a "
                              "direction ±1…6 (X, Y, Z, RX, RY, RZ)",
                              field + 1, what, direction_text(direction)));
    return fem::NodeDof{node, fem::all_dofs[static_cast<std::size_t>(std::abs(direction) - 1)]};
  };
  m.response = dof_of(f.response_node, f.response_direction, 6, "response");
  m.drive = dof_of(f.reference_node, f.reference_direction, 9, "reference");
  // Numerator: displacement, velocity or acceleration; denominator: the force (or moment).
  const AxisScale num = axis_scale(f, f.ordinate, 9, fem::is_rotation(m.response.dof),
                                   fmt::format("record 6 field 7 (response direction) is {}",
                                               direction_text(f.response_direction)),
                                   error);
  if (num.quantity == identify::Quantity::force)
    throw error(fmt::format("record 9 (ordinate) is a force (field 1, specific data type, {} ({}); "
                            "field 6, axis units label, '{}'): an FRF's numerator is the "
                            "response (8 displacement, 11 velocity, 12 acceleration)",
                            f.ordinate.data_type, uff_data_type_name(f.ordinate.data_type),
                            trim(f.ordinate.units_label)));
  AxisScale den;
  if (f.denominator.data_type == uff_data_type::unknown &&
      uff_no_units_label(f.denominator.units_label))
    den.factor = f.units ? uff164_to_si(*f.units, fem::is_rotation(m.drive.dof) ? 1 : 0, 1)
                         : 1.0; // not given: a force in the file's units
  else
    den = axis_scale(f, f.denominator, 10, fem::is_rotation(m.drive.dof),
                     fmt::format("record 6 field 10 (reference direction) is {}",
                                 direction_text(f.reference_direction)),
                     error);
  if (den.quantity != identify::Quantity::force)
    throw error(fmt::format("record 10 (ordinate denominator) is a response, not a force (field "
                            "1, specific data type, {} ({}); field 6, axis units label, '{}'): an "
                            "FRF is per excitation force (13)",
                            f.denominator.data_type, uff_data_type_name(f.denominator.data_type),
                            trim(f.denominator.units_label)));
  double sign = num.factor / den.factor;
  if ((f.response_direction < 0) != (f.reference_direction < 0)) sign = -sign;
  // Abscissa: frequency in Hz.
  const Uff58Axis& a = f.abscissa;
  if (a.data_type != uff_data_type::frequency && a.data_type != uff_data_type::unknown &&
      a.data_type != uff_data_type::general)
    throw error(fmt::format("record 8 field 1 (abscissa specific data type) is {} ({}): an "
                            "FRF's abscissa is frequency (18)",
                            a.data_type, uff_data_type_name(a.data_type)));
  if (!uff_no_units_label(a.units_label) && !uff_unit_to_si(UffUnitKind::frequency, a.units_label))
    throw error(fmt::format("record 8 field 6 (axis units label) '{}' is not a unit of "
                            "frequency that jointid reads (Hz)",
                            trim(a.units_label)));
  const Eigen::Index n = f.complex_data.size();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double freq = f.even ? f.abscissa_min + static_cast<double>(i) * f.abscissa_increment
                               : f.abscissa_values(i);
    if (!std::isfinite(freq) || freq < 0.0)
      throw error(fmt::format("record {} (abscissa) point {} is at {} Hz: expected a finite "
                              "frequency >= 0",
                              f.even ? 7 : 12, i + 1, freq));
    if (!m.frequencies_hz.empty() && !(freq > m.frequencies_hz.back()))
      throw error(fmt::format("record 12 (data values) point {} is at {} Hz, not above the "
                              "previous point ({} Hz): the frequencies must increase",
                              i + 1, freq, m.frequencies_hz.back()));
    std::complex<double> v = sign * f.complex_data(i);
    const double w = 2.0 * std::numbers::pi * freq;
    if (num.quantity != identify::Quantity::displacement && freq == 0.0)
      continue; // mobility and accelerance say nothing of the receptance at 0 Hz
    if (num.quantity == identify::Quantity::velocity) v /= std::complex<double>(0.0, w);
    if (num.quantity == identify::Quantity::acceleration) v /= -w * w;
    if (!std::isfinite(v.real()) || !std::isfinite(v.imag()))
      throw error(fmt::format("record 12 (data values) point {} ({} Hz) is {}{:+}i, not a "
                              "finite receptance in SI units",
                              i + 1, freq, f.complex_data(i).real(), f.complex_data(i).imag()));
    m.frequencies_hz.push_back(freq);
    m.receptance.push_back(v);
  }
  if (m.frequencies_hz.size() < 2)
    throw error(fmt::format("record 7 field 2 (number of points) gives {} usable line(s): an "
                            "FRF needs at least 2",
                            m.frequencies_hz.size()));
  return m;
}

} // namespace

std::vector<frf::MeasuredFunction> uff58_frfs(const std::vector<Uff58Function>& functions,
                                              const std::filesystem::path& path) {
  if (functions.empty())
    throw Error(fmt::format("{}: no dataset 58 (function at nodal DOF) in the file; expected "
                            "FRFs (function type 4)",
                            path.string()));
  std::vector<frf::MeasuredFunction> out;
  for (const Uff58Function& f : functions) {
    const std::string at = where(path, f);
    frf::MeasuredFunction m = frf_of(f, at, culprit(path, f));
    for (const frf::MeasuredFunction& other : out)
      if (other.response == m.response && other.drive == m.drive)
        throw Error(fmt::format("{}: the FRF {}/{} (response/reference) is already in {}", at,
                                fem::to_string(m.response), fem::to_string(m.drive), other.source));
    out.push_back(std::move(m));
  }
  return out;
}

} // namespace jointid::io
