#include "analysis/data/table_records.h"

#include "analysis/data/long_table.h"

namespace lucent::analysis {

TableRecords::TableRecords(std::istream& in, std::string source)
    : in_(in), source_(std::move(source)), records_(in) {
    if (!read(header_)) throw InputError(source_ + ": empty file (no header)");
    header_line_ = records_.line();
}

bool TableRecords::read(std::vector<std::string>& fields) {
    try {
        if (records_.next(fields)) return true;
    } catch (const common::CsvError& e) {
        throw InputError(source_ + ":" + e.what());
    }
    if (in_.bad()) throw InputError(source_ + ": read error");
    return false;
}

bool TableRecords::next(std::vector<std::string>& fields) {
    if (!read(fields)) return false;
    if (fields.size() != header_.size())
        throw InputError(source_ + ":" + std::to_string(line()) + ": expected " +
                         std::to_string(header_.size()) + " fields, found " +
                         std::to_string(fields.size()));
    return true;
}

}  // namespace lucent::analysis
