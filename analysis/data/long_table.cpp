#include "data/long_table.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "data/decimal.h"

namespace lucent::analysis {
namespace {

constexpr std::array<const char*, 6> kColumns{"participant", "stimulus", "factor",
                                              "level",       "question", "rating"};

std::string location(const std::string& source, std::size_t line) {
    return source + ":" + std::to_string(line);
}

std::string format_exact(double value) {
    char buffer[32];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return error == std::errc() ? std::string(buffer, end) : std::to_string(value);
}

// Splits one CSV record into `fields`. A record without quotes (the common case) is cut
// at its commas in place: the views point into `line`, and a million rows cost no copies.
// A quoted record is decoded into `decoded` (quotes may span lines: more lines are then
// pulled from `in`).
void split_record(std::string& line, std::istream& in, std::size_t& line_no,
                  const std::string& source, std::vector<std::string>& decoded,
                  std::vector<std::string_view>& views) {
    views.clear();
    if (line.find('"') == std::string::npos) {
        for (std::size_t start = 0;;) {
            const std::size_t comma = std::min(line.find(',', start), line.size());
            views.emplace_back(line.data() + start, comma - start);
            if (comma == line.size()) return;
            start = comma + 1;
        }
    }
    std::vector<std::string>& fields = decoded;
    fields.assign(1, std::string());
    bool quoted = false;
    for (std::size_t i = 0;; ++i) {
        if (i == line.size()) {
            if (!quoted) break;
            std::string more;
            if (!std::getline(in, more))
                throw InputError(location(source, line_no) +
                                 ": unterminated quoted field");
            ++line_no;
            if (!more.empty() && more.back() == '\r') more.pop_back();
            line += "\n" + more;
        }
        if (i == line.size()) break;
        const char c = line[i];
        if (quoted) {
            if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
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
        } else {
            fields.back() += c;
        }
    }
    for (const std::string& field : fields) views.emplace_back(field);
}

std::string_view trimmed(std::string_view s) {
    const auto first = s.find_first_not_of(" \t");
    if (first == std::string_view::npos) return {};
    return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

// Rows still to come, estimated from the bytes left and one line's length, when the
// stream can tell its size (a file); 0 otherwise.
std::size_t estimated_rows(std::istream& in, std::size_t line_length) {
    const auto here = in.tellg();
    if (here < 0 || line_length == 0) return 0;
    in.seekg(0, std::ios::end);
    const auto end = in.tellg();
    in.seekg(here);
    if (end < here || !in) {
        in.clear();
        in.seekg(here);
        return 0;
    }
    return static_cast<std::size_t>(end - here) / (line_length + 1) + 16;
}

}  // namespace

RatingScale parse_scale(std::string_view text) {
    if (text == "any") return {true, 0.0, 0.0};
    const auto dots = text.find("..");
    std::optional<double> low, high;
    if (dots != std::string_view::npos) {
        low = parse_finite_number(text.substr(0, dots));
        high = parse_finite_number(text.substr(dots + 2));
    }
    if (!low || !high || !(*low < *high))
        throw InputError(
            "--scale: expected MIN..MAX with MIN < MAX (e.g. 1..7) or 'any', got '" +
            std::string(text) + "'");
    return {false, *low, *high};
}

std::string describe_scale(const RatingScale& scale) {
    if (scale.any) return "any finite number";
    return format_exact(scale.min) + ".." + format_exact(scale.max);
}

void check_scale(const LongTable& table, const RatingScale& scale,
                 const std::string& source) {
    for (const RatingRow& row : table.rows) {
        if (!row.rating) continue;
        const double value = table.origin + *row.rating;
        if (!std::isfinite(value))  // rows from a database reader arrive unparsed
            throw InputError(location(source, row.source_line) +
                             ": rating is not finite");
        if (scale.any) continue;
        if (value < scale.min || value > scale.max)
            throw InputError(location(source, row.source_line) + ": rating " +
                             format_exact(value) + " is outside the scale " +
                             describe_scale(scale) +
                             " (set it with --scale MIN..MAX, or --scale any)");
    }
}

LongTable read_long_csv(std::istream& in, const std::string& source,
                        const RatingScale& scale) {
    LongTable table;
    std::string line;
    std::size_t line_no = 0;
    std::array<int, kColumns.size()> column{};
    column.fill(-1);
    std::size_t header_fields = 0;
    std::string origin_text;
    std::vector<std::string> decoded;
    std::vector<std::string_view> fields;
    while (std::getline(in, line)) {
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // BOM
        if (trimmed(line).empty()) continue;
        split_record(line, in, line_no, source, decoded, fields);
        if (header_fields == 0) {
            // Header: find each required column by name.
            header_fields = fields.size();
            for (std::size_t f = 0; f < fields.size(); ++f)
                for (std::size_t c = 0; c < kColumns.size(); ++c)
                    if (trimmed(fields[f]) == kColumns[c])
                        column[c] = static_cast<int>(f);
            for (std::size_t c = 0; c < kColumns.size(); ++c)
                if (column[c] < 0)
                    throw InputError(location(source, line_no) +
                                     ": header lacks column '" + kColumns[c] +
                                     "' (expected participant,stimulus,factor,level,"
                                     "question,rating)");
            continue;
        }
        if (table.rows.empty()) table.rows.reserve(estimated_rows(in, line.size()));
        if (fields.size() != header_fields)
            throw InputError(location(source, line_no) + ": expected " +
                             std::to_string(header_fields) + " fields, found " +
                             std::to_string(fields.size()));
        RatingRow row;
        row.participant = trimmed(fields[column[0]]);
        row.stimulus = trimmed(fields[column[1]]);
        row.factor = trimmed(fields[column[2]]);
        row.level = trimmed(fields[column[3]]);
        row.question = trimmed(fields[column[4]]);
        row.source_line = line_no;
        if (row.factor.empty() || row.level.empty() || row.question.empty())
            throw InputError(location(source, line_no) +
                             ": factor, level and question must not be empty");
        const std::string_view rating_text = trimmed(fields[column[5]]);
        if (!rating_text.empty() && rating_text != "NA") {
            if (!parse_finite_number(rating_text))
                throw InputError(location(source, line_no) + ": rating '" +
                                 std::string(rating_text) + "' is not a finite number");
            if (origin_text.empty()) {
                origin_text = rating_text;
                table.origin = *parse_finite_number(rating_text);
            }
            row.rating = exact_difference(rating_text, origin_text);
        }
        table.rows.push_back(std::move(row));
    }
    if (header_fields == 0) throw InputError(source + ": empty file (no header)");
    // The origin is the first rating rounded to double; the stored differences are exact
    // relative to its text, so add back what that rounding dropped.
    if (!origin_text.empty()) {
        const double rounding = exact_difference(origin_text, format_exact(table.origin));
        if (rounding != 0.0)
            for (RatingRow& row : table.rows)
                if (row.rating) *row.rating += rounding;
    }
    check_scale(table, scale, source);
    return table;
}

LongTable read_long_csv(const std::filesystem::path& path, const RatingScale& scale) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot open for reading");
    return read_long_csv(in, path.string(), scale);
}

void write_long_csv(std::ostream& out, const LongTable& table) {
    auto quote = [](const std::string& s) {
        if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
        std::string q = "\"";
        for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
        return q + "\"";
    };
    out << "participant,stimulus,factor,level,question,rating\n";
    for (const RatingRow& row : table.rows) {
        out << quote(row.participant) << ',' << quote(row.stimulus) << ','
            << quote(row.factor) << ',' << quote(row.level) << ',' << quote(row.question)
            << ',';
        if (row.rating) out << format_exact(table.origin + *row.rating);
        out << '\n';
    }
}

}  // namespace lucent::analysis
