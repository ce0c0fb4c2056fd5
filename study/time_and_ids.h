#pragma once
// Times and identities every store writes: UTC timestamps, session and trial UUIDs, and
// the station's machine id.
#include <chrono>
#include <string>

namespace lucent::study {

// UTC as 2026-12-02T16:56:02.123Z (milliseconds), the form every stored time uses.
std::string utc_iso8601(std::chrono::system_clock::time_point t);
std::string utc_now_iso8601();
// A random (version 4) UUID.
std::string new_uuid_v4();
// /etc/machine-id, else "host:" and the host name.
std::string machine_id();

}  // namespace lucent::study
