#pragma once
/// Messages about a record's channels, worded for every format a record is read from (CSV
/// columns, UFF58 datasets), and the checks of its samples, shared by the reductions of sine,
/// periodic and sweep records.
#include "identify/record.hpp"

#include <Eigen/Core>

#include <string>

namespace jointid::identify {

/// "no force channel among its channels (x@7:uy): …" (without the record's name).
std::string no_force_channel(const Record& record);
/// "no response channel among its channels (f@7:uy): …" (without the record's name).
std::string no_response_channel(const Record& record);
/// The record's channel names, "f@7:uy, x@7:uy" ("none" without channels).
std::string channel_list(const Record& record);
/// The fraction of samples sitting at the channel's extreme values (a flat top: clipping); a
/// displacement at rest (its velocity, if given, zero, as in a friction joint's stick phase)
/// is exempt.
double clipped_fraction(const Eigen::VectorXd& x, const Eigen::VectorXd* velocity = nullptr);

} // namespace jointid::identify
