#include "analysis/data/long_table.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "analysis/data/decimal.h"
#include "common/content_hash.h"
#include "common/csv.h"
#include "common/number_text.h"

namespace lucent::analysis {
namespace {

constexpr std::array<const char*, 6> kColumns{"participant", "stimulus", "factor",
                                              "level",       "question", "rating"};

std::string location(const std::string& source, std::size_t line) {
    return source + ":" + std::to_string(line);
}

// The CSV text, walked line by line without copying: a million rows cost no per-line
// allocation. `line_no` counts physical lines (a quoted field may span several).
class LineCursor {
public:
    explicit LineCursor(std::string_view text, std::size_t line_no = 0)
        : text_(text), line_no_(line_no) {}
    // The next line without its LF (and CR), or nullopt at the end.
    std::optional<std::string_view> next() {
        if (position_ >= text_.size()) return std::nullopt;
        const char* begin = text_.data() + position_;
        const void* newline = std::memchr(begin, '\n', text_.size() - position_);
        const std::size_t length = newline ? static_cast<const char*>(newline) - begin
                                           : text_.size() - position_;
        position_ += length + 1;
        ++line_no_;
        std::string_view line(begin, length);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        return line;
    }
    std::size_t line_no() const { return line_no_; }
    std::string_view rest() const {
        return text_.substr(std::min(position_, text_.size()));
    }
    // Lines after this one (at least as many as the records still to come): counted
    // once so that a million rows are placed without a reallocation.
    std::size_t lines_left() const {
        if (position_ >= text_.size()) return 0;
        return static_cast<std::size_t>(
                   std::count(text_.begin() + static_cast<std::ptrdiff_t>(position_),
                              text_.end(), '\n')) +
               1;
    }

private:
    std::string_view text_;
    std::size_t position_ = 0, line_no_ = 0;
};

// Splits one CSV record into `views`. A record without quotes (the common case) is cut
// at its commas in place: the views point into the text. A quoted record is decoded into
// `decoded` (quotes may span lines: more lines are then pulled from `lines`).
void split_record(std::string_view line, LineCursor& lines, const std::string& source,
                  std::vector<std::string>& decoded,
                  std::vector<std::string_view>& views) {
    views.clear();
    if (std::memchr(line.data(), '"', line.size()) == nullptr) {
        // Fields are short: one pass over the characters beats a memchr per field.
        const char* start = line.data();
        const char* const end = line.data() + line.size();
        for (const char* c = start; c != end; ++c)
            if (*c == ',') {
                views.emplace_back(start, c - start);
                start = c + 1;
            }
        views.emplace_back(start, end - start);
        return;
    }
    const std::size_t first_line = lines.line_no();
    std::vector<std::string>& fields = decoded;
    std::string joined(line);
    while (!common::decode_csv_record(joined, fields, common::BareCarriageReturn::keep)) {
        const auto more = lines.next();
        if (!more)
            throw InputError(location(source, first_line) +
                             ": unterminated quoted field");
        joined += '\n';
        joined += *more;
    }
    for (const std::string& field : fields) views.emplace_back(field);
}

std::string_view trimmed(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

// A whole file mapped read-only (no copy into the heap); unmapped on destruction.
class MappedFile {
public:
    explicit MappedFile(const std::filesystem::path& path) {
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) throw InputError(path.string() + ": cannot open for reading");
        struct stat info {};
        if (::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) && info.st_size > 0) {
            size_ = static_cast<std::size_t>(info.st_size);
            void* map =
                ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
            if (map != MAP_FAILED) data_ = static_cast<const char*>(map);
        }
        ::close(fd);
    }
    ~MappedFile() {
        if (data_) ::munmap(const_cast<char*>(data_), size_);
    }
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    // Empty when the file could not be mapped (empty, not regular): read it instead.
    std::optional<std::string_view> text() const {
        if (!data_) return std::nullopt;
        return std::string_view(data_, size_);
    }

private:
    const char* data_ = nullptr;
    std::size_t size_ = 0;
};

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Interns one column's texts for the parse. Long tables repeat a column's text for runs
// of rows (one participant, factor and question for many ratings), so the previous text
// is checked first; a small open-addressing table (FNV-1a, linear probing) then spares
// the shared pool's lock and std::hash's cost for the column that changes every row.
class ColumnLabels {
public:
    Label operator()(std::string_view text) {
        if (has_previous_ && text == previous_.str()) return previous_;
        if (4 * (used_ + 1) > 3 * slots_.size()) grow();
        const std::uint64_t hash = common::fnv1a_64(text);
        std::size_t at = hash & (slots_.size() - 1);
        while (slots_[at].used && !(slots_[at].hash == hash && slots_[at].label == text))
            at = (at + 1) & (slots_.size() - 1);
        if (!slots_[at].used) {
            slots_[at] = {hash, Label(text), true};
            ++used_;
        }
        previous_ = slots_[at].label;
        has_previous_ = true;
        return previous_;
    }

private:
    struct Slot {
        std::uint64_t hash = 0;
        Label label;
        bool used = false;
    };
    void grow() {
        std::vector<Slot> old(std::max<std::size_t>(64, 2 * slots_.size()));
        old.swap(slots_);
        for (const Slot& slot : old) {
            if (!slot.used) continue;
            std::size_t at = slot.hash & (slots_.size() - 1);
            while (slots_[at].used) at = (at + 1) & (slots_.size() - 1);
            slots_[at] = slot;
        }
    }
    std::vector<Slot> slots_;
    std::size_t used_ = 0;
    Label previous_;
    bool has_previous_ = false;
};

// The ratings' origin: the first rating's text (its value is what the rows store
// differences from, exactly; see parse_rows).
struct Origin {
    std::string text;
    double value = 0.0;
    std::size_t line = 0;  // where it was read, for messages
};

// "FILE:LINE: column N (rating): " for a message about one rating cell.
std::string rating_cell(const std::string& source, std::size_t line, int column) {
    return location(source, line) + ": column " + std::to_string(column + 1) +
           " (rating): ";
}

// Why a rating text is not a number the analysis takes: beyond the double range
// (1e400), or not a finite number at all ("abc", "inf").
[[noreturn]] void refuse_rating(const std::string& source, std::size_t line, int column,
                                std::string_view text) {
    std::string_view digits = text;
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
    double value = 0.0;
    const auto [end, error] =
        std::from_chars(digits.data(), digits.data() + digits.size(), value);
    const bool out_of_range =
        error == std::errc::result_out_of_range && end == digits.data() + digits.size() &&
        digits.find_first_not_of("0123456789.eE+-") == std::string_view::npos;
    throw InputError(rating_cell(source, line, column) + "rating '" + std::string(text) +
                     (out_of_range
                          ? "' is beyond the range of a double (magnitudes up to "
                            "about 1.8e308): rescale the ratings"
                          : "' is not a finite number"));
}

// The data records of a long CSV after its header, appended to `rows`. `column` gives
// each required column's field; `origin` is set by the first rating when still empty.
void parse_rows(LineCursor& lines, const std::string& source,
                const std::array<int, kColumns.size()>& column, std::size_t header_fields,
                Origin& origin, std::vector<RatingRow>& rows) {
    std::vector<std::string> decoded;
    std::vector<std::string_view> fields;
    std::array<ColumnLabels, 5> labels;
    while (const auto next = lines.next()) {
        const std::string_view line = *next;
        const std::size_t line_no = lines.line_no();
        if (trimmed(line).empty()) continue;
        split_record(line, lines, source, decoded, fields);
        if (fields.size() != header_fields)
            throw InputError(location(source, line_no) + ": expected " +
                             std::to_string(header_fields) + " fields, found " +
                             std::to_string(fields.size()));
        const std::string_view factor = trimmed(fields[column[2]]),
                               level = trimmed(fields[column[3]]),
                               question = trimmed(fields[column[4]]);
        if (factor.empty() || level.empty() || question.empty())
            throw InputError(location(source, line_no) +
                             ": factor, level and question must not be empty");
        RatingRow& row = rows.emplace_back();
        row.participant = labels[0](trimmed(fields[column[0]]));
        row.stimulus = labels[1](trimmed(fields[column[1]]));
        row.factor = labels[2](factor);
        row.level = labels[3](level);
        row.question = labels[4](question);
        row.source_line = line_no;
        const std::string_view rating_text = trimmed(fields[column[5]]);
        if (rating_text.empty() || rating_text == "NA") continue;
        if (origin.text.empty()) {
            const auto value = common::parse_finite_number(rating_text);
            if (!value) refuse_rating(source, line_no, column[5], rating_text);
            origin.text = rating_text;
            origin.value = *value;
            origin.line = line_no;
        }
        if (rating_text.size() == 1 && is_digit(rating_text[0]) &&
            origin.text.size() == 1) {
            // Every Likert rating: one digit against a one-digit origin, exact.
            row.rating = static_cast<double>(rating_text[0] - origin.text[0]);
            continue;
        }
        if (!common::parse_finite_number(rating_text))
            refuse_rating(source, line_no, column[5], rating_text);
        row.rating = exact_difference(rating_text, origin.text);
        if (!std::isfinite(*row.rating))  // 1e308 after -1e308: no double holds the gap
            throw InputError(rating_cell(source, line_no, column[5]) + "rating '" +
                             std::string(rating_text) +
                             "' lies further from the rating '" + origin.text +
                             "' (line " + std::to_string(origin.line) +
                             ") than a double can hold: ratings this far apart cannot be "
                             "analysed; rescale them");
    }
}

// The analysis sums squared deviations of the ratings (one-way and repeated-measures
// sums of squares, variances, their weights): with n ratings spanning S each such sum is
// at most n * S^2, finite while S <= sqrt(DBL_MAX / n) / 4 (headroom for the terms the
// sums combine). Ratings spread wider (1e200 next to 0) are refused naming the row, so
// that no table holds an infinity or NaN that the data did not call for.
void check_spread(const LongTable& table, const std::string& source, int column) {
    const RatingRow *low = nullptr, *high = nullptr;
    std::size_t n = 0;
    for (const RatingRow& row : table.rows) {
        if (!row.rating) continue;
        ++n;
        if (!low || *row.rating < *low->rating) low = &row;
        if (!high || *row.rating > *high->rating) high = &row;
    }
    if (n < 2) return;
    const double span = *high->rating - *low->rating;  // infinite when beyond a double
    const double limit =
        std::sqrt(std::numeric_limits<double>::max() / static_cast<double>(n)) / 4.0;
    if (span <= limit) return;
    const RatingRow& later = high->source_line > low->source_line ? *high : *low;
    const RatingRow& earlier = &later == high ? *low : *high;
    char span_text[32], limit_text[32];
    std::snprintf(span_text, sizeof span_text, "%.3g", span);
    std::snprintf(limit_text, sizeof limit_text, "%.3g", limit);
    throw InputError(
        rating_cell(source, later.source_line, column) + "the ratings span " +
        (std::isfinite(span) ? std::string(span_text) : "more than 1.8e308") +
        " (this rating and line " + std::to_string(earlier.source_line) +
        "); the sums of squares of " + std::to_string(n) +
        " ratings stay finite only up to a span of " + limit_text +
        ": rescale the ratings");
}

// Files this large are parsed in two halves at once (when they have no quoted field,
// so that every line is a record and the halves can be cut at a newline).
constexpr std::size_t kParallelParseBytes = std::size_t{4} << 20;

LongTable parse_long_csv(std::string_view text, const std::string& source,
                         const RatingScale& scale) {
    LongTable table;
    LineCursor lines(text);
    std::array<int, kColumns.size()> column{};
    column.fill(-1);
    std::size_t header_fields = 0;
    std::vector<std::string> decoded;
    std::vector<std::string_view> fields;
    while (header_fields == 0) {
        const auto next = lines.next();
        if (!next) break;
        std::string_view line = *next;
        const std::size_t line_no = lines.line_no();
        if (line_no == 1 && line.substr(0, 3) == "\xEF\xBB\xBF")
            line.remove_prefix(3);  // BOM
        if (trimmed(line).empty()) continue;
        split_record(line, lines, source, decoded, fields);
        // Header: find each required column by name.
        header_fields = fields.size();
        for (std::size_t f = 0; f < fields.size(); ++f)
            for (std::size_t c = 0; c < kColumns.size(); ++c)
                if (trimmed(fields[f]) == kColumns[c]) column[c] = static_cast<int>(f);
        for (std::size_t c = 0; c < kColumns.size(); ++c)
            if (column[c] < 0)
                throw InputError(location(source, line_no) + ": header lacks column '" +
                                 kColumns[c] +
                                 "' (expected participant,stimulus,factor,level,"
                                 "question,rating)");
    }
    if (header_fields == 0) throw InputError(source + ": empty file (no header)");
    table.rows.reserve(lines.lines_left());
    Origin origin;
    const std::string_view body = lines.rest();
    const std::size_t cut = body.size() >= kParallelParseBytes &&
                                    std::thread::hardware_concurrency() > 1 &&
                                    std::memchr(body.data(), '"', body.size()) == nullptr
                                ? body.find('\n', body.size() / 2)
                                : std::string_view::npos;
    if (cut == std::string_view::npos) {
        parse_rows(lines, source, column, header_fields, origin, table.rows);
    } else {
        // The origin first (the first rating of the file), so that both halves store
        // differences from the same text; then the second half on its own thread, its
        // line numbers counted on from the first half's.
        const std::string_view first = body.substr(0, cut + 1),
                               second = body.substr(cut + 1);
        {
            LineCursor scout(first, lines.line_no());
            std::vector<RatingRow> scratch;
            while (origin.text.empty() && scout.rest().size() > 0) {
                LineCursor one(scout.next().value(), scout.line_no() - 1);
                parse_rows(one, source, column, header_fields, origin, scratch);
            }
        }
        // The first half reads a copy: the worker may still set `origin` when the first
        // half has no rating at all.
        Origin first_origin = origin;
        std::vector<RatingRow> second_rows;
        std::exception_ptr second_error;
        const std::size_t header_lines = lines.line_no();
        std::thread worker([&] {
            try {
                const std::size_t first_lines = static_cast<std::size_t>(
                    std::count(first.begin(), first.end(), '\n'));
                second_rows.reserve(static_cast<std::size_t>(
                                        std::count(second.begin(), second.end(), '\n')) +
                                    1);
                LineCursor second_lines(second, header_lines + first_lines);
                parse_rows(second_lines, source, column, header_fields, origin,
                           second_rows);
            } catch (...) {
                second_error = std::current_exception();
            }
        });
        std::exception_ptr first_error;
        try {
            LineCursor first_lines(first, header_lines);
            parse_rows(first_lines, source, column, header_fields, first_origin,
                       table.rows);
        } catch (...) {
            first_error = std::current_exception();
        }
        worker.join();
        // The earlier line's error is the one reported, as a single pass would.
        if (first_error) std::rethrow_exception(first_error);
        if (second_error) std::rethrow_exception(second_error);
        table.rows.insert(table.rows.end(), second_rows.begin(), second_rows.end());
    }
    if (!origin.text.empty()) table.origin = origin.value;
    // The origin is the first rating rounded to double; the stored differences are exact
    // relative to its text, so add back what that rounding dropped.
    if (!origin.text.empty()) {
        const double rounding =
            exact_difference(origin.text, common::shortest_text(table.origin));
        if (rounding != 0.0)
            for (RatingRow& row : table.rows)
                if (row.rating) *row.rating += rounding;
    }
    check_scale(table, scale, source);
    check_spread(table, source, column[5]);
    return table;
}

}  // namespace

