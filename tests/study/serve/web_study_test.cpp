// lucent serve's core over every store backend (SQLite file, a real PostgreSQL server),
// driven as a browser page drives it: JSON requests, performance.now() times, the input
// events of each answer. Expected values come from the protocol (trial counts, scales,
// screen texts), the order the page was given, and the times the test chose; never from
// the server under test.
#include "study/serve/web_study.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <thread>

#include "study/postgres/postgres_store.h"
#include "study/serve/web_files.h"
#include "study/simulated_observer.h"
#include "study/sqlite/sqlite_store.h"
#include "study/store_pool.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/serve/web_page.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::direct;
using lucent::test::Page;
using lucent::test::page_rating;
using nlohmann::json;

std::string web_protocol_text() {
    return std::string(lucent::test::kSmallProtocol) +
           "\n[screens]\nconsent = \"Do you agree?\"\ninstructions = \"Rate each "
           "picture.\"\n"
           "debrief = \"Thank you.\"\n\n[online]\ncompletion_code = \"C0DE42\"\n"
           "completion_url = "
           "\"https://app.prolific.com/submissions/complete?cc=C0DE42\"\n";
}

// Trials a session of the protocol plans: practice, each block stimulus per repeat,
// catch.
size_t planned_trials(const Protocol& p) {
    size_t n = p.practice.size() + p.catch_trials.size();
    for (const Block& b : p.blocks)
        n += b.stimuli.size() * static_cast<size_t>(b.repeats);
    return n;
}

class Serve : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::string slug;
        for (char c : test)
            slug +=
                std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
        dir_ = lucent::test::scratch_dir("serve_" + slug);
        if (GetParam() == "sqlite") {
            db_ = (dir_ / "study.db").string();
        } else {
            db_ = lucent::test::new_postgres_database("serve_" + slug);
            init_study_store(db_);
        }
        protocol_ = parse_protocol(web_protocol_text(), "web.toml");
        start_server();
    }
    // A new, empty store with another protocol (the fixture's store holds one protocol).
    void use_protocol(const std::string& text, const std::string& name) {
        web_.reset();
        store_.reset();
        if (GetParam() == "sqlite") {
            db_ = (dir_ / (name + ".db")).string();
        } else {
            db_ = lucent::test::new_postgres_database(name);
            init_study_store(db_);
        }
        protocol_ = parse_protocol(text, name + ".toml");
        start_server();
    }
    void start_server() {
        web_.reset();
        store_.reset();
        store_ = open_store("journal");
        WebStudyOptions o;
        o.secret = "test secret";
        o.environment.machine_id = "server-machine";
        o.environment.software_version = "test";
        o.environment.build_hash = "test";
        // What each segment shows: one segment_stimuli row per stimulus.
        for (const Stimulus& s : protocol_.stimuli) {
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
            o.environment.stimuli.push_back(p);
        }
        for (const Stimulus& s : protocol_.stimuli) o.images[s.id] = {64, 48};
        o.idle_timeout = std::chrono::minutes(30);
        o.clock = [this] { return now_; };
        o.participant_wait = std::chrono::milliseconds(300);
        options_ = o;
        web_ = std::make_unique<WebStudy>(protocol_, *store_, o);
    }
    // Another connection to the same store (a lab station, a second serve process).
    std::unique_ptr<StudyStore> open_store(const std::string& journal) {
        StoreOptions options;
        options.journal_path = (dir_ / (journal + ".db")).string();
        options.retry_interval_ms = 0;
        return open_study_store(db_, options);
    }
    int64_t count(const std::string& sql) { return store_->query_int(sql); }
    int64_t responses() { return count("SELECT count(*) FROM responses"); }

    std::filesystem::path dir_;
    std::string db_;
    Protocol protocol_;
    std::unique_ptr<StudyStore> store_;
    WebStudyOptions options_;
    std::unique_ptr<WebStudy> web_;
    // The server's wall clock: the real time until a test moves it on.
    std::chrono::system_clock::time_point now_ = std::chrono::system_clock::now();
};

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    return info.param;
}

TEST_P(Serve, APageCompletesTheWholeProtocolAndEveryAnswerIsStoredAsSent) {
    Page page{direct(*web_)};
    page.open({{"participant", "P1"}});
    ASSERT_EQ(page.state["screen"], "consent");
    EXPECT_EQ(page.state["text"], "Do you agree?");
    ASSERT_EQ(page.token.rfind("P1.", 0), 0u);
    page.enter();
    EXPECT_EQ(page.state["screen"], "instructions");
    EXPECT_EQ(page.state["text"], "Rate each picture.");
    std::vector<std::string> screens;
    for (int guard = 0; guard < 100 && page.state["screen"] != "done"; ++guard) {
        screens.push_back(page.state["screen"]);
        if (page.state["screen"] == "trial")
            page.answer(static_cast<int>(page.shown.size()));
        else
            page.enter();
    }
    ASSERT_EQ(page.state["screen"], "done");
    EXPECT_EQ(page.state["completion"]["code"], "C0DE42");
    EXPECT_EQ(page.state["completion"]["url"],
              "https://app.prolific.com/submissions/complete?cc=C0DE42");

    // Every planned trial shown once, in the stored order; practice first, then the
    // practice-done screen; the break after every 2 main trials; the debrief last.
    const size_t n = planned_trials(protocol_);
    ASSERT_EQ(page.shown.size(), n);
    EXPECT_EQ(std::set<std::string>(page.shown.begin(), page.shown.end()).size(), n);
    const std::optional<SessionRow> none = store_->unfinished_session("P1");
    EXPECT_FALSE(none);
    EXPECT_TRUE(store_->has_completed_session("P1"));
    const int64_t session = count("SELECT id FROM sessions");
    const std::vector<TrialRow> trials = store_->trials(session);
    ASSERT_EQ(trials.size(), n);
    std::vector<std::string> expected_screens = {"instructions"};
    for (size_t k = 0; k < n; ++k) {
        EXPECT_EQ(trials[k].uuid, page.shown[k]) << "trial " << k;
        if (k > 0 && trials[k - 1].practice && !trials[k].practice)
            expected_screens.push_back("practice_done");
        else if (trials[k].break_before)
            expected_screens.push_back("break");
        expected_screens.push_back("trial");
    }
    expected_screens.push_back("debrief");
    EXPECT_EQ(screens, expected_screens);

    // Ratings as clicked, RT from the onset to the final click (100 ms per question).
    EXPECT_EQ(responses(), static_cast<int64_t>(n * protocol_.questions.size()));
    for (size_t k = 0; k < n; ++k)
        for (size_t q = 0; q < protocol_.questions.size(); ++q) {
            const int rating = page_rating(int(k), int(q), trials[k].is_catch);
            EXPECT_EQ(
                count(
                    "SELECT count(*) FROM responses r JOIN trials t ON t.id = r.trial_id "
                    "WHERE t.uuid = '" +
                    trials[k].uuid + "' AND r.question = '" + protocol_.questions[q].id +
                    "' AND r.rating = " + std::to_string(rating) + " AND abs(r.rt_ms - " +
                    std::to_string(100 * (q + 1)) + ") < 0.001 AND r.changes = 0"),
                1)
                << "trial " << k << " question " << q;
        }
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed' AND "
                    "consent_utc IS NOT NULL"),
              1);
    // The browser's details on the session's segment.
    EXPECT_EQ(
        count("SELECT count(*) FROM session_segments WHERE gl_vendor = 'web browser' "
              "AND gl_renderer = 'TestBrowser/1.0' AND display_mode = 'browser window "
              "1280x900 CSS px, devicePixelRatio 2, screen 2560x1440' AND "
              "machine_id = 'server-machine'"),
        1);
    {
        // Nothing holds the participant between requests: a lab station may claim them.
        auto station = open_store("station");
        EXPECT_NO_THROW(station->claim_participant("P1"));
    }
    // A return after completion shows the completion page and starts nothing.
    Page again{direct(*web_)};
    again.open({{"participant", "P1"}});
    EXPECT_EQ(again.state["screen"], "done");
    EXPECT_EQ(again.state["already_completed"], true);
    EXPECT_EQ(count("SELECT count(*) FROM sessions"), 1);
}

TEST_P(Serve, TheRefreshEstimateIsStoredWithTheSegment) {
    Page page{direct(*web_)};
    page.open({{"participant", "P2"}});
    page.call("environment", {{"refresh_hz", 59.94}});
    // Kept in memory on the consent screen; stored with the segment once they agree.
    EXPECT_EQ(count("SELECT count(*) FROM session_segments"), 0);
    page.enter();
    EXPECT_EQ(
        count("SELECT count(*) FROM session_segments WHERE abs(measured_refresh_hz - "
              "59.94) < 1e-9"),
        1);
    page.call("environment", {{"refresh_hz", 120}});
    EXPECT_EQ(
        count("SELECT count(*) FROM session_segments WHERE abs(measured_refresh_hz - "
              "120) < 1e-9"),
        1);
    page.call("environment", {{"refresh_hz", 0}}, 400);
    page.call("environment", {{"refresh_hz", "fast"}}, 400);
}

