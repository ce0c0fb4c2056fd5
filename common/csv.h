#pragma once
// CSV fields as RFC 4180 writes and reads them: every table Lucent writes (manifests,
// exports, analysis tables, bench results) and reads (manifests, long rating tables).
#include <cstddef>
#include <istream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace lucent::common {

// One field: as it is, or in double quotes (inner quotes doubled) when it holds a comma,
// a double quote or a line break (CR or LF).
std::string csv_field(std::string_view text);
// One field always in double quotes, inner quotes doubled.
std::string csv_quoted(std::string_view text);

// What a carriage return outside double quotes is read as.
enum class BareCarriageReturn {
    keep,  // text of the field
    drop,  // nothing: a line read by std::getline from a CRLF file ends in one
};

// Decodes the fields of one record into `fields` (at least one): commas separate fields;
// a double-quoted field may hold commas, line breaks and doubled quotes. Returns false
// when `record` ends inside a quoted field, i.e. the record goes on on the next line:
// append "\n" and that line, and decode again.
bool decode_csv_record(std::string_view record, std::vector<std::string>& fields,
                       BareCarriageReturn cr = BareCarriageReturn::drop);

// The fields of one line (as decode_csv_record, bare CRs dropped; a quote left open at
// the end of the line closes there).
std::vector<std::string> split_csv_line(std::string_view line);

// A stream ended inside a quoted field; the message names the record's first line.
class CsvError : public std::runtime_error {
public:
    CsvError(std::size_t line, const std::string& message)
        : std::runtime_error(message), line(line) {}
    std::size_t line;
};

// A CSV stream record by record, as every table reader takes it: a UTF-8 byte-order mark
// skipped, blank lines (spaces, tabs, a CR) skipped, a quoted field may span lines.
class CsvRecordReader {
public:
    explicit CsvRecordReader(std::istream& in) : in_(in) {}
    // The next record's fields, false at the end. Throws CsvError ("unterminated quoted
    // field") when the stream ends inside a quoted field.
    bool next(std::vector<std::string>& fields);
    std::size_t line() const { return first_line_; }  // the record's first line

private:
    std::istream& in_;
    std::size_t line_no_ = 0, first_line_ = 0;
    std::string line_, record_;
};

}  // namespace lucent::common
