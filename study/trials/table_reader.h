#pragma once
// The protocol's TOML reader, for the protocol and every trial kind's block keys: each
// error names the file, line, column and key (ProtocolError), and a key nobody asked for
// is refused as a typo or an unsupported option.
#include <toml++/toml.h>

#include <cmath>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "study/protocol.h"

namespace lucent::study {

// Reads one TOML table, remembering which keys were used so unknown ones are reported.
class TableReader {
public:
    TableReader(const toml::table& table, std::string path, const std::string& source)
        : table_(table), path_(std::move(path)), source_(source) {}

    [[noreturn]] void fail(const toml::node* node, const std::string& key,
                           const std::string& reason) const {
        throw ProtocolError(where(node, key) + ": " + reason);
    }
    // "p.toml:12:17: key 'analysis.primary_model'": where a key was written.
    std::string where(const toml::node* node, const std::string& key) const {
        const toml::source_region& at = node ? node->source() : table_.source();
        std::ostringstream out;
        out << source_ << ":" << at.begin.line << ":" << at.begin.column << ": key '"
            << full(key) << "'";
        return out.str();
    }
    std::string full(const std::string& key) const {
        return path_.empty() ? key : path_ + "." + key;
    }
    const toml::node* get(const std::string& key) {
        used_.insert(key);
        return table_.get(key);
    }
    std::string string(const std::string& key, std::string fallback,
                       bool required = false) {
        const toml::node* node = get(key);
        if (!node) {
            if (required) fail(nullptr, key, "is required");
            return fallback;
        }
        if (!node->is_string()) fail(node, key, "must be a string");
        return std::string(*node->value<std::string>());
    }
    double number(const std::string& key, double fallback, double lo, double hi) {
        const toml::node* node = get(key);
        if (!node) return fallback;
        std::optional<double> value = node->value<double>();
        if (!value || !(node->is_integer() || node->is_floating_point()))
            fail(node, key, "must be a number");
        if (!std::isfinite(*value) || *value < lo || *value > hi) {
            std::ostringstream range;
            range << "must lie in [" << lo << ", " << hi << "], got " << *value;
            fail(node, key, range.str());
        }
        return *value;
    }
    int integer(const std::string& key, int fallback, int lo, int hi) {
        const toml::node* node = get(key);
        if (node && !node->is_integer()) fail(node, key, "must be an integer");
        return static_cast<int>(number(key, fallback, lo, hi));
    }
    bool boolean(const std::string& key, bool fallback) {
        const toml::node* node = get(key);
        if (!node) return fallback;
        if (!node->is_boolean()) fail(node, key, "must be true or false");
        return *node->value<bool>();
    }
    std::vector<std::string> strings(const std::string& key) {
        std::vector<std::string> out;
        const toml::node* node = get(key);
        if (!node) return out;
        const toml::array* array = node->as_array();
        if (!array) fail(node, key, "must be an array of strings");
        for (const toml::node& item : *array) {
            if (!item.is_string()) fail(&item, key, "must be an array of strings");
            out.emplace_back(*item.value<std::string>());
        }
        return out;
    }
    const toml::array* array(const std::string& key) {
        const toml::node* node = get(key);
        if (!node) return nullptr;
        if (!node->is_array()) fail(node, key, "must be an array");
        return node->as_array();
    }
    const toml::table* table(const std::string& key) {
        const toml::node* node = get(key);
        if (!node) return nullptr;
        if (!node->is_table()) fail(node, key, "must be a table");
        return node->as_table();
    }
    // Call after reading: any key not asked for is a typo or an unsupported option.
    void reject_unknown() const {
        for (const auto& [key, node] : table_) {
            if (!used_.count(std::string(key.str())))
                fail(&node, std::string(key.str()), "unknown key");
        }
    }
    const toml::table& raw() const { return table_; }
    const std::string& path() const { return path_; }

private:
    const toml::table& table_;
    std::string path_;
    const std::string& source_;
    std::set<std::string> used_;
};

}  // namespace lucent::study