TEST_P(Serve, ProlificIdsNameTheParticipantAndAreStored) {
    Page page{direct(*web_)};
    page.open({{"prolific",
                {{"PROLIFIC_PID", "5f1a2b3c4d5e6f7a8b9c0d1e"},
                 {"STUDY_ID", "60aabbccddeeff0011223344"},
                 {"SESSION_ID", "abc123XYZ"}}}});
    EXPECT_EQ(page.state["screen"], "consent");
    EXPECT_EQ(page.token.rfind("5f1a2b3c4d5e6f7a8b9c0d1e.", 0), 0u);
    // Nothing of them is stored before they agree (issue 26 item 5).
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 0);
    page.enter();
    EXPECT_EQ(
        count(
            "SELECT count(*) FROM participants WHERE code = '5f1a2b3c4d5e6f7a8b9c0d1e'"),
        1);
    EXPECT_EQ(
        count("SELECT count(*) FROM session_segments WHERE display_mode LIKE "
              "'%; Prolific STUDY_ID=60aabbccddeeff0011223344 SESSION_ID=abc123XYZ'"),
        1);
    Page other{direct(*web_)};
    other.open({{"participant", "someone"}, {"prolific", {{"PROLIFIC_PID", "else"}}}},
               400);
    other.open({{"prolific", {{"PROLIFIC_PID", "x"}, {"STUDY_ID", "a/b"}}}}, 400);
}

TEST_P(Serve, AReloadOrARestartResumesAtTheFirstUnansweredTrialOnlyWithTheToken) {
    std::string token;
    std::vector<std::string> shown;
    {
        Page page{direct(*web_)};
        page.open({{"participant", "P3"}});
        page.run(3);
        ASSERT_EQ(page.shown.size(), 3u);
        token = page.token;
        shown = page.shown;
    }
    const int64_t session = count("SELECT id FROM sessions");
    const std::vector<TrialRow> trials = store_->trials(session);
    // Someone else with the code but not the key: refused, nothing changes.
    Page stranger{direct(*web_)};
    stranger.open({{"participant", "P3"}}, 403);
    // The last character changed (a token that ends in '0' must not be "forged" into
    // itself: that made this test fail one run in sixteen).
    std::string forged = token;
    forged.back() = forged.back() == '0' ? '1' : '0';
    stranger.open({{"participant", "P3"}, {"token", forged}}, 403);
    EXPECT_EQ(count("SELECT count(*) FROM session_segments"), 1);

    auto resume = [&](int segments) {
        Page page{direct(*web_)};
        page.token = token;
        page.open({{"participant", "P3"}, {"token", token}});
        // Consent is on record: straight to the first unanswered trial (the 4th).
        EXPECT_EQ(page.state["screen"], "trial");
        EXPECT_EQ(page.state["trial"]["id"], trials[3].uuid);
        EXPECT_EQ(count("SELECT count(*) FROM session_segments"), segments);
        return page;
    };
    resume(2);       // a reload: segment 1 holds answers, so segment 2 begins
    start_server();  // the server restarted: the token still holds
    // Nothing was answered in segment 2: the reload replaces it rather than adding one.
    Page page = resume(2);
    page.shown = shown;
    page.run();
    EXPECT_EQ(page.state["screen"], "done");
    EXPECT_EQ(responses(), static_cast<int64_t>(planned_trials(protocol_) *
                                                protocol_.questions.size()));
}

// The hostile requests of issue 16: each a 4xx with one line, and nothing stored.
TEST_P(Serve, HostileRequestsAreRefusedWithOneLineAndStoreNothing) {
    Page page{direct(*web_)};
    page.open({{"participant", "P4"}});
    page.run(1);  // consent, instructions, the practice trial
    Page other{direct(*web_)};
    other.open({{"participant", "P5"}});
    other.run(1);
    while (page.state["screen"] != "trial") page.enter();
    const int64_t stored = responses();
    const int64_t answered =
        count("SELECT count(*) FROM trials WHERE answered_utc IS NOT NULL");
    auto refused = [&](const std::string& endpoint, const std::string& body, int status,
                       const std::string& reason) {
        const WebReply r = web_->handle(endpoint, body);
        EXPECT_EQ(r.status, status) << body << " -> " << r.body;
        const json reply = json::parse(r.body, nullptr, false);
        ASSERT_TRUE(reply.is_object() && reply.contains("error")) << r.body;
        const std::string line = reply["error"];
        EXPECT_EQ(line.find('\n'), std::string::npos);
        EXPECT_NE(line.find(reason), std::string::npos) << line;
        EXPECT_EQ(responses(), stored) << body;
    };
    auto with = [&](const std::function<void(json&)>& edit) {
        json body = page.answer_body(1);
        body["token"] = page.token;
        edit(body);
        return body.dump();
    };
    refused("answer", with([](json& b) { b["events"][0]["value"] = 0; }), 400,
            "rating 0 is outside 1..7");
    refused("answer", with([](json& b) { b["events"][0]["value"] = 8; }), 400,
            "rating 8 is outside 1..7");
    refused("answer", with([](json& b) { b["events"][0]["value"] = 2.5; }), 400,
            "outside 1..7");
    refused("answer", with([](json& b) { b["events"][0]["question"] = 2; }), 400,
            "question index 2");
    refused("answer", with([](json& b) {
                b["events"][0] = {{"t_ms", 1e4}, {"type", "key"}, {"key", "8"}};
            }),
            400, "key '8' is outside every scale");
    refused("answer", with([](json& b) {
                b["events"][0] = {{"t_ms", 1e4}, {"type", "key"}, {"key", "Escape"}};
            }),
            400, "unknown key");
    refused("answer", with([](json& b) { b["events"].erase(b["events"].size() - 1); }),
            400, "do not rate every question and confirm");
    // Answered before the picture was on screen (events stamped before the onset).
    refused("answer", with([](json& b) {
                for (json& e : b["events"]) e["t_ms"] = b["onset_ms"].get<double>() - 1;
            }),
            400, "do not rate every question");
    refused("answer", with([](json& b) { b["onset_ms"] = 0; }), 400, "blank ended");
    refused("answer", with([](json& b) { b["events"][0]["t_ms"] = nullptr; }), 400,
            "'t_ms' is required");
    refused("answer", with([](json& b) { b["events"][0]["t_ms"] = -5; }), 400,
            "'t_ms' must lie in");
    refused("answer", with([](json& b) {
                b["events"] = json::array();
                for (int i = 0; i < 600; ++i)
                    b["events"].push_back({{"t_ms", 1}, {"type", "next"}});
            }),
            400, "more than 500 events");
    {
        // An answer to a trial already answered (a retry after a lost reply, perhaps
        // through another serve process) is stored once: 200, the page where it stands.
        const WebReply again =
            web_->handle("answer", with([&](json& b) { b["trial"] = page.shown[0]; }));
        EXPECT_EQ(again.status, 200) << again.body;
        const json reply = json::parse(again.body);
        EXPECT_EQ(reply["already_answered"], true);
        EXPECT_EQ(reply["view"], page.state["view"]);
        EXPECT_EQ(responses(), stored);
    }
    refused("answer", with([&](json& b) { b["trial"] = other.shown[0]; }), 404,
            "not one of this session's trials");
    refused("answer", with([&](json& b) { b["token"] = other.token; }), 404,
            "not one of this session's trials");
    refused("answer", with([&](json& b) { b["view"] = b["view"].get<int>() + 7; }), 409,
            "no longer shown");
    refused("answer", with([&](json& b) { b["token"] = "P4.0000"; }), 403,
            "unknown session token");
    refused("answer", with([&](json& b) { b["token"] = "../../etc.x"; }), 403,
            "unknown session token");
    refused("answer", "{\"token\": ", 400, "malformed JSON");
    refused("answer", "[1, 2]", 400, "must be a JSON object");
    refused("answer", "{\"token\": \"\xff\xfe\"}", 400, "malformed JSON");  // not UTF-8
    refused("answer", "{\"token\": 5}", 400, "'token' must be a string");
    refused("answer", std::string(70 * 1024, ' '), 413, "over the limit");
    refused("answer", with([](json& b) { b["trial"] = std::string(5000, 'a'); }), 400,
            "longer than");
    refused("wipe", "{}", 404, "no API endpoint");
    refused("continue",
            json{{"token", page.token},
                 {"view", page.state["view"]},
                 {"shown_ms", 1},
                 {"t_ms", 2}}
                .dump(),
            409, "not continued with Enter");
    for (const std::string& code :
         std::vector<std::string>{"", "a b", "../P1", "P1;DROP TABLE", "<script>",
                                  std::string(65, 'x'), "P\xc3\xa9"})
        refused("session", json{{"participant", code}, {"t_ms", 1}}.dump(), 400,
                "participant code");
    refused("session", json{{"t_ms", 1}}.dump(), 400, "no participant code");
    refused("session",
            json{{"participant", "P9"},
                 {"t_ms", 1},
                 {"client", {{"user_agent", std::string(600, 'u')}}}}
                .dump(),
            400, "'user_agent' is longer than 512");
    EXPECT_EQ(count("SELECT count(*) FROM trials WHERE answered_utc IS NOT NULL"),
              answered);
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 2);
    // The page still answers its trial afterwards: nothing above changed its state.
    page.answer(1);
    EXPECT_EQ(responses(), stored + static_cast<int64_t>(protocol_.questions.size()));
}

