// Stimulus-set loader: TOML -> validated, expanded list of stimuli.
// [SECTION] ErrorReporter: "file:line:column: key: reason" from toml++ source regions
// [SECTION] knob_value(): the renderer's TOML knob reader, errors at file:line:column
// [SECTION] Loader: top-level keys, meshes, shared parameter tables, each [[stimuli]]
//           entry with its [stimuli.vary] expansion and ids
// [SECTION] public entry points
// Parameter precedence (later wins): technique defaults, [defaults], [camera], the
// stimulus's light, its material, its own keys, its [stimuli.vary] values.
#include "renderer/core/stimulus_set.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "renderer/core/knob_toml.h"

namespace lucent {
namespace {

constexpr int kMaxSide = 8192;
constexpr std::size_t kMaxStimuli = 100000;

std::string join(const std::vector<std::string>& items) {
    std::string out;
    for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
    return out;
}

// Builds "file:line:column: key: message" errors from toml++ source regions.
class ErrorReporter {
public:
    explicit ErrorReporter(std::string source) : source_(std::move(source)) {}
    [[noreturn]] void fail(const toml::source_region& where, const std::string& key,
                           const std::string& message) const {
        std::ostringstream out;
        out << source_ << ":" << where.begin.line << ":" << where.begin.column << ": ";
        if (!key.empty()) out << key << ": ";
        out << message;
        throw StimulusSetError(out.str());
    }
    [[noreturn]] void fail(const toml::node& node, const std::string& key,
                           const std::string& message) const {
        fail(node.source(), key, message);
    }

private:
    std::string source_;
};

// Rejects keys of `table` that are not in `allowed`.
void check_keys(const toml::table& table, std::initializer_list<std::string_view> allowed,
                const std::string& prefix, const ErrorReporter& errors) {
    for (auto&& [key, node] : table) {
        (void)node;
        if (std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end()) {
            std::vector<std::string> names(allowed.begin(), allowed.end());
            errors.fail(key.source(), prefix + std::string(key.str()),
                        "unknown key (valid: " + join(names) + ")");
        }
    }
}

const toml::table& as_table(const toml::node& node, const std::string& key,
                            const ErrorReporter& errors) {
    if (const auto* table = node.as_table()) return *table;
    errors.fail(node, key, "expected a table");
}

std::string as_string(const toml::node& node, const std::string& key,
                      const ErrorReporter& errors) {
    if (const auto* text = node.as_string()) return text->get();
    errors.fail(node, key, "expected a string");
}

// One TOML value for `knob` through the renderer's one TOML knob reader, its error placed
// at the value's file:line:column.
KnobValue knob_value(const Knob& knob, const toml::node& node, const std::string& key,
                     const ErrorReporter& errors) {
    try {
        return read_knob_value(knob, node);
    } catch (const KnobError& e) {
        errors.fail(node, key, e.what());
    }
}

// A parameter assignment kept with its source node until a technique is known.
struct Assignment {
    std::string key;
    const toml::node* node;
};
using Assignments = std::vector<Assignment>;

class Loader {
public:
    Loader(const SetCatalog& catalog, const std::string& source,
           std::filesystem::path base)
        : catalog_(catalog), errors_(source), base_dir_(std::move(base)) {
        for (const auto& name : catalog_.technique_names)
            if (auto knobs = catalog_.knobs_of(name))
                for (const auto& knob : *knobs) any_knob_.emplace(knob.name, knob);
    }

