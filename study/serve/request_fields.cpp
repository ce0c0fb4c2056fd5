#include "study/serve/request_fields.h"

#include <cstdio>

namespace lucent::study {

using nlohmann::json;

std::string one_line(std::string text) {
    for (char& c : text)
        if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    return text;
}

std::string to_text(const json& value) {
    return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

const json* field(const json& body, const char* key) {
    const auto it = body.find(key);
    return it == body.end() || it->is_null() ? nullptr : &*it;
}

std::string text_field(const json& body, const char* key, size_t max_length,
                       bool required) {
    const json* value = field(body, key);
    if (!value) {
        if (required)
            throw RequestError(400, std::string("field '") + key + "' is required");
        return "";
    }
    if (!value->is_string())
        throw RequestError(400, std::string("field '") + key + "' must be a string");
    const std::string& text = value->get_ref<const std::string&>();
    if (text.size() > max_length)
        throw RequestError(400, std::string("field '") + key + "' is longer than " +
                                    std::to_string(max_length) + " bytes");
    return text;
}

std::optional<double> number_field(const json& body, const char* key, double lo,
                                   double hi, bool required) {
    const json* value = field(body, key);
    if (!value) {
        if (required)
            throw RequestError(400, std::string("field '") + key + "' is required");
        return std::nullopt;
    }
    if (!value->is_number())
        throw RequestError(400, std::string("field '") + key + "' must be a number");
    const double v = value->get<double>();
    if (!std::isfinite(v) || v < lo || v > hi) {
        char range[96];
        std::snprintf(range, sizeof range, "' must lie in [%g, %g]", lo, hi);
        throw RequestError(400, std::string("field '") + key + range);
    }
    return v;
}

}  // namespace lucent::study
