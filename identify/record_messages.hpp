#pragma once
/// Messages about a record's channels, worded for every format a record is read from (CSV
/// columns, UFF58 datasets), shared by the reductions of sine, periodic and sweep records.
#include "identify/record.hpp"

#include <string>

namespace jointid::identify {

/// "no force channel among its channels (x@7:uy): …" (without the record's name).
std::string no_force_channel(const Record& record);
/// "no response channel among its channels (f@7:uy): …" (without the record's name).
std::string no_response_channel(const Record& record);

} // namespace jointid::identify
