#include "renderer/core/knobs.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "common/number_text.h"

namespace lucent {
namespace {

// Numbers in messages (ranges, a refused value): 9 digits read easily.
std::string message_number(double value) { return common::nine_digit_text(value); }

std::string_view trim(std::string_view text) {
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t'))
        text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t'))
        text.remove_suffix(1);
    return text;
}

// Whole-string parse of a finite real number; nullopt-like failure through `ok`.
bool parse_real(std::string_view text, double& value) {
    text = trim(text);
    if (!text.empty() && text.front() == '+') text.remove_prefix(1);
    const auto number = common::parse_finite(text);
    if (number) value = *number;
    return number.has_value();
}

std::vector<std::string_view> split_commas(std::string_view text) {
    std::vector<std::string_view> parts;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = text.find(',', start);
        parts.push_back(text.substr(start, comma - start));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return parts;
}

[[noreturn]] void fail(const Knob& knob, const std::string& what) {
    throw KnobError(knob.name + ": " + what + " (accepted: " + accepted_range(knob) +
                    ")");
}

void check_range(const Knob& knob, double value, std::string_view text) {
    if (!std::isfinite(value) || value < knob.min || value > knob.max)
        fail(knob, "'" + std::string(text) + "' is out of range");
}

const char* kind_name(KnobKind kind) {
    switch (kind) {
        case KnobKind::scalar:
            return "a number";
        case KnobKind::rgb:
            return "an rgb colour";
        case KnobKind::integer:
            return "an integer";
        case KnobKind::choice:
            return "a choice";
        case KnobKind::vec3:
            return "a 3-vector";
        case KnobKind::text:
            return "text";
    }
    return "?";
}

}  // namespace

const KnobValue& KnobValues::get(std::string_view name) const {
    const auto it = values_.find(name);
    if (it == values_.end())
        throw std::logic_error("knob '" + std::string(name) + "' has no value");
    return it->second;
}

double KnobValues::scalar(std::string_view name) const {
    const auto& value = get(name);
    if (const double* v = std::get_if<double>(&value)) return *v;
    if (const int* v = std::get_if<int>(&value)) return *v;
    throw std::logic_error("knob '" + std::string(name) + "' is not a scalar");
}

glm::dvec3 KnobValues::vec3(std::string_view name) const {
    const auto& value = get(name);
    if (const auto* v = std::get_if<glm::dvec3>(&value)) return *v;
    throw std::logic_error("knob '" + std::string(name) + "' is not an rgb/vec3");
}

int KnobValues::integer(std::string_view name) const {
    const auto& value = get(name);
    if (const int* v = std::get_if<int>(&value)) return *v;
    throw std::logic_error("knob '" + std::string(name) + "' is not an integer");
}

const std::string& KnobValues::choice(std::string_view name) const {
    const auto& value = get(name);
    if (const auto* v = std::get_if<std::string>(&value)) return *v;
    throw std::logic_error("knob '" + std::string(name) + "' is not a choice");
}

Knob choice_knob(std::string name, std::string description, std::string value,
                 std::vector<std::string> choices) {
    return Knob{std::move(name),  std::move(description), KnobKind::choice, 0.0, 0.0,
                std::move(value), std::move(choices)};
}

KnobAssignment parse_assignment(std::string_view key_equals_value) {
    const std::size_t equals = key_equals_value.find('=');
    if (equals == std::string_view::npos)
        throw KnobError("'" + std::string(key_equals_value) + "': expected key=value");
    const std::string_view key = trim(key_equals_value.substr(0, equals));
    if (key.empty())
        throw KnobError("'" + std::string(key_equals_value) +
                        "': empty key in key=value");
    return {std::string(key), std::string(trim(key_equals_value.substr(equals + 1)))};
}

std::string accepted_range(const Knob& knob) {
    const std::string range =
        "[" + message_number(knob.min) + ", " + message_number(knob.max) + "]";
    switch (knob.kind) {
        case KnobKind::scalar:
            return "a number in " + range;
        case KnobKind::integer:
            return "an integer in " + range;
        case KnobKind::rgb:
            return "r,g,b (or one grey value) with each in " + range;
        case KnobKind::vec3:
            return "x,y,z with each in " + range + ", not all zero";
        case KnobKind::choice: {
            std::string list;
            for (const auto& c : knob.choices) list += (list.empty() ? "" : ", ") + c;
            return "one of " + list;
        }
        case KnobKind::text:
            return knob.accepted.empty() ? "text" : knob.accepted;
    }
    return "";
}

KnobValue parse_knob_value(const Knob& knob, std::string_view text) {
    text = trim(text);
    switch (knob.kind) {
        case KnobKind::scalar: {
            double value = 0;
            if (!parse_real(text, value))
                fail(knob, "'" + std::string(text) + "' is not a number");
            check_range(knob, value, text);
            return value;
        }
        case KnobKind::integer: {
            int value = 0;
            const auto [end, error] =
                std::from_chars(text.data(), text.data() + text.size(), value);
            if (text.empty() || error != std::errc() || end != text.data() + text.size())
                fail(knob, "'" + std::string(text) + "' is not an integer");
            check_range(knob, value, text);
            return value;
        }
        case KnobKind::rgb:
        case KnobKind::vec3: {
            const auto parts = split_commas(text);
            const bool grey_allowed = knob.kind == KnobKind::rgb;
            if (parts.size() != 3 && !(grey_allowed && parts.size() == 1))
                fail(knob, "'" + std::string(text) + "' needs " +
                               (grey_allowed ? "3 comma-separated numbers or 1"
                                             : "3 comma-separated numbers"));
            double c[3];
            for (std::size_t i = 0; i < parts.size(); ++i) {
                if (!parse_real(parts[i], c[i]))
                    fail(knob, "'" + std::string(trim(parts[i])) + "' is not a number");
                check_range(knob, c[i], text);
            }
            const glm::dvec3 value =
                parts.size() == 1 ? glm::dvec3(c[0]) : glm::dvec3(c[0], c[1], c[2]);
            validate_knob_value(knob, value);
            return value;
        }
        case KnobKind::choice:
            for (const auto& c : knob.choices)
                if (text == c) return c;
            fail(knob, "'" + std::string(text) + "' is not a valid choice");
        case KnobKind::text: {
            const std::string value(text);
            validate_knob_value(knob, value);
            return value;
        }
    }
    fail(knob, "unknown kind");
}

void validate_knob_value(const Knob& knob, const KnobValue& value) {
    const auto wrong_type = [&] {
        fail(knob, std::string("expected ") + kind_name(knob.kind));
    };
    switch (knob.kind) {
        case KnobKind::scalar: {
            const double* v = std::get_if<double>(&value);
            if (!v) wrong_type();
            check_range(knob, *v, message_number(*v));
            return;
        }
        case KnobKind::integer: {
            const int* v = std::get_if<int>(&value);
            if (!v) wrong_type();
            check_range(knob, *v, std::to_string(*v));
            return;
        }
        case KnobKind::rgb:
        case KnobKind::vec3: {
            const auto* v = std::get_if<glm::dvec3>(&value);
            if (!v) wrong_type();
            for (int i = 0; i < 3; ++i)
                check_range(knob, (*v)[i], format_knob_value(value));
            if (knob.kind == KnobKind::vec3 && glm::dot(*v, *v) <= 0.0)
                fail(knob, "'" + format_knob_value(value) + "' is the zero vector");
            return;
        }
        case KnobKind::choice: {
            const auto* v = std::get_if<std::string>(&value);
            if (!v) wrong_type();
            for (const auto& c : knob.choices)
                if (*v == c) return;
            fail(knob, "'" + *v + "' is not a valid choice");
        }
        case KnobKind::text: {
            const auto* v = std::get_if<std::string>(&value);
            if (!v) wrong_type();
            if (knob.check)
                if (const std::string why = knob.check(*v); !why.empty())
                    throw KnobError(knob.name + ": " + why);
            return;
        }
    }
}

std::string format_knob_value(const KnobValue& value) {
    // Every bit: manifests, databases and protocols record the double the renderer
    // received, and parse_knob_value() reads the text back to that same double.
    using common::shortest_text;
    if (const double* v = std::get_if<double>(&value)) return shortest_text(*v);
    if (const int* v = std::get_if<int>(&value)) return std::to_string(*v);
    if (const auto* v = std::get_if<std::string>(&value)) return *v;
    const auto& c = std::get<glm::dvec3>(value);
    return shortest_text(c.x) + "," + shortest_text(c.y) + "," + shortest_text(c.z);
}

const Knob* find_knob(std::span<const Knob> knobs, std::string_view name) {
    for (const auto& knob : knobs)
        if (knob.name == name) return &knob;
    return nullptr;
}

KnobValues resolve_knob_values(std::span<const Knob> knobs,
                               std::span<const KnobAssignment> assignments) {
    KnobValues values;
    for (const auto& knob : knobs) values.set(knob.name, knob.default_value);
    for (const auto& assignment : assignments) {
        const Knob* knob = find_knob(knobs, assignment.key);
        if (!knob) {
            std::string valid;
            for (const auto& k : knobs) valid += (valid.empty() ? "" : ", ") + k.name;
            throw KnobError(assignment.key + ": unknown parameter (valid: " + valid +
                            ")");
        }
        values.set(knob->name, parse_knob_value(*knob, assignment.text));
    }
    return values;
}

std::string input_hash_column(const Knob& knob) { return knob.name + "_hash"; }

std::vector<std::pair<std::string, std::string>> input_hashes(std::span<const Knob> knobs,
                                                              const KnobValues& values) {
    std::vector<std::pair<std::string, std::string>> hashes;
    for (const Knob& knob : knobs)
        if (knob.input_hash)
            hashes.emplace_back(input_hash_column(knob), knob.input_hash(values));
    return hashes;
}

}  // namespace lucent
