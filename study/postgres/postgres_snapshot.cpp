// A consistent copy of the whole server as a new SQLite study file, so export, analyze
// and merge read a server as they read a file.
#include <pqxx/pqxx>

#include "study/postgres/server_connection.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

// ---- [6] snapshot --------------------------------------------------------------------

void PostgresStore::snapshot_to_sqlite(const std::string& sqlite_path) {
    // Parents before children, so every foreign key finds its row.
    static const char* const kTables[] = {"studies",
                                          "stimuli",
                                          "stimulus_parameters",
                                          "stimulus_values",
                                          "participants",
                                          "retired_participant_numbers",
                                          "sessions",
                                          "session_segments",
                                          "segment_stimuli",
                                          "trials",
                                          "responses",
                                          "adjustments",
                                          "withdrawn_sessions",
                                          "withdrawn_codes",
                                          "consent_declines",
                                          "declined_codes",
                                          "series_pictures"};
    Store out(sqlite_path);
    Database& db = out.db();
    guarded("taking a snapshot", [&] {
        // One snapshot of the whole server: stations may be writing meanwhile.
        pqxx::transaction<pqxx::repeatable_read, pqxx::read_only> tx(connection());
        Transaction write(db);
        for (const char* table : kTables) {
            std::vector<std::pair<std::string, std::string>>
                columns;  // name, declared type
            {
                Statement info =
                    db.prepare("SELECT name, type FROM pragma_table_info(?)");
                info.bind(1, table);
                while (info.step()) columns.emplace_back(info.text(0), info.text(1));
            }
            std::string names, marks;
            for (const auto& [name, type] : columns) {
                names += (names.empty() ? "" : ", ") + name;
                marks += marks.empty() ? "?" : ", ?";
            }
            Statement insert = db.prepare(std::string("INSERT INTO ") + table + " (" +
                                          names + ") VALUES (" + marks + ")");
            // Table and column names are this build's constants, never input.
            for (const pqxx::row& r : tx.exec(std::string("SELECT ") + names + " FROM " +
                                              table + " ORDER BY 1")) {
                insert.reset();
                for (pqxx::row::size_type c = 0; c < pqxx::row::size_type(columns.size());
                     ++c) {
                    const int index = static_cast<int>(c) + 1;
                    if (r[c].is_null())
                        insert.bind_null(index);
                    else if (columns[c].second == "INTEGER")
                        insert.bind(index, r[c].as<int64_t>());
                    else if (columns[c].second == "REAL")
                        insert.bind(index, r[c].as<double>());
                    else
                        insert.bind(index, std::string_view(r[c].c_str(), r[c].size()));
                }
                insert.run();
            }
        }
        write.commit();
        return 0;
    });
}

}  // namespace lucent::study
