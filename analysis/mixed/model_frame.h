#pragma once
// The inputs of a mixed model, as R's model.frame and model.matrix make them: a table of
// text columns (from a CSV, or built from the long rating table), factors with their
// levels, a fixed-effects matrix with R's default treatment contrasts and R's column
// names, and grouping factors for the random effects.
#include <Eigen/Dense>
#include <cstddef>
#include <filesystem>
#include <istream>
#include <map>
#include <string>
#include <vector>

namespace lucent::analysis::mixed {

// A factor: each observation's level index. levels[0] is the reference level.
struct FactorColumn {
    std::string name;
    std::vector<std::string> levels;
    std::vector<int> codes;  // one per observation, 0 .. levels.size() - 1

    std::size_t size() const { return codes.size(); }
};

// The levels R's factor() gives by default: numeric order when every value reads as a
// number ("2" before "10"), otherwise byte order (R's C-locale sort).
std::vector<std::string> default_level_order(const std::vector<std::string>& values);

// A table with named text columns of equal length.
class DataFrame {
public:
    // Reads a CSV with a header (RFC 4180 quotes, LF or CRLF). Throws InputError naming
    // `source` and the line when a row has the wrong number of fields.
    static DataFrame read_csv(std::istream& in, const std::string& source);
    static DataFrame read_csv(const std::filesystem::path& path);

    std::size_t rows() const { return rows_; }
    bool has(const std::string& column) const { return columns_.count(column) != 0; }
    // Throws InputError naming the column (and the table's source) when it is absent.
    const std::vector<std::string>& text(const std::string& column) const;
    // Every value as a finite number; throws InputError naming source, line and column.
    std::vector<double> numeric(const std::string& column) const;
    // The column as a factor, levels in `order` (each value must be one of them) or,
    // when `order` is empty, in default_level_order.
    FactorColumn factor(const std::string& column,
                        const std::vector<std::string>& order = {}) const;
    // Adds (or replaces) a column; its length must be rows() (or the table is empty).
    void set(const std::string& column, std::vector<std::string> values);
    const std::string& source() const { return source_; }

private:
    std::string source_;
    std::size_t rows_ = 0;
    std::map<std::string, std::vector<std::string>> columns_;
    std::vector<std::size_t> lines_;  // CSV line of each row (for messages); may be empty
};

// One term of a fixed-effects formula: a factor (treatment contrasts: one indicator
// column per level after the first, named column + level as R names them, e.g.
// "tempwarm") or a numeric covariate (one column, named as the column).
struct FixedTerm {
    std::string column;
    bool is_factor = true;
    std::vector<std::string> level_order;  // factors only; empty: default_level_order
};

struct FixedDesign {
    Eigen::MatrixXd x;               // n x p
    std::vector<std::string> names;  // p column names ("(Intercept)", "tempwarm", "Days")
    // The term each column belongs to ("(Intercept)" for the intercept): tests of a
    // factor use all its columns together.
    std::vector<std::string> term_of_column;
};

FixedDesign fixed_design(const DataFrame& frame, const std::vector<FixedTerm>& terms,
                         bool intercept);

// The columns of `design` that belong to `term`.
std::vector<int> columns_of_term(const FixedDesign& design, const std::string& term);

}  // namespace lucent::analysis::mixed