    StimulusSet load(const toml::table& root, const std::string& source) {
        StimulusSet set;
        set.source = source;
        check_keys(root,
                   {"name", "resolution", "formats", "meshes", "camera", "lights",
                    "materials", "defaults", "stimuli"},
                   "", errors_);
        set.name = std::filesystem::path(source).stem().string();  // unless named
        if (const auto* node = root.get("name"))
            set.name = as_string(*node, "name", errors_);
        if (const auto* node = root.get("resolution")) read_resolution(*node, set);
        if (const auto* node = root.get("formats")) read_formats(*node, set);
        read_meshes(root);
        if (const auto* node = root.get("defaults"))
            defaults_ =
                read_parameters(as_table(*node, "defaults", errors_), "defaults.", {});
        if (const auto* node = root.get("camera")) {
            const auto& camera = as_table(*node, "camera", errors_);
            check_keys(camera, {"fov_y"}, "camera.", errors_);
            camera_ = read_parameters(camera, "camera.", {});
        }
        read_named_tables(
            root, "lights", lights_,
            {"light_ambient", "light_diffuse", "light_specular", "light_direction"});
        read_named_tables(root, "materials", materials_, {});
        const auto* stimuli = root.get("stimuli");
        if (!stimuli)
            errors_.fail(root.source(), "stimuli", "missing: the set lists no stimuli");
        const auto* array = stimuli->as_array();
        if (!array || !array->is_array_of_tables())
            errors_.fail(*stimuli, "stimuli", "expected [[stimuli]] tables");
        if (array->empty()) errors_.fail(*stimuli, "stimuli", "the set lists no stimuli");
        for (std::size_t i = 0; i < array->size(); ++i)
            read_stimulus(*(*array)[i].as_table(), "stimuli[" + std::to_string(i) + "].",
                          set);
        return set;
    }

private:
    void read_resolution(const toml::node& node, StimulusSet& set) {
        const auto* array = node.as_array();
        if (!array || array->size() != 2 || !(*array)[0].is_integer() ||
            !(*array)[1].is_integer())
            errors_.fail(node, "resolution",
                         "wrong type: expected [width, height] integers");
        const auto w = (*array)[0].as_integer()->get(),
                   h = (*array)[1].as_integer()->get();
        if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide)
            errors_.fail(
                node, "resolution",
                "out of range: each side in [1, " + std::to_string(kMaxSide) + "]");
        set.width = int(w);
        set.height = int(h);
    }

    void read_formats(const toml::node& node, StimulusSet& set) {
        const auto* array = node.as_array();
        if (!array || array->empty())
            errors_.fail(node, "formats",
                         "wrong type: expected a list such as [\"png\", \"exr\"]");
        set.formats.clear();
        for (const auto& element : *array) {
            const std::string name = as_string(element, "formats", errors_);
            ImageFormat format = ImageFormat::png;
            if (name == "exr")
                format = ImageFormat::exr;
            else if (name == "tif")
                format = ImageFormat::tif;
            else if (name != "png")
                errors_.fail(element, "formats",
                             "'" + name + "' is not a format (valid: png, exr, tif)");
            if (std::find(set.formats.begin(), set.formats.end(), format) !=
                set.formats.end())
                errors_.fail(element, "formats", "'" + name + "' is listed twice");
            set.formats.push_back(format);
        }
    }

    void read_meshes(const toml::table& root) {
        const auto* node = root.get("meshes");
        if (!node)
            errors_.fail(root.source(), "meshes", "missing: name at least one mesh");
        for (auto&& [key, value] : as_table(*node, "meshes", errors_)) {
            const std::string name(key.str()), full = "meshes." + name;
            const std::string spec = as_string(value, full, errors_);
            const std::string builtin = spec.substr(0, spec.find(':'));
            const auto& names = catalog_.builtin_meshes;
            if (std::find(names.begin(), names.end(), builtin) != names.end()) {
                meshes_[name] = spec;
                continue;
            }
            std::filesystem::path path(spec);
            if (path.is_relative()) path = base_dir_ / path;
            std::error_code error;
            if (!std::filesystem::is_regular_file(path, error))
                errors_.fail(value, full,
                             "missing mesh: '" + spec + "' is neither a built-in mesh (" +
                                 join(names) + ") nor a file");
            meshes_[name] = std::filesystem::absolute(path).lexically_normal().string();
        }
        if (meshes_.empty()) errors_.fail(*node, "meshes", "name at least one mesh");
    }

