#pragma once
// Every number a bench prints, also written to its --csv FILE as
// section,name,value,unit (one header line; sections and names quoted), so runs can be
// compared by script. Shared by the `lucent bench` subcommands.
#include <string>
#include <utility>
#include <vector>

namespace lucent::app {

struct BenchResults {
    struct Row {
        std::string section, name;
        double value;
        std::string unit;
    };
    std::vector<Row> rows;
    void add(std::string section, std::string name, double value, std::string unit) {
        rows.push_back({std::move(section), std::move(name), value, std::move(unit)});
    }
    // Writes atomically (the old file stays if anything fails); false on failure.
    bool write_csv(const std::string& path) const;
};

}  // namespace lucent::app
