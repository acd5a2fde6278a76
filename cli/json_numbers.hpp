#pragma once
/// \file
/// \brief How the commands write numbers in JSON: maps/json_numbers.hpp's one rule.

#include "maps/json_numbers.hpp"

namespace skylane::cli {

using maps::metresOrNull;
using maps::roundToMm;

}  // namespace skylane::cli