    // A table of parameters; each key must be a knob of some technique (or of `only`).
    Assignments read_parameters(const toml::table& table, const std::string& prefix,
                                std::initializer_list<std::string_view> only) {
        Assignments out;
        for (auto&& [key, value] : table) {
            const std::string name(key.str());
            const auto it = any_knob_.find(name);
            const bool allowed = only.size() == 0 ||
                                 std::find(only.begin(), only.end(), name) != only.end();
            if (it == any_knob_.end() || !allowed)
                errors_.fail(key.source(), prefix + name,
                             "unknown key (not a parameter of any technique)");
            knob_value(it->second, value, prefix + name, errors_);  // type and range now
            out.push_back({name, &value});
        }
        return out;
    }

    void read_named_tables(const toml::table& root, const char* section,
                           std::map<std::string, Assignments>& into,
                           std::initializer_list<std::string_view> only) {
        const auto* node = root.get(section);
        if (!node) return;
        for (auto&& [key, value] : as_table(*node, section, errors_)) {
            const std::string prefix =
                std::string(section) + "." + std::string(key.str()) + ".";
            into[std::string(key.str())] =
                read_parameters(as_table(value, prefix, errors_), prefix, only);
        }
    }

    // Looks up a named light or material; one defined and none named means that one.
    const Assignments* lookup(const toml::table& stimulus, const char* key,
                              const std::map<std::string, Assignments>& table,
                              const std::string& prefix) {
        const auto* node = stimulus.get(key);
        if (!node) return nullptr;
        const std::string name = as_string(*node, prefix + key, errors_);
        const auto it = table.find(name);
        if (it == table.end()) {
            std::vector<std::string> names;
            for (const auto& entry : table) names.push_back(entry.first);
            errors_.fail(*node, prefix + key,
                         "unknown name '" + name + "' (defined: " +
                             (names.empty() ? "none" : join(names)) + ")");
        }
        return &it->second;
    }

    // One [[stimuli]] entry: who it is, its values in precedence order, then its
    // [stimuli.vary] expansion into one or several stimuli.
    void read_stimulus(const toml::table& table, const std::string& prefix,
                       StimulusSet& set) {
        const EntryIdentity entry = read_identity(table, prefix);
        Stimulus base =
            base_values(table, prefix, entry, read_own_parameters(table, prefix, entry));
        const Axes axes = read_vary(table, prefix, entry);
        read_motion(table, prefix, entry, axes, base);
        read_factors(table, prefix, entry, base);
        const std::string expand = read_expand(table, prefix);
        const std::size_t count = expansion_count(table, prefix, axes, expand);
        // The factor series: named, or the id pattern of an entry with several stimuli.
        std::string series = count > 1 ? entry.id : std::string();
        if (const auto* node = table.get("series")) {
            series = as_string(*node, prefix + "series", errors_);
            if (!is_safe_name(series))
                errors_.fail(
                    *node, prefix + "series",
                    "'" + series + "' is not a valid name (letters, digits, _ - . only)");
        }
        const std::vector<std::string> varies = read_varies(table, prefix, base, axes);
        const int line = int(table.source().begin.line);
        for (std::size_t index = 0; index < count; ++index) {
            Stimulus stimulus = base;
            std::size_t rest = index;
            for (auto axis = axes.rbegin(); axis != axes.rend(); ++axis) {
                const std::size_t n = axis->second.size();
                const std::size_t pick = expand == "zip" ? index : rest % n;
                rest /= n;
                stimulus.values.set(axis->first, axis->second[pick].value);
                stimulus.parameters[axis->first] = axis->second[pick].text;
            }
            stimulus.id = expanded_id(entry.id, stimulus.values, index, count);
            stimulus.series = series;
            stimulus.varies = varies;
            stimulus.source_line = line;
            check_id(stimulus.id, *entry.id_node, prefix + "id");
            set.stimuli.push_back(std::move(stimulus));
        }
    }

