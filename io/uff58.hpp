#pragma once
/// Universal File Format dataset 58, "function at nodal DOF": ASCII (`58`) and binary (`58b`),
/// read and written; and their time responses as jointid's sine-test records.
///
/// A universal file is a sequence of datasets, each between two `    -1` lines, the first line
/// inside giving its number (`    58`, `    58b`, `   164`, `  2411`, ...). read_uff58 returns
/// every dataset 58 and skips the others, except the units of dataset 164, which it attaches to
/// the functions that follow it.
///
/// Dataset 58 (SDRC/I-DEAS "Universal Dataset Number 58"; UC-SDRL's note on the binary 58b):
///   records 1–5   Format(80A1)                     ID lines (1: function description, 3: date)
///   record 6      Format(2(I5,I10),2(1X,10A1,I10,I4))  function type, function id, version,
///                 load case, response entity name, node, direction, reference entity name,
///                 node, direction
///   record 7      Format(3I10,3E13.5)              ordinate data type, number of points,
///                 spacing (0 uneven, 1 even), abscissa minimum, increment, z-axis value
///   records 8–11  Format(I10,3I5,2(1X,20A1))       abscissa, ordinate numerator, ordinate
///                 denominator, z-axis: specific data type, length, force and temperature unit
///                 exponents, axis label, axis units label
///   record 12     the values: y (even) or x y pairs (uneven); complex: re im (even) or x re im
///                 (uneven); 6E13.5 single, 4E20.12 double
/// 58b: the identifier line is `    58b     1     2          11        nbytes     0     0 ...`
/// (I6,A1,I6,I6,I12,I12,I6,I6,I12,I12: byte ordering 1 little-endian / 2 big-endian, floating
/// point format 1 DEC VMS / 2 IEEE 754 / 3 IBM 370, 11 ASCII lines, bytes of binary data), then
/// records 1–11 as ASCII lines, then the values as nbytes bytes, then `    -1` at once.
///
/// Reading. Records 6 and 8–11 are read by their columns (entity names and labels may hold
/// blanks), or, when a line does not fit the columns, as blank-separated fields. Records 7 and
/// 12 and dataset 164's factors are read as blank-separated numbers (E or Fortran D exponents).
/// ASCII single-precision values are rounded to single precision as read. 58b: only
/// little-endian IEEE 754 is read (anything else is refused, naming the flags); uneven spacing
/// takes the abscissa in the ordinate's precision or in single precision (the standard's
/// "abscissa is always single precision"), told apart by the number of bytes.
///
/// Writing. The layout is the standard's, but every number is written with the digits its
/// precision needs to read back exactly: double values as E25.16, three a line; single values
/// as E16.8, five a line; record 7's minimum, increment and z value as E13.5 when that is exact,
/// else E25.16. Readers that split fields at blanks read these files; readers that cut the
/// standard's fixed columns (E20.12) need the binary form, which is exact and standard.
#include "frf/measured_frf.hpp"
#include "identify/measurement.hpp"
#include "identify/record.hpp"

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace jointid::io {

/// Specific data type codes of records 8–11 field 1 (the standard's table):
/// 0 unknown, 1 general, 2 stress, 3 strain, 5 temperature, 6 heat flux, 8 displacement,
/// 9 reaction force, 11 velocity, 12 acceleration, 13 excitation force, 15 pressure, 16 mass,
/// 17 time, 18 frequency, 19 rpm, 20 order (21 sound pressure, 22 sound intensity, 23 sound
/// power in later revisions).
namespace uff_data_type {
inline constexpr int unknown = 0, general = 1, displacement = 8, reaction_force = 9, velocity = 11,
                     acceleration = 12, excitation_force = 13, time = 17, frequency = 18;
}

/// Function types of record 6 field 1: 0 general or unknown, 1 time response, 2 auto spectrum,
/// 3 cross spectrum, 4 frequency response function, 5 transmissibility, 6 coherence, 7 auto
/// correlation, 8 cross correlation, 9 PSD, 10 ESD, 11 probability density, 12 spectrum, 13
/// cumulative frequency distribution, 14 peaks valley, 15 stress/cycles, 16 strain/cycles, 17
/// orbit, 18 mode indicator function, 19 force pattern, 20 partial power, 21 partial coherence,
/// 22 eigenvalue, 23 eigenvector, 24 shock response spectrum, 25 FIR filter, 26 multiple
/// coherence, 27 order function, 28 phase compensation.
namespace uff_function_type {
inline constexpr int general = 0, time_response = 1, frequency_response = 4;
}

/// "time response", "frequency response function", ... ("function type 99" if unknown).
std::string uff_function_type_name(int type);
/// "displacement", "excitation force", ... ("data type 99" if unknown).
std::string uff_data_type_name(int type);

/// Records 8–11: the data characteristics of one axis.
struct Uff58Axis {
  int data_type = uff_data_type::unknown; ///< specific data type (field 1)
  int length_exponent = 0;                ///< field 2
  int force_exponent = 0;                 ///< field 3
  int temperature_exponent = 0;           ///< field 4
  std::string label = "NONE";             ///< axis label (field 5, at most 20 characters)
  std::string units_label = "NONE";       ///< axis units label (field 6, at most 20 characters)
  friend bool operator==(const Uff58Axis&, const Uff58Axis&) = default;
};

/// Dataset 164: the file's unit system. A value in the file's units divided by the factor is SI
/// (length: m, force: N), e.g. length 1000 for millimetres.
struct UffUnits {
  int code = 1;                   ///< 1 SI, 2 BG, 3 MG, 4 BA, 5 MM, 6 CM, 7 IN, 8 GM, 9 US, 10 MN
  std::string description = "SI"; ///< documentation only
  int temperature_mode = 2;       ///< 1 absolute, 2 relative
  double length = 1.0, force = 1.0, temperature = 1.0, temperature_offset = 0.0;
  friend bool operator==(const UffUnits&, const UffUnits&) = default;
};

/// One dataset 58. Defaults: a real double-precision, evenly spaced time response.
struct Uff58Function {
  std::array<std::string, 5> id_lines{"NONE", "NONE", "NONE", "NONE", "NONE"}; ///< records 1–5
  // Record 6: DOF identification. Directions: 0 scalar, 1..6 = +X +Y +Z +RX +RY +RZ, negative =
  // the negative direction.
  int function_type = uff_function_type::time_response;
  int function_id = 0;
  int version = 0;   ///< version or sequence number
  int load_case = 0; ///< 0: single point excitation
  std::string response_entity = "NONE";
  int response_node = 0;
  int response_direction = 0;
  std::string reference_entity = "NONE";
  int reference_node = 0;
  int reference_direction = 0;
  // Record 7: data form.
  int ordinate_type = 4;     ///< 2 real single, 4 real double, 5 complex single, 6 complex double
  bool even = true;          ///< field 3: 1 even (no abscissa values stored), 0 uneven
  double abscissa_min = 0.0; ///< field 4 (even spacing)
  double abscissa_increment = 0.0;                               ///< field 5 (even spacing)
  double z_value = 0.0;                                          ///< field 6
  Uff58Axis abscissa{uff_data_type::time, 0, 0, 0, "Time", "s"}; ///< record 8
  Uff58Axis ordinate;                                            ///< record 9 (numerator)
  Uff58Axis denominator;                                         ///< record 10
  Uff58Axis z_axis;                                              ///< record 11
  // Record 12: the values, `data` for real ordinates (types 2, 4), `complex_data` for complex
  // ones (5, 6); single-precision types hold values that single precision represents.
  Eigen::VectorXd data;
  Eigen::VectorXcd complex_data;
  Eigen::VectorXd abscissa_values; ///< uneven spacing only: one per value
  /// The unit system of the last dataset 164 before this one in its file (none: SI). The writer
  /// writes a dataset 164 before a function whose units differ from the previous function's.
  std::optional<UffUnits> units;

  // Where it was read from (for messages; not written).
  int dataset = 0; ///< 1-based position among all datasets of its file (0: not read)
  int line = 0;    ///< line of the dataset's opening `    -1`
  bool binary = false;

  bool is_complex() const { return ordinate_type == 5 || ordinate_type == 6; }
  /// Record 7 field 2: the number of values (even) or of abscissa–ordinate pairs (uneven).
  Eigen::Index num_points() const { return is_complex() ? complex_data.size() : data.size(); }
};

/// Every dataset 58 and 58b of a universal file, in file order. Throws io::Error naming the
/// file, the line (ASCII) or byte offset (binary data), the dataset, record and field, and what
/// was expected: text before the first `    -1`, a dataset without its closing `    -1`,
/// truncated records or data, a field that is not a number or out of range (ordinate type not
/// 2/4/5/6, spacing not 0/1, direction beyond ±6, even spacing with an increment that is not
/// > 0), the wrong number of values, a 58b with another byte order or float format than
/// little-endian IEEE 754 or a byte count that does not fit the values, a malformed dataset 164.
std::vector<Uff58Function> read_uff58(const std::filesystem::path& path);

/// The text (ASCII) or bytes (58b) of the functions as a universal file, each function's units
/// preceded by a dataset 164 when they change (see Uff58Function::units). Throws io::Error
/// naming the function (its position in the list, from 1) and the field: an ID line longer than
/// 80 characters or holding a line break, an entity name longer than 10 or a label longer than
/// 20 characters, an integer too wide for its field, an ordinate type not 2/4/5/6, data of the
/// wrong kind for it (or both kinds, or none), abscissa values given for even spacing or
/// missing for uneven, an increment that is not finite and > 0 for even spacing, a value
/// beyond single precision for types 2 and 5. NaN and infinite values are written as such.
std::string uff58_text(const std::vector<Uff58Function>& functions, bool binary = false);
/// Writes uff58_text(functions, binary) atomically (see write_file_atomically).
void write_uff58(const std::filesystem::path& path, const std::vector<Uff58Function>& functions,
                 bool binary = false);

/// The time responses of a universal file as sine-test records. Every function must be a time
/// response: function type 1, or 0 ("general or unknown", as many test systems write time
/// data) whose abscissa is time (record 8 data type 17, or a units label of time: s, ms,
/// "Time"); real, evenly spaced, of at least 4 finite values. Those with the same abscissa
/// (minimum, increment, number of points, in seconds) form one identify::Record, in the order of
/// their first function; Record::source is "<path>#<dataset>" with the position of that first
/// function's dataset in the file (from 1, counting every dataset).
///  - Channel quantity from record 9's data type: 13 excitation force → f, 8 displacement → x,
///    11 velocity → v, 12 acceleration → a; for 0 (unknown) and 1 (general), from the axis units
///    label (uff_label_quantity: m/s², mm/s², g → a; m/s → v; m, mm → x; N, kN, lbf → f; at a
///    rotation rad/s², rad/s, rad, N m). Other data types, or 0 and 1 without such a label, are
///    refused.
///  - Channel DOF: node = the response node, DOF from the response direction (1..6 → ux uy uz
///    rx ry rz); a negative direction flips the sign of the samples. Reference node and
///    direction are not used.
///  - Units, converted to SI: the axis units label (record 9 field 6) when given: length m, mm,
///    cm, um (µm), in; velocity m/s, mm/s, cm/s, um/s, in/s; acceleration m/s^2 (also m/s2, m/s²,
///    m/s**2), mm/s^2, cm/s^2, in/s^2, g or G (9.80665 m/s²); force N, kN, mN, lbf; rotations rad,
///    mrad, deg (and /s, /s^2); moments N m (N*m, N.m, Nm, N·m), kN m, N mm, mN m; without a label
///    ("NONE" or blank) the dataset 164 in force (factors of length and force, with the
///    exponents of the standard's Addendum A for the quantity), or SI without one. Time (record
///    8 label): s, ms, or none ("Time", which some writers put there, reads as s). A label not in
///    this list is refused, naming it. io/uff_units.hpp holds these labels and factors.
///  - Unit exponents (record 9 fields 2–4) must be 0 0 0 (not given) or those of Addendum A for
///    the quantity (translational motion 1 0 0, force 0 1 0, rotation 0 0 0, moment 1 1 0).
///  - `excitation_hz = <Hz>` in any ID line gives Record::excitation_hz (the functions of one
///    record must not disagree).
/// Throws io::Error naming the file, the dataset, its line and ID line 1, the record and field
/// to fix, and what jointid can use instead: another function type (an FRF is for the model
/// file's [frf] section or modal-fit; a spectrum has lost the time history), type 0 without a
/// time abscissa, a quantity neither the data type nor the label tells, complex or uneven data,
/// a scalar direction, a channel given twice in one record, no function at all.
std::vector<identify::SineTest> uff58_tests(const std::vector<Uff58Function>& functions,
                                            const std::filesystem::path& path);

/// The FRFs of a universal file (function type 4) as the substructure's measured receptance
/// (frf::MeasuredFunction, SI, x(t) = Re(H F e^{iωt})), one per dataset, in file order; source
/// "<path>: dataset N (line L)".
///  - Response = record 6's response node and direction, drive = its reference node and
///    direction (1..6 → ux uy uz rx ry rz); a negative direction at either end flips the sign.
///  - Record 9 (numerator): 8 displacement (receptance), 11 velocity (mobility: H = Y / iω),
///    12 acceleration (accelerance: H = A / (iω)² = −A / ω²; "g" in the label is 9.80665 m/s²);
///    record 10 (denominator): 13 excitation force, or 0 with no label (a force in the file's
///    units); data types 0 and 1 with a units label take the quantity from it, as for time
///    responses. Units as for time responses: each axis' units label, else dataset 164, else SI.
///  - Record 8: frequency (18, or 0/1 unspecified) in Hz; even or uneven spacing; complex single
///    or double values. A mobility or accelerance line at 0 Hz is dropped (it does not give the
///    receptance there).
/// Throws io::Error naming the file, the dataset and its line, the record and field: another
/// function type, real data, a response (not a force) as the denominator or a force as the
/// numerator, a unit or axis it does not read, frequencies that are negative or do not
/// increase, non-finite values, the same response and reference twice, fewer than 2 lines.
std::vector<frf::MeasuredFunction> uff58_frfs(const std::vector<Uff58Function>& functions,
                                              const std::filesystem::path& path);

/// Records 8–11 of a channel of `quantity` at a translation or rotation: data types 13/8/11/12,
/// the exponents of the standard's Addendum A (length, force, temperature) and SI units labels
/// ("N", "N m", "m", "rad", "m/s", "rad/s", "m/s^2", "rad/s^2").
Uff58Axis uff58_axis(identify::Quantity quantity, bool rotation);

/// A record as functions to write: one real double-precision time response per channel (type 1,
/// response node and +direction of its DOF, no reference), even spacing with minimum t(0) and
/// increment Record::dt(), data types 13/8/11/12 with their Addendum A exponents and SI units
/// labels; ID line 1 is the channel's name, ID line 2 `excitation_hz = <Hz>` when the record has
/// one. Throws io::Error naming the record's source: fewer than 2 samples, a channel's length
/// differing from t's, non-finite values, sampling that is not uniform (to 1e-6 of the step).
std::vector<Uff58Function> uff58_from_record(const identify::Record& record);

} // namespace jointid::io
