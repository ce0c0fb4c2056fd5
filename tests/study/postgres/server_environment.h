#pragma once
// The real PostgreSQL server every test of lucent_store_backend_tests uses: a throwaway
// local one (study/postgres/local_server.h: initdb + pg_ctl on a Unix socket in a
// temporary folder, as `nobody` when the tests run as root), started once by a gtest
// environment before the first test and stopped after the last. Never a mock.
#include <string>

#include "study/postgres/local_server.h"

namespace lucent::test {

study::LocalPostgres& postgres_server();
// A new, empty database on it, named after `hint` (made unique); returns its URI.
std::string new_postgres_database(const std::string& hint);
// The server at `uri` brought to schema `version` only, as an older release left it:
// the first `version` migrations and lucent_schema saying so.
void migrate_server_to(const std::string& uri, int version);

}  // namespace lucent::test