TEST_P(Serve, TheConsentScreenCanBeDeclinedAndADoubleEnterActsOnce) {
    Page page{direct(*web_)};
    page.open({{"participant", "P6"}});
    const json consent = page.state;
    page.enter();  // agreed; on the instructions now
    // The same Enter again (a double press, a second tab): the view it names is gone.
    const WebReply again = web_->handle("continue", json{{"token", page.token},
                                                         {"view", consent["view"]},
                                                         {"shown_ms", 1},
                                                         {"t_ms", 2}}
                                                        .dump());
    EXPECT_EQ(again.status, 409);
    EXPECT_EQ(page.state["screen"], "instructions");
    // A key stamped before its screen was shown counts for nothing.
    const WebReply early = web_->handle("continue", json{{"token", page.token},
                                                         {"view", page.state["view"]},
                                                         {"shown_ms", 5000},
                                                         {"t_ms", 4000}}
                                                        .dump());
    EXPECT_EQ(early.status, 400) << early.body;

    Page no{direct(*web_)};
    no.open({{"participant", "P7"}});
    const json declined =
        no.call("decline", {{"view", no.state["view"]}, {"shown_ms", 60}, {"t_ms", 900}});
    EXPECT_EQ(declined["screen"], "declined");
    // Declined: no participant, no session; only the code, salted and hashed, counted
    // (issue 26 item 5, issue 44 item 5).
    EXPECT_EQ(count("SELECT count(*) FROM participants WHERE code = 'P7'"), 0);
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 1);
    // The same decline sent again (a lost reply) counts once.
    const json again_declined =
        no.call("decline", {{"view", 1}, {"shown_ms", 60}, {"t_ms", 900}});
    EXPECT_EQ(again_declined["screen"], "declined");
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 1);
}

// Fifty pages at once through one server (threads calling handle as the HTTP server's
// workers do), each retrying a busy server's 503 as lucent.js does: every answer stored
// exactly once, cells from the participant numbers. Whether a page had to wait (every
// pooled connection busy on a loaded machine) is not the question; that nothing is lost
// or doubled is.
TEST_P(Serve, FiftyParticipantsAtOnceLoseAndDuplicateNothing) {
    constexpr int kPages = 50;
    std::vector<std::thread> threads;
    std::atomic<int> finished{0};
    lucent::test::Retries retries;
    std::vector<std::vector<std::string>> shown(kPages);
    for (int i = 0; i < kPages; ++i)
        threads.emplace_back([&, i] {
            Page page{lucent::test::retrying(direct(*web_), &retries)};
            page.open({{"participant", "W" + std::to_string(i + 1)}});
            page.run();
            if (page.state["screen"] == "done") ++finished;
            shown[i] = page.shown;
        });
    for (std::thread& t : threads) t.join();
    RecordProperty("requests_sent_again", retries.sent_again.load());
    std::printf("[ measured ] %d pages (%s): %d requests sent again after a 503\n",
                kPages, GetParam().c_str(), retries.sent_again.load());
    EXPECT_EQ(finished, kPages);
    const int64_t n = static_cast<int64_t>(planned_trials(protocol_));
    EXPECT_EQ(responses(), kPages * n * static_cast<int64_t>(protocol_.questions.size()));
    EXPECT_EQ(
        count("SELECT count(*) FROM (SELECT trial_id, question FROM responses GROUP BY "
              "trial_id, question HAVING count(*) > 1) d"),
        0);
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"), kPages);
    EXPECT_EQ(count("SELECT count(DISTINCT number) FROM participants"), kPages);
    for (int i = 0; i < kPages; ++i) EXPECT_EQ(static_cast<int64_t>(shown[i].size()), n);
}

// ---- issue 26: consent first, claims that end, arrival-order cells, bounded rows ------

// Item 5: before consent nothing of the person is stored; a decline leaves only their
// code counted once, as a salted hash (issue 44).
TEST_P(Serve, DecliningConsentStoresNothingOfThePersonOnlyTheCount) {
    const std::string pid = "5f3a9c1b2d4e6f708192a3b4";
    auto nothing_of_them = [&](const std::string& when) {
        EXPECT_EQ(count("SELECT count(*) FROM participants"), 0) << when;
        EXPECT_EQ(count("SELECT count(*) FROM sessions"), 0) << when;
        EXPECT_EQ(count("SELECT count(*) FROM session_segments"), 0) << when;
        EXPECT_EQ(count("SELECT count(*) FROM segment_stimuli"), 0) << when;
        EXPECT_EQ(count("SELECT count(*) FROM trials"), 0) << when;
        EXPECT_EQ(count("SELECT count(*) FROM session_segments WHERE gl_renderer LIKE "
                        "'%TestBrowser%' OR display_mode LIKE '%" +
                        pid +
                        "%' OR display_mode "
                        "LIKE '%60aabbcc%'"),
                  0)
            << when;
    };
    const json prolific = {{"prolific",
                            {{"PROLIFIC_PID", pid},
                             {"STUDY_ID", "60aabbccddeeff0011223344"},
                             {"SESSION_ID", "abc123XYZ"}}}};
    Page page{direct(*web_)};
    page.open(prolific);
    ASSERT_EQ(page.state["screen"], "consent");
    EXPECT_EQ(page.state["text"], "Do you agree?");
    nothing_of_them("on the consent screen");
    page.call("environment", {{"refresh_hz", 60}});  // the page measures its refresh
    page.open(prolific);                             // and is reloaded
    ASSERT_EQ(page.state["screen"], "consent");
    nothing_of_them("after a reload and the refresh estimate");

    const json declined = page.call(
        "decline", {{"view", page.state["view"]}, {"shown_ms", 60}, {"t_ms", 900}});
    EXPECT_EQ(declined["screen"], "declined");
    EXPECT_NE(declined["text"].get<std::string>().find("Nothing of yours was stored"),
              std::string::npos);
    nothing_of_them("after the decline");
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 1);
    // The declined page's token is spent: it acts on nothing.
    page.call("continue", {{"view", 1}, {"shown_ms", 60}, {"t_ms", 900}}, 409);
    nothing_of_them("after the spent token was used");

    // A second person declines: the count only grows.
    Page second{direct(*web_)};
    second.open({{"participant", "P2"}});
    second.call("decline",
                {{"view", second.state["view"]}, {"shown_ms", 10}, {"t_ms", 20}});
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 2);
    nothing_of_them("after the second decline");

    // Agreeing stores them, with the browser's details, and the consent time.
    Page yes{direct(*web_)};
    yes.open(prolific);
    yes.enter();
    EXPECT_EQ(yes.state["screen"], "instructions");
    EXPECT_EQ(count("SELECT count(*) FROM participants WHERE code = '" + pid + "'"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE consent_utc IS NOT NULL AND "
                    "gl_renderer = 'TestBrowser/1.0'"),
              1);
    EXPECT_EQ(count("SELECT count(*) FROM session_segments WHERE display_mode LIKE "
                    "'%Prolific STUDY_ID=60aabbccddeeff0011223344 SESSION_ID=abc123XYZ'"),
              1);
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 2);
    // The token handed out before consent is the stored session's: a reload with it
    // resumes that session (403 without it).
    const std::string token = yes.token;
    yes.open(prolific);
    EXPECT_EQ(yes.state["token"], token);
    EXPECT_EQ(count("SELECT count(*) FROM sessions"), 1);
    Page stranger{direct(*web_)};
    stranger.open(prolific, 403);
}

// Item 7: a session's claim ends with the session, so a lab station (another store
// connection) may take the participant; on PostgreSQL no advisory lock stays behind.
TEST_P(Serve, CompletedSessionsLeaveNoClaimBehind) {
    constexpr int kSessions = 6;
    for (int i = 1; i <= kSessions; ++i) {
        Page page{direct(*web_)};
        page.open({{"participant", "C" + std::to_string(i)}});
        page.run();
        ASSERT_EQ(page.state["screen"], "done");
    }
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              kSessions);
    if (GetParam() == "postgresql")
        EXPECT_EQ(count("SELECT count(*) FROM pg_locks WHERE locktype = 'advisory' AND "
                        "pid = pg_backend_pid()"),
                  0);
    auto station = open_store("station");
    for (int i = 1; i <= kSessions; ++i)
        EXPECT_NO_THROW(station->claim_participant("C" + std::to_string(i))) << i;
    // A declined page held nothing either.
    Page no{direct(*web_)};
    no.open({{"participant", "D1"}});
    no.call("decline", {{"view", no.state["view"]}, {"shown_ms", 10}, {"t_ms", 20}});
    EXPECT_NO_THROW(station->claim_participant("D1"));
}

