#include "data/decimal.h"

#include <boost/multiprecision/cpp_dec_float.hpp>
#include <cctype>
#include <charconv>
#include <cmath>
#include <string>

namespace lucent::analysis {
namespace {

std::string_view trim(std::string_view text) {
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
        text.remove_prefix(1);
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
        text.remove_suffix(1);
    return text;
}

}  // namespace

std::optional<double> parse_finite_number(std::string_view text) {
    text = trim(text);
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    if (text.empty()) return std::nullopt;
    // Only digits, one point, an exponent and signs: from_chars would accept "inf"/"nan".
    for (char c : text)
        if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == 'e' ||
              c == 'E' || c == '-' || c == '+'))
            return std::nullopt;
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
        return std::nullopt;
    return value;
}

double exact_difference(std::string_view value, std::string_view origin) {
    using Decimal = boost::multiprecision::cpp_dec_float_100;
    auto to_decimal = [](std::string_view text) {
        text = trim(text);
        if (!text.empty() && text.front() == '+') text.remove_prefix(1);
        return Decimal(std::string(text));
    };
    const Decimal difference = to_decimal(value) - to_decimal(origin);
    // Round once: through the shortest exact decimal text, parsed correctly rounded.
    const std::string text = difference.str(40, std::ios_base::scientific);
    return std::stod(text);
}

}  // namespace lucent::analysis
