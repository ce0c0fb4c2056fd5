// RFC 4180 CSV fields (see csv.h).
#include "common/csv.h"

namespace lucent::common {

std::string csv_quoted(std::string_view text) {
    std::string out = "\"";
    for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string csv_field(std::string_view text) {
    if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
    return csv_quoted(text);
}

bool decode_csv_record(std::string_view record, std::vector<std::string>& fields,
                       BareCarriageReturn cr) {
    fields.assign(1, std::string());
    bool quoted = false;
    for (std::size_t i = 0; i < record.size(); ++i) {
        const char c = record[i];
        if (quoted) {
            if (c == '"' && i + 1 < record.size() && record[i + 1] == '"') {
                fields.back() += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                fields.back() += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            fields.emplace_back();
        } else if (c != '\r' || cr == BareCarriageReturn::keep) {
            fields.back() += c;
        }
    }
    return !quoted;
}

std::vector<std::string> split_csv_line(std::string_view line) {
    std::vector<std::string> fields;
    decode_csv_record(line, fields);
    return fields;
}

bool CsvRecordReader::next(std::vector<std::string>& fields) {
    while (std::getline(in_, line_)) {
        first_line_ = ++line_no_;
        if (first_line_ == 1 && line_.rfind("\xEF\xBB\xBF", 0) == 0) line_.erase(0, 3);
        if (line_.find_first_not_of(" \t\r") == std::string::npos) continue;
        record_ = line_;
        while (!decode_csv_record(record_, fields)) {
            if (!std::getline(in_, line_))
                throw CsvError(first_line_, std::to_string(first_line_) +
                                                ": unterminated quoted field");
            ++line_no_;
            record_ += '\n';
            record_ += line_;
        }
        return true;
    }
    return false;
}

}  // namespace lucent::common