// Item 7, issue 32: nothing holds an online participant between requests (a claim
// lasts one request), so a lab station can take over at once, a request while it runs
// them is refused and changes nothing, and the page goes on where it stood afterwards.
TEST_P(Serve, AnOnlineParticipantIsHeldOnlyWhileARequestRuns) {
    Page page{direct(*web_)};
    page.open({{"participant", "G1"}});
    page.run(2);
    ASSERT_EQ(page.state["screen"], "trial");
    const json before = page.state;
    if (GetParam() == "postgresql")
        EXPECT_EQ(count("SELECT count(*) FROM pg_locks WHERE locktype = 'advisory' AND "
                        "pid = pg_backend_pid()"),
                  0);
    {
        auto station = open_store("station");
        EXPECT_NO_THROW(station->claim_participant("G1"));
        // While the station runs them, the page's requests are refused (after waiting
        // WebStudyOptions::participant_wait) and change nothing.
        const WebReply busy = web_->handle(
            "session",
            json{{"participant", "G1"}, {"token", page.token}, {"t_ms", 5}}.dump());
        EXPECT_EQ(busy.status, 409) << busy.body;
        page.call("state", json::object(), 409);
    }
    // The station is done with them: the page goes on at the screen it showed.
    const json after = page.call("state", json::object());
    EXPECT_EQ(after["view"], before["view"]);
    EXPECT_EQ(after["trial"]["id"], before["trial"]["id"]);
    page.run();
    EXPECT_EQ(page.state["screen"], "done");
    auto station = open_store("station");
    EXPECT_NO_THROW(station->claim_participant("G1"));
}

std::string four_block_protocol_text() {
    std::string text = web_protocol_text();
    const std::string main =
        "[[blocks]]\nid = \"main\"\nstimuli = [\"a\", \"b\", \"c\"]\n";
    text.replace(text.find(main), main.size(),
                 "[[blocks]]\nid = \"main\"\nstimuli = [\"a\"]\n\n"
                 "[[blocks]]\nid = \"second\"\nstimuli = [\"b\"]\n\n"
                 "[[blocks]]\nid = \"third\"\nstimuli = [\"c\"]\n\n"
                 "[[blocks]]\nid = \"fourth\"\nstimuli = [\"b\", \"c\"]\n");
    return text;
}

// Item 8: online numbers follow arrival and cells are balanced, whatever the codes'
// digits; an abandoned slot's cell goes to the next arrival; each allocation is stored.
TEST_P(Serve, OnlineArrivalsAreBalancedAcrossCellsWhateverTheirCodes) {
    use_protocol(four_block_protocol_text(), "four_blocks");
    ASSERT_EQ(latin_square_rows(4), 4);
    // A Prolific id, two codes with the same trailing digit, digitless codes, one whose
    // digits would name a later participant.
    const std::vector<std::string> codes = {
        "5f3a9c1b2d4e6f708192a3b4", "-A1", "P01", "abc", "P06", "xyz", "Q7", "a-b_c"};
    std::vector<Page> pages;
    for (const std::string& code : codes) {
        pages.push_back(Page{direct(*web_)});
        pages.back().open({{"participant", code}});
        pages.back().enter();  // consents: enrolled now
        ASSERT_EQ(pages.back().state["screen"], "instructions") << code;
    }
    // Numbers 1..8 in arrival order, never from the codes.
    for (size_t i = 0; i < codes.size(); ++i)
        EXPECT_EQ(
            count("SELECT number FROM participants WHERE code = '" + codes[i] + "'"),
            static_cast<int64_t>(i + 1))
            << codes[i];
    // Each of the 4 cells twice; -A1 and P01 apart.
    for (int cell = 0; cell < 4; ++cell)
        EXPECT_EQ(
            count("SELECT count(*) FROM sessions WHERE cell = " + std::to_string(cell)),
            2)
            << "cell " << cell;
    auto cell_of = [&](const std::string& code) {
        return count(
            "SELECT s.cell FROM sessions s JOIN participants p ON p.id = "
            "s.participant_id WHERE p.code = '" +
            code + "'");
    };
    EXPECT_NE(cell_of("-A1"), cell_of("P01"));
    // Every allocation is recorded: arrival, cell, the counts it saw.
    EXPECT_EQ(
        count("SELECT count(*) FROM sessions WHERE allocation LIKE 'online arrival %: "
              "cell % of 4, the fewest completed + active sessions (per cell %'"),
        8);
    EXPECT_EQ(count("SELECT count(*) FROM sessions s JOIN participants p ON p.id = "
                    "s.participant_id WHERE p.code = 'P01' AND s.allocation LIKE "
                    "'online arrival 3: cell % of 4, % (per cell %'"),
              1);

    // All finish but P01 (arrival 3), who stops after consenting.
    const int64_t abandoned_cell = cell_of("P01");
    for (size_t i = 0; i < pages.size(); ++i)
        if (codes[i] != "P01") {
            pages[i].run();
            ASSERT_EQ(pages[i].state["screen"], "done") << codes[i];
        }
    // Arrival 9 while P01's page is still active: P01's cell is taken (its slot is held).
    Page ninth{direct(*web_)};
    ninth.open({{"participant", "N9"}});
    ninth.enter();
    ninth.run();
    const int64_t ninth_cell = cell_of("N9");
    EXPECT_NE(ninth_cell, abandoned_cell);
    // 31 minutes later P01 has abandoned: arrival 10 takes the freed cell, the only
    // one with fewer than 2 completed + active sessions.
    now_ += std::chrono::minutes(31);
    Page tenth{direct(*web_)};
    tenth.open({{"participant", "N10"}});
    tenth.enter();
    EXPECT_EQ(cell_of("N10"), abandoned_cell);
    std::vector<int64_t> expected_counts(4, 2);
    expected_counts[static_cast<size_t>(ninth_cell)] = 3;
    expected_counts[static_cast<size_t>(abandoned_cell)] = 1;
    std::string per_cell;
    for (int64_t n : expected_counts)
        per_cell += (per_cell.empty() ? "" : ",") + std::to_string(n);
    EXPECT_EQ(count("SELECT count(*) FROM sessions s JOIN participants p ON p.id = "
                    "s.participant_id WHERE p.code = 'N10' AND s.allocation LIKE "
                    "'online arrival 10: cell " +
                    std::to_string(abandoned_cell) +
                    " of 4, the fewest completed + active sessions (per cell " +
                    per_cell + ";%'"),
              1);
    EXPECT_EQ(count("SELECT number FROM participants WHERE code = 'N10'"), 10);
}

