#include "bench_results.h"

#include <exception>
#include <ostream>

#include "output_file.h"

namespace lucent::app {

bool BenchResults::write_csv(const std::string& path) const {
    try {
        output::write_file_atomically(path, true, [&](std::ostream& out) {
            out.precision(10);
            out << "section,name,value,unit\n";
            for (const Row& r : rows)
                out << r.section << ",\"" << r.name << "\"," << r.value << ',' << r.unit
                    << '\n';
        });
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

}  // namespace lucent::app
