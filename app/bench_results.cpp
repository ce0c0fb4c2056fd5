#include "app/bench_results.h"

#include <exception>
#include <ostream>
#include <string>

#include "common/csv.h"
#include "common/output_file.h"

namespace lucent::app {

bool BenchResults::write_csv(const std::string& path) const {
    try {
        common::write_file_atomically(path, true, [&](std::ostream& out) {
            out.precision(10);
            out << "section,name,value,unit\n";
            for (const Row& r : rows)
                out << common::csv_quoted(r.section) << ',' << common::csv_quoted(r.name)
                    << ',' << r.value << ',' << r.unit << '\n';
        });
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

}  // namespace lucent::app
