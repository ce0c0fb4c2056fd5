#pragma once
// The --db argument's check: an existing study file, or a server URI (study_store.h).
#include <CLI/CLI.hpp>

#include "study/study_store.h"

namespace lucent::app {

inline CLI::Validator study_db_validator() {
    return CLI::Validator(
        [](std::string& value) -> std::string {
            if (study::is_server_uri(value)) return "";
            return CLI::ExistingFile(value);
        },
        "FILE.db|postgresql://URI");
}

}  // namespace lucent::app