// Item 10: reloads and declines do not add rows without bound.
TEST_P(Serve, FiftyReloadsAndDeclinesAddBoundedRows) {
    const int64_t stimuli = static_cast<int64_t>(protocol_.stimuli.size());
    Page page{direct(*web_)};
    page.open({{"participant", "R1"}});
    page.enter();
    for (int i = 0; i < 50; ++i)
        page.open({{"participant", "R1"}, {"token", page.token}});
    // No trial answered yet: still one segment showing each stimulus once.
    EXPECT_EQ(count("SELECT count(*) FROM session_segments"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM segment_stimuli"), stimuli);
    EXPECT_EQ(count("SELECT count(*) FROM sessions"), 1);
    // Reloads between answers: at most one segment per answered trial, plus the first.
    page.run(1);
    for (int i = 0; i < 50; ++i)
        page.open({{"participant", "R1"}, {"token", page.token}});
    page.run(2);
    for (int i = 0; i < 50; ++i)
        page.open({{"participant", "R1"}, {"token", page.token}});
    const int64_t answered =
        count("SELECT count(*) FROM trials WHERE answered_utc IS NOT NULL");
    ASSERT_EQ(answered, 2);
    EXPECT_LE(count("SELECT count(*) FROM session_segments"), answered + 1);
    EXPECT_LE(count("SELECT count(*) FROM segment_stimuli"), (answered + 1) * stimuli);
    // Every answered trial names a segment that is still there.
    EXPECT_EQ(count("SELECT count(*) FROM trials t JOIN session_segments g ON g.id = "
                    "t.segment_id"),
              answered);
    // Fifty codes declined: one row each (a salted hash), nothing else.
    for (int i = 0; i < 50; ++i) {
        Page no{direct(*web_)};
        no.open({{"participant", "N" + std::to_string(i)}});
        no.call("decline", {{"view", no.state["view"]}, {"shown_ms", 10}, {"t_ms", 20}});
    }
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM sessions"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 50);
}

// Issue 44 item 5: a decline counts a participant code, not a page load. 400 scripted
// declines of one code (each a fresh page, as a reload without the token gets) are one
// code that declined consent, one row; the old count made 400.
TEST_P(Serve, OneCodeDecliningOnFourHundredPagesCountsOnce) {
    std::string last_token;
    for (int i = 0; i < 400; ++i) {
        Page no{direct(*web_)};
        no.open({{"participant", "S1"}});
        ASSERT_EQ(no.state["screen"], "consent") << i;
        no.call("decline", {{"view", no.state["view"]}, {"shown_ms", 10}, {"t_ms", 20}});
        last_token = no.token;
    }
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 0);
    // The newest declined page stays declined: its token acts on nothing.
    Page again{direct(*web_)};
    again.token = last_token;
    again.who = {{"participant", "S1"}};
    again.call("continue", {{"view", 1}, {"shown_ms", 60}, {"t_ms", 900}}, 409);
    EXPECT_EQ(count("SELECT count(*) FROM sessions"), 0);
    // The person may still agree later, from a new page: enrolled, still counted once.
    Page yes{direct(*web_)};
    yes.open({{"participant", "S1"}});
    yes.enter();
    EXPECT_EQ(yes.state["screen"], "instructions");
    EXPECT_EQ(count("SELECT count(*) FROM declined_codes"), 1);
}

// A store whose consent write fails, as a fault between two commits would: enrolment
// commits, then the connection or the disk goes.
template <class Base>
class ConsentWriteFails : public Base {
public:
    using Base::Base;
    void set_consent(int64_t) override {
        throw StoreUnavailable("fault injected: the consent write after enrolment");
    }
};

// Issue 44 item 6: consent is part of the enrolment's transaction. With a second commit
// for it, a fault between the two left a stored session (user agent, Prolific ids)
// without consent; now no session is ever stored without its consent.
TEST_P(Serve, AFaultAfterEnrolmentLeavesNoSessionWithoutConsent) {
    web_.reset();
    store_.reset();
    std::unique_ptr<StudyStore> faulty;
    if (GetParam() == "sqlite") {
        faulty = std::make_unique<ConsentWriteFails<Store>>(db_);
    } else {
        StoreOptions options;
        options.journal = false;
        faulty = std::make_unique<ConsentWriteFails<PostgresStore>>(db_, options);
    }
    WebStudy web(protocol_, *faulty, options_);
    Page page{direct(web)};
    page.open({{"prolific",
                {{"PROLIFIC_PID", "5f3a9c1b2d4e6f708192a3b4"},
                 {"STUDY_ID", "60aabbccddeeff0011223344"},
                 {"SESSION_ID", "abc123XYZ"}}}});
    ASSERT_EQ(page.state["screen"], "consent");
    const WebReply agreed = page.request(
        "continue", {{"view", page.state["view"]}, {"shown_ms", 60}, {"t_ms", 900}});
    EXPECT_EQ(agreed.status, 200) << agreed.body;
    EXPECT_EQ(
        faulty->query_int("SELECT count(*) FROM sessions WHERE consent_utc IS NULL"), 0);
    EXPECT_EQ(
        faulty->query_int("SELECT count(*) FROM sessions WHERE consent_utc IS NOT NULL"),
        1);
}

// Item 10: a participant withdrawn while their page is open: the page is told so (410),
// never the store's own words ("FOREIGN KEY constraint failed").
TEST_P(Serve, AWithdrawnParticipantsOpenPageIsToldTheSessionWasWithdrawn) {
    Page page{direct(*web_)};
    page.open({{"participant", "W1"}});
    page.run(1);
    ASSERT_EQ(page.state["screen"], "trial");
    auto admin = open_store("admin");
    ASSERT_TRUE(admin->withdraw_participant("W1"));
    const json body = [&] {
        json b = page.answer_body(1);
        b["token"] = page.token;
        return b;
    }();
    const WebReply answered = web_->handle("answer", body.dump());
    EXPECT_EQ(answered.status, 410) << answered.body;
    EXPECT_NE(answered.body.find("withdrawn"), std::string::npos) << answered.body;
    EXPECT_EQ(answered.body.find("FOREIGN KEY"), std::string::npos) << answered.body;
    EXPECT_EQ(count("SELECT count(*) FROM responses"), 0);

    // The same on a reload of a page whose participant was withdrawn.
    Page other{direct(*web_)};
    other.open({{"participant", "W2"}});
    other.run(1);
    ASSERT_TRUE(admin->withdraw_participant("W2"));
    const WebReply reload = web_->handle(
        "session",
        json{{"participant", "W2"}, {"token", other.token}, {"t_ms", 5}}.dump());
    EXPECT_EQ(reload.status, 410) << reload.body;
    EXPECT_NE(reload.body.find("withdrawn"), std::string::npos) << reload.body;
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 0);
    if (GetParam() == "postgresql")
        EXPECT_EQ(count("SELECT count(*) FROM pg_locks WHERE locktype = 'advisory' AND "
                        "pid = pg_backend_pid()"),
                  0);
}

// Item 10: a number beyond a double is a 400 naming its field (it was a 500).
TEST_P(Serve, ANumberBeyondADoubleIsA400NamingTheField) {
    for (const char* t : {"1e999", "-1e999", "1e400"}) {
        const WebReply r = web_->handle(
            "session", std::string("{\"participant\": \"P1\", \"t_ms\": ") + t + "}");
        EXPECT_EQ(r.status, 400) << t << " -> " << r.body;
        EXPECT_NE(r.body.find("'t_ms'"), std::string::npos) << r.body;
    }
    const std::string huge_integer = std::string(400, '9');
    const WebReply r = web_->handle("session",
                                    "{\"participant\": \"P1\", \"client\": "
                                    "{\"window_width\": " +
                                        huge_integer + "}, \"t_ms\": 1}");
    EXPECT_EQ(r.status, 400) << r.body;
    EXPECT_NE(r.body.find("'window_width'"), std::string::npos) << r.body;
    // Inside an answer's events.
    Page page{direct(*web_)};
    page.open({{"participant", "P2"}});
    page.run(0);
    ASSERT_EQ(page.state["screen"], "trial");
    json body = page.answer_body(0);
    body["token"] = page.token;
    std::string text = body.dump();
    const std::string onset = "\"onset_ms\":" + body["onset_ms"].dump();
    text.replace(text.find(onset), onset.size(), "\"onset_ms\":1e309");
    const WebReply a = web_->handle("answer", text);
    EXPECT_EQ(a.status, 400) << a.body;
    EXPECT_NE(a.body.find("'onset_ms'"), std::string::npos) << a.body;
    EXPECT_EQ(count("SELECT count(*) FROM responses"), 0);
}

// ---- forced choices (issue 30)
// --------------------------------------------------------- A study of every trial kind:
// a rating block, pairs and triads side by side, quadruples in sequence (short
// durations), in the protocol's order (no counterbalancing).
std::string choice_web_protocol_text() {
    std::string text = R"toml(
[study]
name = "web_choices"
break_every = 8
inter_trial_ms = 100

[screens]
consent = "Do you agree?"
instructions = "Choose."
debrief = "Thank you."

[online]
completion_code = "CH0ICE"

[randomisation]
counterbalance_blocks = false

[[questions]]
id = "translucent"
text = "The object looks translucent."
)toml";
    for (int i = 1; i <= 5; ++i)
        text += "\n[[stimuli]]\nid = \"s" + std::to_string(i) +
                "\"\ntechnique = \"empirical\"\nmesh = \"sphere\"\nparams = { "
                "thickness_exponent = " +
                std::to_string(5 + 5 * i) + " }\n";
    return text + R"toml(
[[blocks]]
id = "ratings"
stimuli = ["s1", "s5"]

[[blocks]]
id = "pairs"
task = "pair"
stimuli = ["s1", "s2", "s3", "s4"]
question = "Which looks more translucent?"
question_id = "more_translucent"
series = "thickness_exponent"
identical_catch = 1
obvious_catch = ["s1", "s4"]
practice = 1

[[blocks]]
id = "triads"
task = "triad"
stimuli = ["s1", "s2", "s3", "s4", "s5"]
question = "Which pair differs more?"
question_id = "triad_differs"
series = "thickness_exponent"
obvious_catch = ["s1", "s5"]

[[blocks]]
id = "quads"
task = "quadruple"
stimuli = ["s1", "s2", "s3", "s4", "s5"]
question = "Which pair differs more?"
question_id = "quad_differs"
labels = ["the first", "the second"]
series = "thickness_exponent"
presentation = "sequential"
duration_ms = 60
blank_ms = 30
)toml";
}
// practice 1 + ratings 2 + pairs C(4,2) = 6 + 2 catch + triads C(5,3) = 10 + 1 catch +
// quadruples C(5,4) = 5.
constexpr size_t kChoiceStudyTrials = 1 + 2 + 6 + 2 + 10 + 1 + 5;

