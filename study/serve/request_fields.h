#pragma once
// The fields of a `lucent serve` request, checked and bounded as they are read: a field
// that is missing, of the wrong type, too long or out of range is a RequestError (HTTP
// status and one line naming the field), never an exception from the JSON library.
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

namespace lucent::study {

// A refused request: HTTP status and one line.
struct RequestError : std::runtime_error {
    RequestError(int status, const std::string& what)
        : std::runtime_error(what), status(status) {}
    int status;
};

// Control characters become spaces, so an echoed value stays on one line.
std::string one_line(std::string text);
// As text; bytes that are not UTF-8 (echoed from a malformed request) become U+FFFD.
std::string to_text(const nlohmann::json& value);
// The field, or nullptr when absent or null.
const nlohmann::json* field(const nlohmann::json& body, const char* key);
// A string of at most `max_length` bytes ("" when absent and not required).
std::string text_field(const nlohmann::json& body, const char* key, size_t max_length,
                       bool required);
// A finite number in [lo, hi] (nullopt when absent and not required).
std::optional<double> number_field(const nlohmann::json& body, const char* key, double lo,
                                   double hi, bool required);

// Browser times: performance.now() milliseconds since the page loaded.
constexpr double kMaxPageMs = 7 * 24 * 3600e3;
inline int64_t ms_to_ns(double ms) {
    return static_cast<int64_t>(std::llround(ms * 1e6));
}

}  // namespace lucent::study
