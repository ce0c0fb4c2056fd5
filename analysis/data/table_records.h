#pragma once
// A CSV table as the analysis's readers take it (the choices and observation tables):
// its header, then each data record with the header's number of fields. Every error is
// an InputError naming the source and line.
#include <cstddef>
#include <istream>
#include <string>
#include <vector>

#include "common/csv.h"

namespace lucent::analysis {

class TableRecords {
public:
    // Reads the header; "SOURCE: empty file (no header)" when there is none.
    TableRecords(std::istream& in, std::string source);
    const std::vector<std::string>& header() const { return header_; }
    std::size_t header_line() const { return header_line_; }
    // The next data record, false at the end ("SOURCE: read error" when the stream
    // failed); "SOURCE:LINE: expected N fields, found M" when it has another count.
    bool next(std::vector<std::string>& fields);
    std::size_t line() const { return records_.line(); }  // the record's first line

private:
    bool read(std::vector<std::string>& fields);
    std::istream& in_;
    std::string source_;
    common::CsvRecordReader records_;
    std::vector<std::string> header_;
    std::size_t header_line_ = 0;
};

}  // namespace lucent::analysis
