// Two stations of one server on one machine share one journal (default_journal_path: one
// per server, machine and user). Issue 26 item 10: a station sent its new trial first and
// flushed its older journaled ones after it, and the other station's flush could send a
// trial while its own station was sending it. Now every send holds the journal's send
// lock and sends oldest first: through an outage, each session's trials reach the server
// in the order they were recorded, none is lost, none is stored twice, and neither
// station fails. Once with two stores in one process, once with two processes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "study/postgres/local_server.h"
#include "study/study_store.h"
#include "study/trial_plan.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

LocalPostgres& server() { return lucent::test::postgres_server(); }

class JournalStations : public ::testing::Test {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        dir_ = lucent::test::scratch_dir("journal_stations");
        uri_ = lucent::test::new_postgres_database("journal_" + test);
        init_study_store(uri_);
        protocol_ = lucent::test::small_protocol();
        open()->ensure_study(protocol_);
    }
    void TearDown() override {
        if (!server().running()) server().start();
    }
    // Every store of this test on one journal, as two stations of one server on one
    // machine get from default_journal_path; every failed send is retried at once.
    std::unique_ptr<StudyStore> open() {
        StoreOptions o;
        o.journal_path = (dir_ / "journal.db").string();
        o.retry_interval_ms = 0;
        return open_study_store(uri_, o);
    }

    // Pairs of trials of one session whose ratings reached the server out of the order
    // they were recorded in (recorded in plan order: position), by the responses' ids.
    int64_t out_of_order(StudyStore& store) {
        return store.query_int(
            "SELECT count(*) FROM trials t1 JOIN trials t2 ON t1.session_id = "
            "t2.session_id AND "
            "t1.position < t2.position WHERE (SELECT min(id) FROM responses r WHERE "
            "r.trial_id = "
            "t1.id) > (SELECT min(id) FROM responses r WHERE r.trial_id = t2.id)");
    }
    // Every planned trial of `sessions` sessions has one rating per question, once, and
    // every session is completed; the journal is empty.
    void expect_every_rating_once(StudyStore& store, int sessions) {
        const int64_t per_session =
            static_cast<int64_t>(plan_trials(protocol_, 1, 1).trials.size());
        const int64_t questions = static_cast<int64_t>(protocol_.questions.size());
        EXPECT_EQ(store.query_int("SELECT count(*) FROM trials"), sessions * per_session);
        EXPECT_EQ(store.query_int("SELECT count(*) FROM responses"),
                  sessions * per_session * questions);
        EXPECT_EQ(store.query_int(
                      "SELECT count(*) FROM trials t WHERE NOT EXISTS (SELECT 1 FROM "
                      "responses r WHERE r.trial_id = t.id)"),
                  0);
        EXPECT_EQ(
            store.query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
            sessions);
        EXPECT_EQ(store.pending_trials(), 0);
    }

    std::filesystem::path dir_;
    std::string uri_;
    Protocol protocol_;
};

struct Station {
    std::unique_ptr<StudyStore> store;
    int64_t session = 0;
    std::vector<TrialRow> trials;
};

Station start_station(std::unique_ptr<StudyStore> store, const Protocol& p,
                      const std::string& code, uint64_t seed) {
    Station s;
    s.store = std::move(store);
    const int64_t study = s.store->ensure_study(p);
    int number = 0;
    const int64_t participant = s.store->ensure_participant(study, code, &number);
    s.session =
        s.store
            ->create_session(study, participant, plan_trials(p, seed, number), seed, {})
            .id;
    s.trials = s.store->trials(s.session);
    return s;
}

void record(Station& s, const Protocol& p, size_t k) {
    s.store->record_trial(s.session, s.trials.at(k).id,
                          lucent::test::outcome_for(p, s.trials.at(k)));
}