    // An entry's identity: id, technique (with its knobs), mesh.
    struct EntryIdentity {
        const toml::node* id_node = nullptr;
        std::string id, technique, mesh_name;
        std::vector<Knob> knobs;
    };
    EntryIdentity read_identity(const toml::table& table, const std::string& prefix) {
        EntryIdentity entry;
        entry.id_node = table.get("id");
        if (!entry.id_node) errors_.fail(table.source(), prefix + "id", "missing");
        entry.id = as_string(*entry.id_node, prefix + "id", errors_);
        const auto* technique_node = table.get("technique");
        if (!technique_node)
            errors_.fail(table.source(), prefix + "technique", "missing");
        entry.technique = as_string(*technique_node, prefix + "technique", errors_);
        auto knobs = catalog_.knobs_of(entry.technique);
        if (!knobs)
            errors_.fail(*technique_node, prefix + "technique",
                         "unknown technique '" + entry.technique +
                             "' (valid: " + join(catalog_.technique_names) + ")");
        entry.knobs = std::move(*knobs);
        if (const auto* node = table.get("mesh")) {
            entry.mesh_name = as_string(*node, prefix + "mesh", errors_);
            if (!meshes_.count(entry.mesh_name)) {
                std::vector<std::string> names;
                for (const auto& mesh : meshes_) names.push_back(mesh.first);
                errors_.fail(*node, prefix + "mesh",
                             "missing mesh '" + entry.mesh_name +
                                 "' (defined in [meshes]: " + join(names) + ")");
            }
        } else if (meshes_.size() == 1) {
            entry.mesh_name = meshes_.begin()->first;
        } else {
            errors_.fail(table.source(), prefix + "mesh",
                         "missing: several meshes are defined");
        }
        return entry;
    }

    // The knob `key` names in the entry's technique; refused at the key otherwise.
    const Knob& technique_knob(const EntryIdentity& entry, const toml::key& key,
                               const std::string& full) const {
        const Knob* knob = find_knob(entry.knobs, key.str());
        if (!knob)
            errors_.fail(
                key.source(), full,
                "unknown key (not a parameter of technique '" + entry.technique + "')");
        return *knob;
    }

    // Own parameters (every other key must be a knob of this technique).
    Assignments read_own_parameters(const toml::table& table, const std::string& prefix,
                                    const EntryIdentity& entry) {
        Assignments own;
        for (auto&& [key, value] : table) {
            const std::string name(key.str());
            if (name == "id" || name == "technique" || name == "mesh" ||
                name == "light" || name == "material" || name == "vary" ||
                name == "expand" || name == "series" || name == "varies" ||
                name == "motion" || name == "factors")
                continue;
            const Knob* knob = &technique_knob(entry, key, prefix + name);
            knob_value(*knob, value, prefix + name, errors_);
            own.push_back({name, &value});
        }
        return own;
    }

    // The entry's stimulus before its vary lists: identity, and its values in precedence
    // order; keys a technique lacks are skipped here.
    Stimulus base_values(const toml::table& table, const std::string& prefix,
                         const EntryIdentity& entry, const Assignments& own) {
        const auto* light = lookup(table, "light", lights_, prefix);
        const auto* material = lookup(table, "material", materials_, prefix);
        Stimulus base;
        base.technique = entry.technique;
        base.mesh_name = entry.mesh_name;
        base.mesh = meshes_.at(entry.mesh_name);
        for (const auto& knob : entry.knobs)
            base.values.set(knob.name, knob.default_value);
        auto apply = [&](const Assignments& assignments) {
            for (const auto& a : assignments)
                if (const Knob* knob = find_knob(entry.knobs, a.key)) {
                    base.values.set(a.key, knob_value(*knob, *a.node, a.key, errors_));
                    base.parameters[a.key] = text_of(*a.node, a.key);
                }
        };
        apply(defaults_);
        apply(camera_);
        if (light) apply(*light);
        if (material) apply(*material);
        apply(own);
        return base;
    }

