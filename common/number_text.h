#pragma once
// Numbers as text that reads back to the same double, and the checked reading of a
// number text: tables, manifests, cache keys and the command line.
#include <optional>
#include <string>
#include <string_view>

namespace lucent::common {

// printf's "%.17g": 17 significant digits, which read back to the same double
// ("0.10000000000000001"; "inf", "-inf", "nan" as printf writes them).
std::string full_precision_text(double value);
// printf's "%.9g": 9 significant digits (every float reads back; a double to 1 part in
// 1e9), for plans, messages and manifests people read ("0.1", "1e+300", "inf", "nan").
std::string nine_digit_text(double value);
// The shortest text that reads back to the same double (std::to_chars: "0.1", "1e+300").
std::string shortest_text(double value);

// The finite number the whole text spells in decimal or exponent notation ("-1.5",
// "2e-3", ".5"), or nullopt: no blanks, no '+', no "inf" or "nan", nothing after it.
std::optional<double> parse_finite(std::string_view text);
// As parse_finite, but blanks around the number (isspace) and one leading '+' are
// allowed: " +2.5 " is 2.5.
std::optional<double> parse_finite_number(std::string_view text);

}  // namespace lucent::common
