#include "app/bench_results.h"

#include <exception>
#include <ostream>
#include <string>

#include "common/output_file.h"

namespace lucent::app {
namespace {

// A CSV field in double quotes, inner quotes doubled (RFC 4180): sections and names may
// hold commas.
std::string quoted(const std::string& text) {
    std::string out = "\"";
    for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + '"';
}

}  // namespace

bool BenchResults::write_csv(const std::string& path) const {
    try {
        common::write_file_atomically(path, true, [&](std::ostream& out) {
            out.precision(10);
            out << "section,name,value,unit\n";
            for (const Row& r : rows)
                out << quoted(r.section) << ',' << quoted(r.name) << ',' << r.value << ','
                    << r.unit << '\n';
        });
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

}  // namespace lucent::app
