#include "analysis/mixed/model_frame.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <unordered_map>

#include "analysis/data/long_table.h"  // InputError
#include "common/csv.h"
#include "common/number_text.h"

namespace lucent::analysis::mixed {

std::vector<std::string> default_level_order(const std::vector<std::string>& values) {
    std::set<std::string> distinct(values.begin(), values.end());
    std::vector<std::string> levels(distinct.begin(), distinct.end());
    const bool all_numbers = std::all_of(levels.begin(), levels.end(), [](const auto& v) {
        return common::parse_finite_number(v).has_value();
    });
    if (all_numbers)
        std::stable_sort(levels.begin(), levels.end(), [](const auto& a, const auto& b) {
            return *common::parse_finite_number(a) < *common::parse_finite_number(b);
        });
    return levels;
}

DataFrame DataFrame::read_csv(std::istream& in, const std::string& source) {
    DataFrame frame;
    frame.source_ = source;
    std::vector<std::string> header, fields;
    std::vector<std::vector<std::string>> columns;
    std::string line, record;
    std::size_t line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        const std::size_t first_line = line_no;
        record = line;
        while (!common::decode_csv_record(record, fields)) {
            if (!std::getline(in, line))
                throw InputError(source + ":" + std::to_string(first_line) +
                                 ": a quoted field is not closed");
            ++line_no;
            record += "\n" + line;
        }
        if (header.empty()) {
            if (record.empty()) continue;
            header = fields;
            columns.resize(header.size());
            std::set<std::string> seen;
            for (const auto& name : header)
                if (name.empty() || !seen.insert(name).second)
                    throw InputError(source + ":" + std::to_string(first_line) +
                                     ": column names must be distinct and not empty ('" +
                                     name + "')");
            continue;
        }
        if (record.empty() || record == "\r") continue;
        if (fields.size() != header.size())
            throw InputError(source + ":" + std::to_string(first_line) + ": expected " +
                             std::to_string(header.size()) + " fields, found " +
                             std::to_string(fields.size()));
        for (std::size_t c = 0; c < fields.size(); ++c) columns[c].push_back(fields[c]);
        frame.lines_.push_back(first_line);
    }
    if (header.empty()) throw InputError(source + ": no header line");
    frame.rows_ = frame.lines_.size();
    for (std::size_t c = 0; c < header.size(); ++c)
        frame.columns_[header[c]] = std::move(columns[c]);
    return frame;
}

DataFrame DataFrame::read_csv(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path.string() + ": cannot open for reading");
    return read_csv(in, path.string());
}

const std::vector<std::string>& DataFrame::text(const std::string& column) const {
    const auto found = columns_.find(column);
    if (found == columns_.end())
        throw InputError((source_.empty() ? std::string("table") : source_) +
                         ": no column '" + column + "'");
    return found->second;
}

std::vector<double> DataFrame::numeric(const std::string& column) const {
    const auto& values = text(column);
    std::vector<double> numbers(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
        const auto value = common::parse_finite_number(values[i]);
        if (!value)
            throw InputError(
                source_ + ":" + std::to_string(i < lines_.size() ? lines_[i] : i + 1) +
                ": column '" + column + "': '" + values[i] + "' is not a finite number");
        numbers[i] = *value;
    }
    return numbers;
}

FactorColumn DataFrame::factor(const std::string& column,
                               const std::vector<std::string>& order) const {
    const auto& values = text(column);
    FactorColumn factor;
    factor.name = column;
    factor.levels = order.empty() ? default_level_order(values) : order;
    std::unordered_map<std::string, int> index;
    for (std::size_t l = 0; l < factor.levels.size(); ++l)
        index.emplace(factor.levels[l], int(l));
    factor.codes.resize(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
        const auto found = index.find(values[i]);
        if (found == index.end())
            throw InputError(source_ + ":" +
                             std::to_string(i < lines_.size() ? lines_[i] : i + 1) +
                             ": column '" + column + "': '" + values[i] +
                             "' is not one of its levels");
        factor.codes[i] = found->second;
    }
    return factor;
}

void DataFrame::set(const std::string& column, std::vector<std::string> values) {
    if (!columns_.empty() && values.size() != rows_)
        throw InputError("column '" + column + "' has " + std::to_string(values.size()) +
                         " values for " + std::to_string(rows_) + " rows");
    rows_ = values.size();
    columns_[column] = std::move(values);
}

FixedDesign fixed_design(const DataFrame& frame, const std::vector<FixedTerm>& terms,
                         bool intercept) {
    const auto n = Eigen::Index(frame.rows());
    std::vector<Eigen::VectorXd> columns;
    FixedDesign design;
    if (intercept) {
        columns.push_back(Eigen::VectorXd::Ones(n));
        design.names.push_back("(Intercept)");
        design.term_of_column.push_back("(Intercept)");
    }
    for (const auto& term : terms) {
        if (!term.is_factor) {
            const auto values = frame.numeric(term.column);
            columns.push_back(Eigen::Map<const Eigen::VectorXd>(values.data(), n));
            design.names.push_back(term.column);
            design.term_of_column.push_back(term.column);
            continue;
        }
        const FactorColumn factor = frame.factor(term.column, term.level_order);
        for (std::size_t l = 1; l < factor.levels.size(); ++l) {
            Eigen::VectorXd indicator = Eigen::VectorXd::Zero(n);
            for (Eigen::Index i = 0; i < n; ++i)
                if (factor.codes[std::size_t(i)] == int(l)) indicator[i] = 1.0;
            columns.push_back(std::move(indicator));
            design.names.push_back(term.column + factor.levels[l]);
            design.term_of_column.push_back(term.column);
        }
    }
    design.x.resize(n, Eigen::Index(columns.size()));
    for (std::size_t c = 0; c < columns.size(); ++c)
        design.x.col(Eigen::Index(c)) = columns[c];
    return design;
}

std::vector<int> columns_of_term(const FixedDesign& design, const std::string& term) {
    std::vector<int> columns;
    for (std::size_t c = 0; c < design.term_of_column.size(); ++c)
        if (design.term_of_column[c] == term) columns.push_back(int(c));
    return columns;
}

}  // namespace lucent::analysis::mixed
