// The suite's PostgreSQL server (server_environment.h).
#include "tests/study/postgres/server_environment.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cctype>
#include <memory>

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

}  // namespace lucent::test
