#pragma once
// Knobs: every tunable parameter described once (name, meaning and unit, kind, range,
// default). The CLI's `--set key=value`, TOML configs, the explorer's sliders, manifests
// and `lucent bench accuracy` all read these descriptions; nothing else lists parameters.
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace lucent {

// Thrown for a bad parameter; what() is one line naming the key and the accepted range,
// e.g. "shininess: 'abc' is not a number (accepted: a number in [0, 10000])".
class KnobError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class KnobKind {
    scalar,   // one real number in [min, max]
    rgb,      // "r,g,b" or one number for grey; each channel in [min, max]
    integer,  // a whole number in [min, max]
    choice,   // one of `choices`, written as text ("5", "32f")
    vec3,     // "x,y,z"; each component in [min, max]; never the zero vector
    text,     // free text (a density spec), checked by Knob::check; stored as a string
};

// double for scalar, glm::dvec3 for rgb and vec3, int for integer, std::string for
// choice.
using KnobValue = std::variant<double, glm::dvec3, int, std::string>;
class KnobValues;

struct Knob {
    std::string name;         // canonical name, used in CLI, configs and the database
    std::string description;  // meaning and unit, one line
    KnobKind kind = KnobKind::scalar;
    double min = 0.0;  // range of a scalar / integer / each channel or component
    double max = 1.0;
    KnobValue default_value = 0.0;
    std::vector<std::string> choices;  // only for KnobKind::choice
    // KnobKind::text only: why the text is not accepted, "" when it is (may be empty).
    std::function<std::string(std::string_view)> check;
    std::string accepted;  // KnobKind::text only: what is accepted, for messages

    // A knob that names an input read from outside its own text (a density volume from
    // a generator or a file) gives that input's content hash for resolved values.
    // Manifests and study databases record it in input_hash_column(), beside the knob,
    // so a changed file under the same spec is noticed. Empty for other knobs.
    std::function<std::string(const KnobValues&)> input_hash;
    // One line on that input for resolved values (its size and statistics), or empty.
    std::function<std::string(const KnobValues&)> describe_input;
    // Where the explorer shows the knob: "" with the technique's other knobs, else a
    // panel of this name holding every knob that names it (a volume, its resolution and
    // contrast).
    std::string panel;
    // Values the explorer offers as one-click buttons (a volume's built-in generators).
    std::vector<std::string> suggestions;
};

// A KnobKind::choice knob: one of `choices` (as text), `value` by default.
Knob choice_knob(std::string name, std::string description, std::string value,
                 std::vector<std::string> choices);

// Named, validated values; lookups of a missing name or the wrong type are logic errors
// (the planner asked for a knob its technique never declared).
class KnobValues {
public:
    void set(const std::string& name, KnobValue value) {
        values_[name] = std::move(value);
    }
    bool contains(std::string_view name) const {
        return values_.find(name) != values_.end();
    }
    const KnobValue& get(std::string_view name) const;
    double scalar(std::string_view name) const;
    glm::dvec3 vec3(std::string_view name) const;  // rgb or vec3 knobs
    int integer(std::string_view name) const;
    const std::string& choice(std::string_view name) const;  // choice or text knobs
    const std::map<std::string, KnobValue, std::less<>>& all() const { return values_; }

private:
    std::map<std::string, KnobValue, std::less<>> values_;
};

// One `key=value` as written on a command line.
struct KnobAssignment {
    std::string key;
    std::string text;
};
// Splits "key=value"; throws KnobError when there is no '=' or the key is empty.
KnobAssignment parse_assignment(std::string_view key_equals_value);

// Parses text for `knob` and validates it; throws KnobError naming the key and range.
KnobValue parse_knob_value(const Knob& knob, std::string_view text);
// Checks type and range of an already typed value (for TOML and the explorer).
void validate_knob_value(const Knob& knob, const KnobValue& value);
// The value written back as text that parse_knob_value() reads back to the same value,
// each number in its shortest such form ("0.8,0.5,0.3", "0.123456789012345").
std::string format_knob_value(const KnobValue& value);
// "a number in [0, 10]", "r,g,b (or one grey value) with each in [0, 1]", "one of 1, 3,
// 5".
std::string accepted_range(const Knob& knob);

const Knob* find_knob(std::span<const Knob> knobs, std::string_view name);

// "<name>_hash": the column a knob's input hash is recorded in (Knob::input_hash).
std::string input_hash_column(const Knob& knob);
// {input_hash_column, hash} for each knob of `knobs` that names an input, in knob order.
std::vector<std::pair<std::string, std::string>> input_hashes(std::span<const Knob> knobs,
                                                              const KnobValues& values);
// Every knob at its default, then `assignments` applied in order (later wins). An
// unknown key throws KnobError listing the valid ones.
KnobValues resolve_knob_values(std::span<const Knob> knobs,
                               std::span<const KnobAssignment> assignments);

}  // namespace lucent
