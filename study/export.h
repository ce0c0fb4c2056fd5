#pragma once
// Data out of a study database: CSV exports (long: one row per rating; wide: one row per
// participant), the analysis long table, and merging databases from several machines.
#include <ostream>
#include <string>
#include <vector>

namespace lucent::study {

enum class ExportFormat { Long, Wide };

// Writes CSV (RFC 4180 quoting, one value per cell, never JSON) to `out`. Opens the
// database read-only after check_database_file. Returns the number of data rows.
int export_csv(const std::string& db_path, ExportFormat format, std::ostream& out);

// A row of the analysis input (issue 4): one per (rating, factor), practice and catch
// trials excluded. Columns participant,stimulus,factor,level,question,rating.
struct LongRow {
    std::string participant;
    std::string stimulus;
    std::string factor;
    std::string level;
    std::string question;
    int rating = 0;
};

struct LongTableOptions {
    // Drop participants who failed more catch trials than the protocol allows.
    bool exclude_failed_catch = true;
};

struct LongTable {
    std::vector<LongRow> rows;
    std::vector<std::string> excluded_participants;  // with the reason, "P3 (2 catch failed)"
    std::string primary_design;  // the stored protocol's [analysis] plan; "" if unreadable
};

// Factors of a stimulus: the parameters it `varies` (or all its parameters when it
// declares none); "technique" is a factor only when listed in `varies`.
LongTable analysis_long_table(const std::string& db_path, const LongTableOptions& options = {});
void write_long_table_csv(const LongTable& table, std::ostream& out);

struct MergeReport {
    int sessions_added = 0;
    int sessions_already_present = 0;  // same UUID seen in an earlier input
};

// Combines databases into `out_path` (which must not exist): sessions are de-duplicated
// by UUID; inputs holding different protocols (hashes) are refused before anything is
// written. Inputs are opened read-only and never modified.
MergeReport merge_databases(const std::vector<std::string>& inputs, const std::string& out_path);

// One CSV cell, quoted when it holds a comma, quote or line break.
std::string csv_cell(const std::string& value);

}  // namespace lucent::study
