#include "renderer/core/knob_toml.h"

#include <cmath>

#include "common/number_text.h"

namespace lucent {
namespace {

// %.17g reads back to the same double, so the text below loses nothing.
std::string number_text(const toml::node& node) {
    if (node.is_integer()) return std::to_string(node.as_integer()->get());
    return common::full_precision_text(node.as_floating_point()->get());
}

}  // namespace

KnobValue read_knob_value(const Knob& knob, const toml::node& node) {
    std::string text;
    auto wrong_type = [&](const char* expected) {
        throw KnobError(std::string("wrong type: expected ") + expected +
                        " (accepted: " + accepted_range(knob) + ")");
    };
    switch (knob.kind) {
        case KnobKind::scalar:
            if (!node.is_number()) wrong_type("a number");
            text = number_text(node);
            break;
        case KnobKind::integer:
            if (!node.is_integer()) wrong_type("an integer");
            text = number_text(node);
            break;
        case KnobKind::rgb:
        case KnobKind::vec3:
            if (const auto* array = node.as_array()) {
                if (array->size() != 3) wrong_type("3 numbers");
                for (const auto& element : *array) {
                    if (!element.is_number()) wrong_type("3 numbers");
                    text += (text.empty() ? "" : ",") + number_text(element);
                }
            } else if (node.is_string()) {
                text = node.as_string()->get();
            } else if (node.is_number() && knob.kind == KnobKind::rgb) {
                text = number_text(node);
            } else {
                wrong_type(knob.kind == KnobKind::rgb ? "a number, [r, g, b] or \"r,g,b\""
                                                      : "[x, y, z] or \"x,y,z\"");
            }
            break;
        case KnobKind::text:
            if (!node.is_string()) wrong_type("a string");
            text = node.as_string()->get();
            break;
        case KnobKind::choice:
            if (node.is_string())
                text = node.as_string()->get();
            else if (node.is_integer())
                text = number_text(node);
            else
                wrong_type("a string");
            break;
    }
    try {
        return parse_knob_value(knob, text);
    } catch (const KnobError& e) {
        // The knob's message starts with its name, which the caller's key already gives.
        std::string message = e.what();
        if (message.rfind(knob.name + ": ", 0) == 0)
            message.erase(0, knob.name.size() + 2);
        throw KnobError(message);
    }
}

std::string parameter_text(const toml::node& node) {
    auto number = [](const toml::node& item) {
        const double v = *item.value<double>();
        if (!std::isfinite(v)) throw ParameterTextError(item, "must be finite");
        return common::shortest_text(v);
    };
    if (node.is_integer() || node.is_floating_point()) return number(node);
    if (node.is_string()) return std::string(*node.value<std::string>());
    if (node.is_boolean()) return *node.value<bool>() ? "true" : "false";
    if (const toml::array* array = node.as_array()) {
        std::string out;
        for (const toml::node& item : *array) {
            if (!(item.is_integer() || item.is_floating_point()))
                throw ParameterTextError(item, "array values must be numbers (r,g,b)");
            out += (out.empty() ? "" : ",") + number(item);
        }
        return out;
    }
    throw ParameterTextError(node,
                             "must be a number, string, boolean or array of numbers");
}

}  // namespace lucent
