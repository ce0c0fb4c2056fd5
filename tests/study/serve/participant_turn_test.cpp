// A request waiting for a participant's turn holds no store connection (issue 44, item
// 2): while a lab station holds a code and eight clients hammer /api/session for it,
// fifty other new participants are all served (no 503 from a starved pool), the hammer
// gets only 409 (the station keeps the code) or 503 (another request of the code waits
// already), and nothing of the held code is stored. Over every store backend.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "study/serve/web_study.h"
#include "study/store_pool.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using nlohmann::json;

class ServeTurn : public ::testing::TestWithParam<std::string> {};

TEST_P(ServeTurn, RequestsForAHeldCodeStarveNoOtherParticipant) {
    const auto dir = lucent::test::scratch_dir("serve_turn_" + GetParam());
    std::string db;
    if (GetParam() == "sqlite") {
        db = (dir / "study.db").string();
    } else {
        db = lucent::test::new_postgres_database("serve_turn");
        init_study_store(db);
    }
    const Protocol protocol = parse_protocol(
        std::string(lucent::test::kSmallProtocol) + "\n[screens]\nconsent = \"Agree?\"\n",
        "turn.toml");
    WebStudyOptions options;
    options.secret = "turn test secret";
    options.environment.machine_id = "server";
    options.environment.software_version = "test";
    options.environment.build_hash = "test";
    for (const Stimulus& s : protocol.stimuli) {
        StimulusProvenance p;
        p.stimulus = s.id;
        p.source = "images";
        p.technique = s.technique;
        p.mesh = "sphere";
        p.mesh_hash = "mesh-hash";
        p.values = {{"knob", "1"}};
        p.software_version = "test";
        p.build_hash = "test";
        p.file = s.id + ".png";
        p.content_hash = "content-" + s.id;
        options.environment.stimuli.push_back(p);
        options.images[s.id] = {64, 48};
    }
    // As lucent serve opens them: 4 connections on a server, 1 on a file, 2 s wait.
    StoreOptions no_journal;
    no_journal.journal = false;
    StorePool pool(db, GetParam() == "sqlite" ? 1 : 4, no_journal,
                   std::chrono::milliseconds(2000));
    WebStudy web(protocol, pool, options);  // participant_wait: the default 3 s

    StoreOptions station_options;
    station_options.journal_path = (dir / "station-journal.db").string();
    auto station = open_study_store(db, station_options);
    station->claim_participant("HELD");

    std::atomic<bool> stop{false};
    std::mutex seen_mutex;
    std::map<int, int> hammer_statuses;
    std::vector<std::thread> hammer;
    for (int i = 0; i < 8; ++i)
        hammer.emplace_back([&] {
            while (!stop) {
                const WebReply r = web.handle(
                    "session", json{{"participant", "HELD"}, {"t_ms", 1}}.dump());
                std::lock_guard lock(seen_mutex);
                ++hammer_statuses[r.status];
                std::this_thread::sleep_for(std::chrono::milliseconds(2));
            }
        });
    // The hammer has started (one of its requests waits out the station).
    while (true) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        std::lock_guard lock(seen_mutex);
        if (!hammer_statuses.empty()) break;
    }
    std::vector<int> statuses(50, 0);
    std::vector<std::thread> arrivals;
    for (int t = 0; t < 10; ++t)
        arrivals.emplace_back([&, t] {
            for (int i = t; i < 50; i += 10) {
                const WebReply r = web.handle(
                    "session",
                    json{{"participant", "N" + std::to_string(i + 1)}, {"t_ms", 1}}
                        .dump());
                statuses[i] = r.status;
            }
        });
    for (std::thread& t : arrivals) t.join();
    stop = true;
    for (std::thread& t : hammer) t.join();

    for (int i = 0; i < 50; ++i) EXPECT_EQ(statuses[i], 200) << "participant N" << i + 1;
    for (const auto& [status, n] : hammer_statuses)
        EXPECT_TRUE(status == 409 || status == 503) << n << " hammer replies " << status;
    EXPECT_EQ(station->query_int("SELECT count(*) FROM participants WHERE code = 'HELD'"),
              0);
    // The station still holds the code, and nothing else was left held.
    station->release_participant("HELD");
    auto other = open_study_store(db, station_options);
    EXPECT_NO_THROW(other->claim_participant("HELD"));
}

INSTANTIATE_TEST_SUITE_P(Stores, ServeTurn, ::testing::Values("sqlite", "postgresql"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace lucent::study