TEST_F(JournalStations, TwoStoresInOneProcessSendEachSessionsTrialsInOrder) {
    Station a = start_station(open(), protocol_, "A1", 11);
    Station b = start_station(open(), protocol_, "B1", 12);
    ASSERT_GE(a.trials.size(), 5u);
    ASSERT_EQ(a.trials.size(), b.trials.size());
    record(a, protocol_, 0);
    record(b, protocol_, 0);
    // The server goes away: trials 1 and 2 of both stations wait in the shared journal.
    server().stop();
    for (size_t k : {1u, 2u}) {
        record(a, protocol_, k);
        record(b, protocol_, k);
    }
    EXPECT_EQ(a.store->pending_trials(), 4);
    server().start();
    // B's next trial: before, it reached the server before B's own trials 1 and 2.
    for (size_t k = 3; k < a.trials.size(); ++k) {
        record(b, protocol_, k);
        record(a, protocol_, k);
    }
    EXPECT_EQ(b.store->pending_trials(), 0);
    auto check = open();
    EXPECT_EQ(out_of_order(*check), 0);
    expect_every_rating_once(*check, 2);
}

// One station in a process of its own (fork; no gtest in it): it records its first trial,
// then waits for the parent at each step (the parent stops and starts the server between
// steps), and finally records the rest as fast as it can, racing the other station, and
// sends what is left. Exit 0, or 1 with the error in `error_file`.
[[noreturn]] void station_process(std::unique_ptr<StudyStore> store, const Protocol& p,
                                  const std::string& code, uint64_t seed, int to_parent,
                                  int from_parent,
                                  const std::filesystem::path& error_file) {
    try {
        Station s = start_station(std::move(store), p, code, seed);
        char byte = 0;
        record(s, p, 0);
        if (write(to_parent, "r", 1) != 1 || read(from_parent, &byte, 1) != 1) _exit(2);
        record(s, p, 1);  // the server is down: journaled
        record(s, p, 2);
        if (write(to_parent, "j", 1) != 1 || read(from_parent, &byte, 1) != 1) _exit(2);
        for (size_t k = 3; k < s.trials.size(); ++k) record(s, p, k);
        for (int attempt = 0; attempt < 100 && s.store->pending_trials() > 0; ++attempt) {
            try {
                s.store->sync();
            } catch (const StoreError&) {
                std::this_thread::sleep_for(std::chrono::milliseconds(20));
            }
        }
        if (s.store->pending_trials() != 0)
            throw StoreError(code + ": journal not empty");
    } catch (const std::exception& e) {
        std::ofstream(error_file) << e.what();
        _exit(1);
    }
    _exit(0);
}

TEST_F(JournalStations, TwoProcessesOnOneJournalSendEachSessionsTrialsInOrder) {
    struct Child {
        pid_t pid = -1;
        int from_child = -1, to_child = -1;
        std::filesystem::path error_file;
    };
    signal(SIGPIPE,
           SIG_IGN);  // a station that died: its pipe fails the test, not the process
    std::vector<Child> children(2);
    for (size_t c = 0; c < children.size(); ++c) {
        int up[2], down[2];
        ASSERT_EQ(pipe(up), 0);
        ASSERT_EQ(pipe(down), 0);
        children[c].error_file = dir_ / ("station" + std::to_string(c) + ".error");
        const pid_t pid = fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            close(up[0]);
            close(down[1]);
            std::unique_ptr<StudyStore> store;
            try {
                store = open();  // the child's own connection, after the fork
            } catch (const std::exception&) {
                _exit(3);
            }
            station_process(std::move(store), protocol_, "P" + std::to_string(c), 20 + c,
                            up[1], down[0], children[c].error_file);
        }
        close(up[1]);
        close(down[0]);
        children[c] = {pid, up[0], down[1], children[c].error_file};
    }
    const auto step = [&](char expected) {
        for (Child& c : children) {
            char byte = 0;
            EXPECT_EQ(read(c.from_child, &byte, 1), 1);
            EXPECT_EQ(byte, expected);
        }
    };
    const auto go = [&] {
        for (Child& c : children) EXPECT_EQ(write(c.to_child, "g", 1), 1);
    };
    step('r');        // each station sent its first trial
    server().stop();  // trials 1 and 2 of both wait in the shared journal
    go();
    step('j');
    server().start();
    go();  // the rest, both stations at once
    for (Child& c : children) {
        int status = 0;
        waitpid(c.pid, &status, 0);
        std::ifstream in(c.error_file);
        const std::string error((std::istreambuf_iterator<char>(in)), {});
        EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << error;
        close(c.from_child);
        close(c.to_child);
    }
    auto check = open();
    EXPECT_EQ(out_of_order(*check), 0);
    expect_every_rating_once(*check, 2);
}

}  // namespace
}  // namespace lucent::study