    // A value's text as the stimulus keeps it (Stimulus::parameters).
    std::string text_of(const toml::node& node, const std::string& key) const {
        try {
            return parameter_text(node);
        } catch (const ParameterTextError& e) {
            errors_.fail(*e.node, key, e.what());
        }
    }

    // Expansion: [stimuli.vary] lists, each a knob with its values.
    struct AxisValue {
        KnobValue value;
        std::string text;  // as written (Stimulus::parameters)
    };
    using Axes = std::vector<std::pair<std::string, std::vector<AxisValue>>>;
    Axes read_vary(const toml::table& table, const std::string& prefix,
                   const EntryIdentity& entry) {
        Axes axes;
        const auto* vary_node = table.get("vary");
        if (!vary_node) return axes;
        // toml++ keeps keys sorted; restore the order they are written in, so the first
        // listed parameter varies slowest.
        std::vector<std::pair<const toml::key*, const toml::node*>> entries;
        for (auto&& [key, value] : as_table(*vary_node, prefix + "vary", errors_))
            entries.emplace_back(&key, &value);
        std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
            const auto& pa = a.first->source().begin;
            const auto& pb = b.first->source().begin;
            return pa.line != pb.line ? pa.line < pb.line : pa.column < pb.column;
        });
        for (const auto& [key_ptr, value_ptr] : entries) {
            const toml::key& key = *key_ptr;
            const toml::node& value = *value_ptr;
            const std::string name(key.str()), full = prefix + "vary." + name;
            const Knob* knob = &technique_knob(entry, key, full);
            const auto* list = value.as_array();
            if (!list || list->empty())
                errors_.fail(value, full,
                             "wrong type: expected a non-empty list of values");
            std::vector<AxisValue> values;
            for (const auto& element : *list)
                values.push_back(
                    {knob_value(*knob, element, full, errors_), text_of(element, full)});
            axes.emplace_back(name, std::move(values));
        }
        return axes;
    }

    // The entry's `varies`: each a parameter it sets, "technique" or "series:NAME" (as a
    // protocol's own entries say it).
    std::vector<std::string> read_varies(const toml::table& table,
                                         const std::string& prefix, const Stimulus& base,
                                         const Axes& axes) {
        std::vector<std::string> varies;
        const auto* node = table.get("varies");
        if (!node) return varies;
        const auto* list = node->as_array();
        if (!list) errors_.fail(*node, prefix + "varies", "expected a list of names");
        for (const auto& element : *list) {
            const std::string factor = as_string(element, prefix + "varies", errors_);
            const bool on_axis =
                std::any_of(axes.begin(), axes.end(),
                            [&](const auto& axis) { return axis.first == factor; });
            if (factor != "technique" && !base.parameters.count(factor) &&
                !base.factors.count(factor) && !on_axis &&
                !(factor.rfind("series:", 0) == 0 && factor.size() > 7))
                errors_.fail(element, prefix + "varies",
                             "'" + factor +
                                 "' is not a parameter or factor the entry sets (nor "
                                 "technique or series:NAME)");
            varies.push_back(factor);
        }
        return varies;
    }

    // `factors`: the experimenter's own named levels (Stimulus::factors); a name that is
    // a knob of the technique is refused, as it would be two columns of one name.
    void read_factors(const toml::table& table, const std::string& prefix,
                      const EntryIdentity& entry, Stimulus& base) {
        const auto* node = table.get("factors");
        if (!node) return;
        const std::string at = prefix + "factors";
        for (auto&& [key, value] : as_table(*node, at, errors_)) {
            const std::string name(key.str()), full = at + "." + name;
            if (find_knob(entry.knobs, name))
                errors_.fail(key.source(), full,
                             "'" + name + "' is a parameter of technique '" +
                                 entry.technique + "': set it as one, not as a factor");
            if (name == "technique" || name.find(':') != std::string::npos ||
                !is_safe_name(name))
                errors_.fail(key.source(), full,
                             "'" + name +
                                 "' is not a factor name (letters, digits, _ - . only; "
                                 "not technique)");
            base.factors[name] = text_of(value, full);
        }
    }

    // [stimuli.motion]: each a scalar knob of the technique as a function of time
    // (Stimulus::motion), not also in the vary lists; the still's value is `from`.
    void read_motion(const toml::table& table, const std::string& prefix,
                     const EntryIdentity& entry, const Axes& axes, Stimulus& base) {
        const auto* node = table.get("motion");
        if (!node) return;
        const std::string at = prefix + "motion";
        if (!catalog_.draws_motion)
            errors_.fail(*node, at,
                         "lucent does not draw moving stimuli yet; leave out "
                         "[stimuli.motion] to render the still at t = 0");
        for (auto&& [key, value] : as_table(*node, at, errors_)) {
            const std::string name(key.str()), full = at + "." + name;
            const Knob* knob = &technique_knob(entry, key, full);
            if (knob->kind != KnobKind::scalar)
                errors_.fail(key.source(), full, "only a number parameter can move");
            if (std::any_of(axes.begin(), axes.end(),
                            [&](const auto& axis) { return axis.first == name; }))
                errors_.fail(key.source(), full,
                             "'" + name + "' is in [stimuli.vary] too: a parameter " +
                                 "either varies across stimuli or moves");
            const toml::table& spec = as_table(value, full, errors_);
            check_keys(spec, {"from", "to", "period_s", "shape"}, full + ".", errors_);
            auto endpoint = [&](const char* end) -> const toml::node& {
                const toml::node* n = spec.get(end);
                if (!n) errors_.fail(spec.source(), full + "." + end, "missing");
                return *n;
            };
            // A scalar knob's value is a double (read_knob_value), checked against its
            // range.
            auto number = [&](const toml::node& n, const std::string& key) {
                const KnobValue v = knob_value(*knob, n, key, errors_);
                if (const double* d = std::get_if<double>(&v)) return *d;
                errors_.fail(n, key, "expected a number");
            };
            KnobMotion motion;
            motion.knob = name;
            const toml::node& from = endpoint("from");
            motion.from = number(from, full + ".from");
            motion.to = number(endpoint("to"), full + ".to");
            const toml::node& period = endpoint("period_s");
            const std::optional<double> seconds = period.value<double>();
            if (!period.is_number() || !seconds || !std::isfinite(*seconds) ||
                *seconds <= 0 || *seconds > 1e6)
                errors_.fail(period, full + ".period_s",
                             "out of range: a number of seconds in (0, 1e6]");
            motion.period_s = *seconds;
            if (const auto* shape = spec.get("shape")) {
                const std::string text = as_string(*shape, full + ".shape", errors_);
                if (text == "loop")
                    motion.shape = KnobMotion::Shape::loop;
                else if (text != "back_and_forth")
                    errors_.fail(*shape, full + ".shape",
                                 "'" + text +
                                     "' is out of range (valid: back_and_forth, "
                                     "loop)");
            }
            base.values.set(name, motion.from);
            base.parameters[name] = text_of(from, full + ".from");
            base.motion.push_back(std::move(motion));
        }
    }

    // "grid" (every combination of the vary lists) or "zip" (the i-th of each).
    std::string read_expand(const toml::table& table, const std::string& prefix) {
        std::string expand = "grid";
        if (const auto* node = table.get("expand")) {
            expand = as_string(*node, prefix + "expand", errors_);
            if (expand != "grid" && expand != "zip")
                errors_.fail(*node, prefix + "expand",
                             "'" + expand + "' is out of range (valid: grid, zip)");
        }
        return expand;
    }

    // How many stimuli the entry expands into (zip: lists of equal length).
    std::size_t expansion_count(const toml::table& table, const std::string& prefix,
                                const Axes& axes, const std::string& expand) {
        std::size_t count = 1;
        for (const auto& axis : axes) {
            if (expand == "zip" && axis.second.size() != axes.front().second.size())
                errors_.fail(*table.get("vary"), prefix + "vary",
                             "zip needs lists of equal length ('" + axis.first +
                                 "' has " + std::to_string(axis.second.size()) + ", '" +
                                 axes.front().first + "' has " +
                                 std::to_string(axes.front().second.size()) + ")");
            count = expand == "zip" ? axis.second.size() : count * axis.second.size();
            if (count > kMaxStimuli)
                errors_.fail(*table.get("vary"), prefix + "vary",
                             "expands to too many stimuli");
        }
        return count;
    }

    // "{key}" placeholders take the value's text; without any, expanded ids get "_N".
    static std::string expanded_id(const std::string& pattern, const KnobValues& values,
                                   std::size_t index, std::size_t count) {
        std::string out;
        bool substituted = false;
        for (std::size_t i = 0; i < pattern.size(); ++i) {
            const std::size_t close = pattern.find('}', i);
            if (pattern[i] == '{' && close != std::string::npos) {
                const std::string key = pattern.substr(i + 1, close - i - 1);
                if (values.contains(key)) {
                    out += format_knob_value(values.get(key));
                    i = close;
                    substituted = true;
                    continue;
                }
            }
            out += pattern[i];
        }
        if (count > 1 && !substituted) {
            const int width = int(std::to_string(count).size());
            std::string number = std::to_string(index + 1);
            out += "_" + std::string(std::size_t(width) - number.size(), '0') + number;
        }
        return out;
    }

    static bool is_safe_name(const std::string& name) {
        return !name.empty() && name.front() != '.' &&
               std::all_of(name.begin(), name.end(), [](char c) {
                   return std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
                          c == '-' || c == '.';
               });
    }

    void check_id(const std::string& id, const toml::node& node, const std::string& key) {
        if (!is_safe_name(id))
            errors_.fail(node, key,
                         "'" + id + "' is not a valid id (letters, digits, _ - . only)");
        // The set report writes DIR/contact-sheet.png beside the stimuli's images.
        if (id == "contact-sheet")
            errors_.fail(node, key,
                         "'contact-sheet' is reserved (the report's contact sheet)");
        if (!ids_.insert(id).second) errors_.fail(node, key, "duplicate id '" + id + "'");
    }

    const SetCatalog& catalog_;
    ErrorReporter errors_;
    std::filesystem::path base_dir_;
    std::map<std::string, Knob> any_knob_;
    std::map<std::string, std::string> meshes_;
    Assignments defaults_, camera_;
    std::map<std::string, Assignments> lights_, materials_;
    std::set<std::string> ids_;
};

}  // namespace

std::string_view image_extension(ImageFormat format) {
    switch (format) {
        case ImageFormat::png:
            return "png";
        case ImageFormat::exr:
            return "exr";
        case ImageFormat::tif:
            return "tif";
    }
    return "png";
}

StimulusSet parse_stimulus_set(std::string_view toml_text, const std::string& source_name,
                               const std::filesystem::path& base_dir,
                               const SetCatalog& catalog) {
    toml::table root;
    try {
        root = toml::parse(toml_text, source_name);
    } catch (const toml::parse_error& e) {
        ErrorReporter(source_name).fail(e.source(), "", std::string(e.description()));
    }
    return Loader(catalog, source_name, base_dir).load(root, source_name);
}

StimulusSet load_stimulus_set(const std::filesystem::path& file,
                              const SetCatalog& catalog) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw StimulusSetError(file.string() + ": cannot read the config file");
    std::ostringstream text;
    text << in.rdbuf();
    return parse_stimulus_set(text.str(), file.string(), file.parent_path(), catalog);
}

}  // namespace lucent