RatingScale parse_scale(std::string_view text) {
    if (text == "any") return {true, 0.0, 0.0};
    const auto dots = text.find("..");
    std::optional<double> low, high;
    if (dots != std::string_view::npos) {
        low = common::parse_finite_number(text.substr(0, dots));
        high = common::parse_finite_number(text.substr(dots + 2));
    }
    if (!low || !high || !(*low < *high))
        throw InputError(
            "--scale: expected MIN..MAX with MIN < MAX (e.g. 1..7) or 'any', got '" +
            std::string(text) + "'");
    return {false, *low, *high};
}

std::string describe_scale(const RatingScale& scale) {
    if (scale.any) return "any finite number";
    return common::shortest_text(scale.min) + ".." + common::shortest_text(scale.max);
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
                             common::shortest_text(value) + " is outside the scale " +
                             describe_scale(scale) +
                             " (set it with --scale MIN..MAX, or --scale any)");
    }
}

LongTable read_long_csv(std::istream& in, const std::string& source,
                        const RatingScale& scale) {
    std::ostringstream whole;
    whole << in.rdbuf();
    if (in.bad()) throw InputError(source + ": read error");
    return parse_long_csv(whole.view(), source, scale);
}

LongTable read_long_csv(const std::filesystem::path& path, const RatingScale& scale) {
    const MappedFile mapped(path);
    if (const auto text = mapped.text())
        return parse_long_csv(*text, path.string(), scale);
    std::ifstream in(path, std::ios::binary);  // a pipe or an empty file
    if (!in) throw InputError(path.string() + ": cannot open for reading");
    return read_long_csv(in, path.string(), scale);
}

LongTable ratings_of(const common::ObservationTable& observations,
                     const std::string& source, const RatingScale& scale) {
    LongTable table;
    const std::vector<common::FactorRating> ratings =
        common::factor_ratings(observations);
    table.rows.reserve(ratings.size());
    for (std::size_t i = 0; i < ratings.size(); ++i) {
        const common::Observation& o = *ratings[i].observation;
        table.rows.push_back({o.participant, o.shown.front(), *ratings[i].factor,
                              *ratings[i].level, o.question, o.response, i + 1});
    }
    check_scale(table, scale, source);
    return table;
}

void write_long_csv(std::ostream& out, const LongTable& table) {
    out << "participant,stimulus,factor,level,question,rating\n";
    for (const RatingRow& row : table.rows) {
        out << common::csv_field(row.participant) << ','
            << common::csv_field(row.stimulus) << ',' << common::csv_field(row.factor)
            << ',' << common::csv_field(row.level) << ','
            << common::csv_field(row.question) << ',';
        if (row.rating) out << common::shortest_text(table.origin + *row.rating);
        out << '\n';
    }
}

}  // namespace lucent::analysis
