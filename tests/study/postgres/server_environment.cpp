// The suite's PostgreSQL server (server_environment.h).
#include "tests/study/postgres/server_environment.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cctype>
#include <cstdint>
#include <memory>
#include <pqxx/pqxx>
#include <vector>

#include "study/postgres/postgres_store.h"
#include "study/schema.h"

namespace lucent::test {
namespace {

std::unique_ptr<study::LocalPostgres> g_server;

class ServerEnvironment : public ::testing::Environment {
public:
    void SetUp() override { g_server = std::make_unique<study::LocalPostgres>(); }
    void TearDown() override { g_server.reset(); }
};
[[maybe_unused]] const auto* const g_environment =
    ::testing::AddGlobalTestEnvironment(new ServerEnvironment);

}  // namespace

study::LocalPostgres& postgres_server() { return *g_server; }

std::string new_postgres_database(const std::string& hint) {
    static std::atomic<int> counter{0};
    std::string name = "t" + std::to_string(counter++) + "_";
    for (char c : hint.substr(0, 40))
        name += std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
    return g_server->create_database(name);
}

void migrate_server_to(const std::string& uri, int version) {
    pqxx::connection c(uri);
    pqxx::work tx(c);
    tx.exec(
        "CREATE TABLE lucent_schema (application_id BIGINT NOT NULL, version INTEGER NOT "
        "NULL)");
    const std::vector<std::string> steps = study::postgres_migrations();
    for (int v = 1; v <= version; ++v) tx.exec(steps[v - 1]);
    tx.exec_params("INSERT INTO lucent_schema VALUES ($1, $2)",
                   static_cast<int64_t>(study::kApplicationId), version);
    tx.commit();
}

}  // namespace lucent::test