// The stimulus id of a picture URL the page was given (the server decodes it).
std::string stimulus_of_url(const WebStudy& web, const std::string& url) {
    const std::optional<NamedPicture> named = web.picture(url);
    EXPECT_TRUE(named) << url;
    return named ? named->id : std::string();
}

// The block of each task in the protocol above.
std::string block_of_task(const std::string& task) {
    return task == "pair" ? "pairs" : task == "triad" ? "triads" : "quads";
}

// A page answering as the simulated observer (psi = x^0.5, sigma 0.1) from what the
// page was shown: the pictures' names in screen order.
Page observer_page(const Protocol& protocol, WebStudy& web, std::mt19937_64& rng) {
    Page page{direct(web)};
    page.choose = [&protocol, &web, &rng](const json& trial) {
        std::vector<std::string> shown;
        for (const json& picture : trial["shown"])
            shown.push_back(stimulus_of_url(web, picture["image"]));
        const ObserverModel observer{0.5, 0.1, 0.0};
        return simulated_choice(
            observer, choice_stimuli(protocol, block_of_task(trial["task"]), shown), rng);
    };
    return page;
}

TEST_P(Serve, PairsTriadsAndQuadruplesAreAnsweredOnlineAsInTheLabEachChoiceStoredOnce) {
    use_protocol(choice_web_protocol_text(), "choices");
    std::mt19937_64 rng(30);
    Page page = observer_page(protocol_, *web_, rng);
    page.open({{"participant", "W1"}});
    ASSERT_EQ(page.state["screen"], "consent");
    EXPECT_EQ(page.state["progress"]["total"], kChoiceStudyTrials - 1);
    std::map<std::string, json> trial_shown;  // the trial JSON the page was given, by id
    std::map<std::string, int> chosen;        // the alternative it chose, by id
    auto run = [&](Page& p, size_t until) {
        for (int guard = 0; guard < 200 && p.state["screen"] != "done"; ++guard) {
            if (p.state["screen"] != "trial") {
                p.enter();
                continue;
            }
            if (p.shown.size() >= until) return;
            const json trial = p.state["trial"];
            trial_shown[trial["id"]] = trial;
            // Nothing tells the page which answer is right, or that a trial is a check.
            const std::string text = trial.dump();
            for (const char* secret : {"expected", "catch", "Attention"})
                EXPECT_EQ(text.find(secret), std::string::npos) << text;
            p.answer(static_cast<int>(p.shown.size()));
            chosen[p.shown.back()] = p.chosen.back();
        }
    };
    run(page, 14);  // into the triads
    ASSERT_EQ(page.state["screen"], "trial");

    // A reload: a fresh page with the token continues at the first open trial.
    const int64_t session = count("SELECT id FROM sessions");
    std::vector<TrialRow> trials = store_->trials(session);
    ASSERT_EQ(trials.size(), kChoiceStudyTrials);
    Page reloaded = observer_page(protocol_, *web_, rng);
    reloaded.token = page.token;
    reloaded.open({{"participant", "W1"}, {"token", page.token}});
    ASSERT_EQ(reloaded.state["screen"], "trial");
    EXPECT_EQ(reloaded.state["trial"]["id"], trials[14].uuid);
    EXPECT_EQ(reloaded.state["trial"], page.state["trial"]);
    reloaded.shown = page.shown;
    reloaded.chosen = page.chosen;
    run(reloaded, 1000);
    ASSERT_EQ(reloaded.state["screen"], "done");
    EXPECT_EQ(reloaded.state["completion"]["code"], "CH0ICE");
    ASSERT_EQ(reloaded.shown.size(), kChoiceStudyTrials);

    // Every trial shown once in the stored order; each choice stored once, as chosen,
    // to its block's question, 100 ms after the answer screen's onset.
    trials = store_->trials(session);
    std::map<std::string, int> per_task;
    for (size_t k = 0; k < trials.size(); ++k) {
        const TrialRow& t = trials[k];
        EXPECT_EQ(t.uuid, reloaded.shown[k]) << k;
        const json& shown = trial_shown.at(t.uuid);
        const std::string where = "trial " + std::to_string(k);
        ++per_task[task_name(t.task)];
        if (t.task == Task::rating) {
            EXPECT_EQ(shown["task"], "rating");
            EXPECT_EQ(stimulus_of_url(*web_, shown["image"]), t.stimulus);
            continue;
        }
        const Block& block = *protocol_.find_block(t.block);
        EXPECT_EQ(shown["task"], task_name(t.task)) << where;
        ASSERT_EQ(shown["shown"].size(), t.shown.size()) << where;
        for (size_t i = 0; i < t.shown.size(); ++i) {
            EXPECT_EQ(stimulus_of_url(*web_, shown["shown"][i]["image"]), t.shown[i]);
            EXPECT_EQ(shown["shown"][i]["width"], 64);
            EXPECT_EQ(shown["shown"][i]["height"], 48);
        }
        EXPECT_EQ(shown["question"], block.question) << where;
        EXPECT_EQ(shown["labels"], json(block.labels)) << where;
        // What each answer names, the page laying it out from these alone.
        EXPECT_EQ(shown["groups"],
                  json::parse(t.task == Task::pair    ? "[[0], [1]]"
                              : t.task == Task::triad ? "[[0, 1], [1, 2]]"
                                                      : "[[0, 1], [2, 3]]"))
            << where;
        EXPECT_EQ(shown["prompt"], "") << where;
        if (t.task == Task::quadruple) {
            EXPECT_EQ(shown["presentation"], "sequential");
            EXPECT_EQ(shown["sequence"], json({{"duration_ms", 60}, {"blank_ms", 30}}));
        } else {
            EXPECT_EQ(shown["presentation"], "side_by_side");
            EXPECT_FALSE(shown.contains("sequence"));
        }
        EXPECT_EQ(count("SELECT count(*) FROM responses r JOIN trials t ON t.id = "
                        "r.trial_id WHERE t.uuid = '" +
                        t.uuid + "'"),
                  1)
            << where;
        EXPECT_EQ(count("SELECT count(*) FROM responses r JOIN trials t ON t.id = "
                        "r.trial_id WHERE t.uuid = '" +
                        t.uuid + "' AND r.question = '" + block.question_id +
                        "' AND r.rating = " + std::to_string(chosen.at(t.uuid)) +
                        " AND abs(r.rt_ms - 100) < 0.001"),
                  1)
            << where << " (" << t.block << ")";
    }
    EXPECT_EQ(per_task,
              (std::map<std::string, int>{
                  {"rating", 2}, {"pair", 9}, {"triad", 11}, {"quadruple", 5}}));
    EXPECT_EQ(responses(), static_cast<int64_t>(kChoiceStudyTrials));
    EXPECT_EQ(
        count("SELECT count(*) FROM responses WHERE rating NOT IN (1, 2) AND question <> "
              "'translucent'"),
        0);
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
    // Both answers occur (an observer, not a constant key).
    EXPECT_EQ(count("SELECT count(DISTINCT rating) FROM responses WHERE question <> "
                    "'translucent'"),
              2);
}

// Hostile answers to forced choices: each a 4xx with one line naming what is wrong, and
// nothing stored.
TEST_P(Serve, HostileChoiceAnswersAreRefusedWithOneLineAndStoreNothing) {
    use_protocol(choice_web_protocol_text(), "choices");
    Page page{direct(*web_)};
    page.open({{"participant", "H1"}});
    page.run(0);  // the practice pair on screen
    ASSERT_EQ(page.state["trial"]["task"], "pair");
    Page other{direct(*web_)};
    other.open({{"participant", "H2"}});
    other.run(1);
    auto refused = [&](const json& body, int status, const std::string& reason) {
        const int64_t stored = responses();
        const WebReply r = web_->handle("answer", body.dump());
        EXPECT_EQ(r.status, status) << body.dump() << " -> " << r.body;
        const json reply = json::parse(r.body, nullptr, false);
        ASSERT_TRUE(reply.is_object() && reply.contains("error")) << r.body;
        const std::string line = reply["error"];
        EXPECT_EQ(line.find('\n'), std::string::npos);
        EXPECT_NE(line.find(reason), std::string::npos) << line;
        EXPECT_EQ(responses(), stored) << body.dump();
    };
    auto with = [&](int k, const std::function<void(json&)>& edit) {
        json body = page.choice_body(k, 2);
        body["token"] = page.token;
        edit(body);
        return body;
    };
    const int64_t session = count(
        "SELECT id FROM sessions WHERE participant_id = (SELECT "
        "id FROM participants WHERE code = 'H1')");
    const std::vector<TrialRow> trials = store_->trials(session);

    // The pair side by side.
    refused(with(2, [](json& b) { b["events"][0]["alternative"] = 3; }), 400,
            "'alternative' must be 1 or 2");
    refused(with(2, [](json& b) { b["events"][0]["alternative"] = 0; }), 400,
            "'alternative' must be 1 or 2");
    refused(with(2, [](json& b) { b["events"][0]["alternative"] = 1.5; }), 400,
            "'alternative' must be 1 or 2");
    refused(with(2, [](json& b) { b["events"][0].erase("alternative"); }), 400,
            "'alternative' must be 1 or 2");
    refused(with(1, [](json& b) { b["events"][0]["key"] = "3"; }), 400,
            "field 'key': '3' does not answer a forced choice");
    refused(with(0, [](json& b) { b["events"][0]["key"] = "ArrowUp"; }), 400,
            "field 'key': 'ArrowUp'");
    refused(
        with(2,
             [](json& b) {
                 b["events"] = {
                     {{"t_ms", 1e4}, {"type", "point"}, {"question", 0}, {"value", 2}},
                     {{"t_ms", 1e4 + 1}, {"type", "next"}}};
             }),
        400,
        "field 'type': a 'point' event rates a question; this trial is a forced "
        "choice (pair)");
    refused(with(0, [](json& b) { b["events"].erase(1); }), 400,
            "do not choose an alternative and confirm it");
    refused(with(2,
                 [](json& b) {
                     b["phase_onsets_ms"] = {{"gap", 1}, {"second", 2}, {"answer", 3}};
                 }),
            400, "'phase_onsets_ms' is only for a trial shown in sequence");
    refused(with(2, [&](json& b) { b["trial"] = trials[5].uuid; }), 409,
            "trial 6 is not the one on screen");
    refused(with(2, [&](json& b) { b["trial"] = other.shown[0]; }), 404,
            "not one of this session's trials");
    refused(with(2, [&](json& b) { b["token"] = other.token; }), 404,
            "not one of this session's trials");
    page.answer(2);
    EXPECT_EQ(responses(), 2);  // the other page's practice pair, this one's

    // A rating trial: no choice events.
    page.run(1);
    ASSERT_EQ(page.state["trial"]["task"], "rating");
    json rating = page.answer_body(1);
    rating["token"] = page.token;
    json as_choice = rating;
    as_choice["events"] = {{{"t_ms", rating["onset_ms"].get<double>() + 100},
                            {"type", "choice"},
                            {"alternative", 1}}};
    refused(as_choice, 400,
            "field 'type': a 'choice' event answers a forced choice; this trial is a "
            "rating");

    // A quadruple in sequence: each part's onset no earlier than the part before's
    // onset plus its duration.
    for (int guard = 0; guard < 100 && !(page.state["screen"] == "trial" &&
                                         page.state["trial"]["task"] == "quadruple");
         ++guard) {
        if (page.state["screen"] == "trial")
            page.answer(static_cast<int>(page.shown.size()));
        else
            page.enter();
    }
    const json ok = with(0, [](json&) {});
    const double onset = ok["onset_ms"];
    refused(with(0,
                 [&](json& b) {
                     b["phase_onsets_ms"]["answer"] =
                         b["phase_onsets_ms"]["second"].get<double>() + 59;
                 }),
            400,
            "field 'phase_onsets_ms.answer': the answer screen came 59.0 ms after the "
            "second part, which is shown for 60 ms");
    refused(with(0, [&](json& b) { b["phase_onsets_ms"]["gap"] = onset + 59.5; }), 400,
            "field 'phase_onsets_ms.gap': the blank came 59.5 ms after the first part");
    refused(
        with(0, [&](json& b) { b["phase_onsets_ms"]["second"] = onset + 60 + 3 + 29; }),
        400, "'phase_onsets_ms.second'");
    refused(with(0, [](json& b) { b.erase("phase_onsets_ms"); }), 400,
            "'phase_onsets_ms' ({\"gap\", \"second\", \"answer\"}) is required");
    refused(with(0, [](json& b) { b["phase_onsets_ms"].erase("answer"); }), 400,
            "'answer' is required");
    // Keys before the answer screen are stale: they answer nothing.
    refused(with(0,
                 [&](json& b) {
                     for (json& e : b["events"]) e["t_ms"] = onset + 50;
                 }),
            400, "do not choose an alternative");
    const int64_t stored = responses();
    page.answer(0);
    EXPECT_EQ(responses(), stored + 1);
    EXPECT_EQ(count("SELECT count(*) FROM responses r JOIN trials t ON t.id = r.trial_id "
                    "WHERE t.task = 'quadruple' AND r.question = 'quad_differs' AND "
                    "r.rating = 1 AND abs(r.rt_ms - 100) < 0.001"),
              1);
}

// ---- issue 32: several serve processes on one database
// ---------------------------------

// Two serve processes (each its own WebStudy and store connections, no journal) on one
// database, a proxy sending each request of a page to the other one in turn: the page
// goes from consent to completion, every answer stored once, the views one sequence.
TEST_P(Serve, AnyServeProcessAnswersAnyRequestOfAPage) {
    StoreOptions no_journal;
    no_journal.journal = false;
    StorePool pool_a(db_, 2, no_journal, std::chrono::seconds(2));
    StorePool pool_b(db_, 2, no_journal, std::chrono::seconds(2));
    WebStudy a(protocol_, pool_a, options_), b(protocol_, pool_b, options_);
    int turn = 0;
    std::map<char, int> served;
    Page page{[&](const std::string& endpoint, const std::string& body) {
        const char which = turn++ % 2 == 0 ? 'a' : 'b';
        ++served[which];
        return (which == 'a' ? a : b).handle(endpoint, body);
    }};
    page.open({{"participant", "M1"}});
    ASSERT_EQ(page.state["screen"], "consent");
    page.run();
    EXPECT_EQ(page.state["screen"], "done");
    EXPECT_GT(served['a'], 3);
    EXPECT_GT(served['b'], 3);
    const int64_t n = static_cast<int64_t>(planned_trials(protocol_));
    EXPECT_EQ(static_cast<int64_t>(page.shown.size()), n);
    EXPECT_EQ(responses(), n * static_cast<int64_t>(protocol_.questions.size()));
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
    // One segment: no request was taken for a reload.
    EXPECT_EQ(count("SELECT count(*) FROM session_segments"), 1);
}

// A request that finds every store connection busy past the wait is told to come back
// (503, Retry-After), changes nothing, and the health check says the same; the next
// request, once a connection is free, goes on.
TEST_P(Serve, ABusyStoreIsA503WithRetryAfterAndNothingChanges) {
    StoreOptions no_journal;
    no_journal.journal = false;
    StorePool pool(db_, 1, no_journal, std::chrono::milliseconds(50));
    WebStudy web(protocol_, pool, options_);
    Page page{direct(web)};
    page.open({{"participant", "B1"}});
    page.run(1);
    ASSERT_EQ(page.state["screen"], "trial");
    EXPECT_EQ(web.health().status, 200);
    const int64_t stored = responses();
    {
        StorePool::Lease held = pool.lease();  // every connection busy
        json body = page.answer_body(1);
        body["token"] = page.token;
        const WebReply busy = web.handle("answer", body.dump());
        EXPECT_EQ(busy.status, 503) << busy.body;
        EXPECT_EQ(busy.retry_after_s, 1);
        EXPECT_NE(busy.body.find("busy"), std::string::npos) << busy.body;
        const WebReply health = web.health();
        EXPECT_EQ(health.status, 503) << health.body;
        EXPECT_EQ(responses(), stored);
    }
    EXPECT_EQ(web.health().status, 200);
    page.answer(1);
    EXPECT_EQ(responses(), stored + static_cast<int64_t>(protocol_.questions.size()));
}

INSTANTIATE_TEST_SUITE_P(Stores, Serve, ::testing::Values("sqlite", "postgresql"),
                         param_name);

// ---- names, tokens, image paths (no store) --------------------------------------------
TEST(ServeNames, HmacMatchesRfc4231) {
    // RFC 4231 test cases 1 and 2.
    EXPECT_EQ(hmac_sha256_hex(std::string(20, '\x0b'), "Hi There"),
              "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
    EXPECT_EQ(hmac_sha256_hex("Jefe", "what do ya want for nothing?"),
              "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
    // Case 6: a key longer than the block is hashed first.
    EXPECT_EQ(hmac_sha256_hex(std::string(131, '\xaa'),
                              "Test Using Larger Than Block-Size Key - Hash Key First"),
              "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54");
}

// A picture's name says nothing of the picture, differs per trial and slot, and only
// the key and the list that made it decode it (issue 44, item 4).
TEST(ServeNames, PictureNamesAreOpaquePerTrialAndSlotAndDecodeOnlyUnderTheirKey) {
    const std::vector<std::string> ids = {"std", "std@r=10.5", "std@r=11", "emp1"};
    const PictureNames names("test secret", ids);
    std::set<std::string> given;
    for (const char* trial : {"trial-a", "trial-b"})
        for (size_t slot = 0; slot < 3; ++slot)
            for (const std::string& id : ids) {
                const std::string url = names.url(trial, slot, id);
                ASSERT_EQ(url.size(), 52u) << url;  // "/images/" + 40 hex digits + ".png"
                EXPECT_EQ(url.rfind("/images/", 0), 0u);
                EXPECT_EQ(url.find_first_not_of("0123456789abcdef", 8), url.size() - 4)
                    << url;
                EXPECT_TRUE(given.insert(url).second) << url << " given twice";
                const std::optional<NamedPicture> named = names.picture(url);
                ASSERT_TRUE(named) << url;
                EXPECT_EQ(named->id, id);
                EXPECT_EQ(names.picture(url + "?v=2")->id, id);
            }
    // The same trial, slot and picture: the same name (a page asking again).
    EXPECT_EQ(names.url("trial-a", 1, "std"), names.url("trial-a", 1, "std"));
    // Any instance with the key and the same pictures, in any order, reads it.
    const std::string url = names.url("trial-a", 0, "std@r=11");
    EXPECT_EQ(PictureNames("test secret", {"emp1", "std@r=11", "std", "std@r=10.5"})
                  .picture(url)
                  ->id,
              "std@r=11");
    // Another key, another list, an altered digit, another spelling: no picture.
    EXPECT_FALSE(PictureNames("other secret", ids).picture(url));
    EXPECT_FALSE(PictureNames("test secret", {"std", "std@r=10.5"}).picture(url));
    for (size_t at = 8; at < 48; ++at) {
        std::string altered = url;
        altered[at] = altered[at] == '0' ? '1' : '0';
        EXPECT_FALSE(names.picture(altered)) << altered;
    }
    std::string upper = url;
    for (char& c : upper)
        if (c >= 'a' && c <= 'f') c = static_cast<char>(c - 'a' + 'A');
    if (upper != url) {
        EXPECT_FALSE(names.picture(upper)) << upper;
    }
    EXPECT_THROW(names.url("trial-a", 0, "not a picture"), std::out_of_range);
    // A stimulus by its id, and every path trick, is no picture.
    for (const char* bad :
         {"/images/emp1.png", "/images/std.png", "/images/../study.db",
          "/images/..%2f..%2fetc%2fpasswd", "/images/%2e%2e/b.png",
          "/images/b.png%00.txt", "/images//b.png", "/images/sub/b.png", "/images/.png",
          "/b.png", "/IMAGES/b.png", "/images/..\\b.png"})
        EXPECT_FALSE(names.picture(bad)) << bad;
    EXPECT_FALSE(names.picture(url.substr(0, 20)));
    EXPECT_FALSE(names.picture(url + "/"));
    EXPECT_FALSE(names.picture("/images/" + std::string(40, 'z') + ".png"));
}

// One serving's noise: at most one step, zero on average, black, white and alpha kept,
// and another serving's noise is another pattern.
TEST(ServeNames, ServingNoiseMovesEachMidtoneByAtMostOneStepAndKeepsTheMean) {
    std::vector<uint8_t> picture(256 * 256 * 4);
    for (size_t i = 0; i < picture.size(); ++i)
        picture[i] = i % 4 == 3 ? static_cast<uint8_t>(i / 4 % 256)
                                : static_cast<uint8_t>(i * 7 % 256);
    std::vector<uint8_t> first = picture, second = picture;
    const size_t changed = add_serving_noise(first, 1);
    add_serving_noise(second, 2);
    EXPECT_NE(first, second);
    size_t midtones = 0;
    double sum_of_changes = 0;
    for (size_t i = 0; i < picture.size(); ++i) {
        const int change = int(first[i]) - int(picture[i]);
        EXPECT_LE(std::abs(change), 1) << i;
        if (i % 4 == 3 || picture[i] == 0 || picture[i] == 255) {
            EXPECT_EQ(change, 0) << i;
            continue;
        }
        ++midtones;
        sum_of_changes += change;
    }
    // Two in three midtones move; the mean change is zero within 4 standard errors
    // (each change has variance 2/3).
    EXPECT_NEAR(double(changed) / double(midtones), 2.0 / 3.0, 0.01);
    EXPECT_NEAR(sum_of_changes / double(midtones), 0.0,
                4 * std::sqrt(2.0 / 3.0 / double(midtones)));
    std::vector<uint8_t> again = picture;
    add_serving_noise(again, 1);
    EXPECT_EQ(again, first);  // the same serving, the same bytes
}

TEST(ServeNames, ParticipantCodes) {
    EXPECT_EQ(participant_code_problem("P07"), "");
    EXPECT_EQ(participant_code_problem("5f1a2b3c4d5e6f7a8b9c0d1e"), "");
    EXPECT_EQ(participant_code_problem("lab-1_b"), "");
    EXPECT_NE(participant_code_problem(""), "");
    EXPECT_NE(participant_code_problem(std::string(65, 'a')), "");
    EXPECT_EQ(participant_code_problem(std::string(64, 'a')), "");
    for (const char* bad : {"a b", "a/b", "a.b", "a%20", "x\n", "P1'--"})
        EXPECT_NE(participant_code_problem(bad), "") << bad;
    // Tokens differ per session and per secret.
    EXPECT_NE(session_token("s", "P1", "u1"), session_token("s", "P1", "u2"));
    EXPECT_NE(session_token("s", "P1", "u1"), session_token("t", "P1", "u1"));
    EXPECT_EQ(session_token("s", "P1", "u1").rfind("P1.", 0), 0u);
}

// ---- the test page's retry is lucent.js's
// ---------------------------------------------- The waits and the statuses retried are
// the page's own (read from the embedded lucent.js), so a test that retries as the page
// does asserts what a participant sees.
TEST(ServePageRetry, WaitsAndStatusesAreLucentJs) {
    const auto script = lucent::embedded::serve_file("lucent.js");
    ASSERT_TRUE(script.has_value());
    const std::string js(*script);
    std::string delays;
    for (std::size_t i = 0; i < lucent::test::kRetryDelaysMs.size(); ++i)
        delays += (i ? ", " : "") + std::to_string(lucent::test::kRetryDelaysMs[i]);
    EXPECT_NE(js.find("const kRetryDelaysMs = [" + delays + "];"), std::string::npos)
        << "lucent.js's retry waits changed; tests/study/serve/web_page.h mirrors them";
    EXPECT_NE(
        js.find("status === 0 || status === 502 || status === 503 || status === 504"),
        std::string::npos);
    EXPECT_NE(js.find("Math.max(kRetryDelaysMs[attempt], retryAfterMs)"),
              std::string::npos);
    for (int status : {0, 502, 503, 504})
        EXPECT_TRUE(lucent::test::transient_status(status));
    for (int status : {200, 400, 403, 404, 409, 410, 500})
        EXPECT_FALSE(lucent::test::transient_status(status));
}

TEST(ServePageRetry, SendsTheSameBodyAgainAfterEachWaitThenGivesTheLastReply) {
    std::vector<std::string> bodies;
    std::vector<int> waits;
    std::vector<WebReply> replies = {
        {503, "{}", 3}, {502, "{}"}, {0, "{}"}, {200, "{\"ok\":1}"}};
    lucent::test::Retries retries;
    auto send = lucent::test::retrying(
        [&](const std::string&, const std::string& body) {
            bodies.push_back(body);
            return replies[bodies.size() - 1];
        },
        &retries,
        [&](std::chrono::milliseconds ms) { waits.push_back(int(ms.count())); });
    const WebReply got = send("answer", "{\"trial\":7}");
    EXPECT_EQ(got.status, 200);
    EXPECT_EQ(bodies, std::vector<std::string>(4, "{\"trial\":7}"));
    // Retry-After (3 s) is longer than the first wait; then the page's own waits.
    EXPECT_EQ(waits, (std::vector<int>{3000, 500, 1000}));
    EXPECT_EQ(retries.sent_again, 3);
    EXPECT_EQ(retries.waited_ms, 4500);

    // Not transient: returned at once.
    bodies.clear();
    waits.clear();
    replies = {{500, "{}"}, {200, "{}"}};
    EXPECT_EQ(send("answer", "{}").status, 500);
    EXPECT_EQ(bodies.size(), 1u);
    EXPECT_TRUE(waits.empty());

    // Always busy: every wait of lucent.js's spent, then the last 503 returned.
    bodies.clear();
    waits.clear();
    replies.assign(lucent::test::kRetryDelaysMs.size() + 1, WebReply{503, "{}"});
    EXPECT_EQ(send("answer", "{}").status, 503);
    EXPECT_EQ(bodies.size(), lucent::test::kRetryDelaysMs.size() + 1);
    EXPECT_EQ(waits, std::vector<int>(lucent::test::kRetryDelaysMs.begin(),
                                      lucent::test::kRetryDelaysMs.end()));
}

}  // namespace
}  // namespace lucent::study
