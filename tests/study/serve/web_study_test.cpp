// lucent serve's core over every store backend (SQLite file, a real PostgreSQL server),
// driven as a browser page drives it: JSON requests, performance.now() times, the input
// events of each answer. Expected values come from the protocol (trial counts, scales,
// screen texts), the order the page was given, and the times the test chose; never from
// the server under test.
#include "serve/web_study.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <functional>
#include <set>
#include <thread>

#include "../study_fixtures.h"
#include "web_page.h"
#include "../postgres/server_environment.h"
#include "store.h"
#include "study_store.h"
#include "test_paths.h"

namespace lucent::study {
namespace {

using nlohmann::json;
using lucent::test::Page;
using lucent::test::direct;
using lucent::test::page_rating;

std::string web_protocol_text() {
    return std::string(lucent::test::kSmallProtocol) +
           "\n[screens]\nconsent = \"Do you agree?\"\ninstructions = \"Rate each picture.\"\n"
           "debrief = \"Thank you.\"\n\n[online]\ncompletion_code = \"C0DE42\"\n"
           "completion_url = \"https://app.prolific.com/submissions/complete?cc=C0DE42\"\n";
}

// Trials a session of the protocol plans: practice, each block stimulus per repeat, catch.
size_t planned_trials(const Protocol& p) {
    size_t n = p.practice.size() + p.catch_trials.size();
    for (const Block& b : p.blocks) n += b.stimuli.size() * static_cast<size_t>(b.repeats);
    return n;
}


class Serve : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::string slug;
        for (char c : test)
            slug += std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
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
    void start_server() {
        web_.reset();
        store_.reset();
        StoreOptions options;
        options.journal_path = (dir_ / "journal.db").string();
        options.retry_interval_ms = 0;
        store_ = open_study_store(db_, options);
        WebStudyOptions o;
        o.secret = "test secret";
        o.environment.machine_id = "server-machine";
        o.environment.software_version = "test";
        o.environment.build_hash = "test";
        for (const StimulusSpec& s : protocol_.stimuli) o.images[s.id] = {64, 48};
        web_ = std::make_unique<WebStudy>(protocol_, *store_, o);
    }
    int64_t count(const std::string& sql) { return store_->query_int(sql); }
    int64_t responses() { return count("SELECT count(*) FROM responses"); }

    std::filesystem::path dir_;
    std::string db_;
    Protocol protocol_;
    std::unique_ptr<StudyStore> store_;
    std::unique_ptr<WebStudy> web_;
};

std::string param_name(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

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
            EXPECT_EQ(count("SELECT count(*) FROM responses r JOIN trials t ON t.id = r.trial_id "
                            "WHERE t.uuid = '" + trials[k].uuid + "' AND r.question = '" +
                            protocol_.questions[q].id + "' AND r.rating = " +
                            std::to_string(rating) + " AND abs(r.rt_ms - " +
                            std::to_string(100 * (q + 1)) + ") < 0.001 AND r.changes = 0"),
                      1)
                << "trial " << k << " question " << q;
        }
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed' AND "
                    "consent_utc IS NOT NULL"),
              1);
    // The browser's details on the session's segment.
    EXPECT_EQ(count("SELECT count(*) FROM session_segments WHERE gl_vendor = 'web browser' "
                    "AND gl_renderer = 'TestBrowser/1.0' AND display_mode = 'browser window "
                    "1280x900 CSS px, devicePixelRatio 2, screen 2560x1440' AND "
                    "machine_id = 'server-machine'"),
              1);
    EXPECT_EQ(web_->live_sessions(), 0u);
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
    EXPECT_EQ(count("SELECT count(*) FROM session_segments WHERE abs(measured_refresh_hz - "
                    "59.94) < 1e-9"),
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
    EXPECT_EQ(count("SELECT count(*) FROM participants WHERE code = '5f1a2b3c4d5e6f7a8b9c0d1e'"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM session_segments WHERE display_mode LIKE "
                    "'%; Prolific STUDY_ID=60aabbccddeeff0011223344 SESSION_ID=abc123XYZ'"),
              1);
    Page other{direct(*web_)};
    other.open({{"participant", "someone"}, {"prolific", {{"PROLIFIC_PID", "else"}}}}, 400);
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
    resume(2);                  // a reload
    start_server();             // the server restarted: the token still holds
    Page page = resume(3);
    page.shown = shown;
    page.run();
    EXPECT_EQ(page.state["screen"], "done");
    EXPECT_EQ(responses(),
              static_cast<int64_t>(planned_trials(protocol_) * protocol_.questions.size()));
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
    const int64_t answered = count("SELECT count(*) FROM trials WHERE answered_utc IS NOT NULL");
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
    refused("answer", with([](json& b) { b["events"][0]["value"] = 0; }), 400, "rating 0 is outside 1..7");
    refused("answer", with([](json& b) { b["events"][0]["value"] = 8; }), 400, "rating 8 is outside 1..7");
    refused("answer", with([](json& b) { b["events"][0]["value"] = 2.5; }), 400, "outside 1..7");
    refused("answer", with([](json& b) { b["events"][0]["question"] = 2; }), 400, "question index 2");
    refused("answer", with([](json& b) { b["events"][0] = {{"t_ms", 1e4}, {"type", "key"}, {"key", "8"}}; }),
            400, "key '8' is outside every scale");
    refused("answer", with([](json& b) { b["events"][0] = {{"t_ms", 1e4}, {"type", "key"}, {"key", "Escape"}}; }),
            400, "unknown key");
    refused("answer", with([](json& b) { b["events"].erase(b["events"].size() - 1); }), 400,
            "do not rate every question and confirm");
    // Answered before the picture was on screen (events stamped before the onset).
    refused("answer", with([](json& b) {
                for (json& e : b["events"]) e["t_ms"] = b["onset_ms"].get<double>() - 1;
            }),
            400, "do not rate every question");
    refused("answer", with([](json& b) { b["onset_ms"] = 0; }), 400, "blank ended");
    refused("answer", with([](json& b) { b["events"][0]["t_ms"] = nullptr; }), 400, "'t_ms' is required");
    refused("answer", with([](json& b) { b["events"][0]["t_ms"] = -5; }), 400, "'t_ms' must lie in");
    refused("answer", with([](json& b) { b["events"] = json::array(); for (int i = 0; i < 600; ++i) b["events"].push_back({{"t_ms", 1}, {"type", "next"}}); }),
            400, "more than 500 events");
    refused("answer", with([&](json& b) { b["trial"] = page.shown[0]; }), 409, "trial 1 is already answered");
    refused("answer", with([&](json& b) { b["trial"] = other.shown[0]; }), 404, "not one of this session's trials");
    refused("answer", with([&](json& b) { b["token"] = other.token; }), 404, "not one of this session's trials");
    refused("answer", with([&](json& b) { b["view"] = b["view"].get<int>() + 7; }), 409, "no longer shown");
    refused("answer", with([&](json& b) { b["token"] = "P4.0000"; }), 403, "unknown session token");
    refused("answer", with([&](json& b) { b["token"] = "../../etc.x"; }), 403, "unknown session token");
    refused("answer", "{\"token\": ", 400, "malformed JSON");
    refused("answer", "[1, 2]", 400, "must be a JSON object");
    refused("answer", "{\"token\": \"\xff\xfe\"}", 400, "malformed JSON");  // not UTF-8
    refused("answer", "{\"token\": 5}", 400, "'token' must be a string");
    refused("answer", std::string(70 * 1024, ' '), 413, "over the limit");
    refused("answer", with([](json& b) { b["trial"] = std::string(5000, 'a'); }), 400, "longer than");
    refused("wipe", "{}", 404, "no API endpoint");
    refused("continue", json{{"token", page.token}, {"view", page.state["view"]}, {"shown_ms", 1}, {"t_ms", 2}}.dump(),
            409, "not continued with Enter");
    for (const std::string& code : std::vector<std::string>{"", "a b", "../P1", "P1;DROP TABLE", "<script>", std::string(65, 'x'), "P\xc3\xa9"})
        refused("session", json{{"participant", code}, {"t_ms", 1}}.dump(), 400, "participant code");
    refused("session", json{{"t_ms", 1}}.dump(), 400, "no participant code");
    refused("session", json{{"participant", "P9"}, {"t_ms", 1}, {"client", {{"user_agent", std::string(600, 'u')}}}}.dump(),
            400, "'user_agent' is longer than 512");
    EXPECT_EQ(count("SELECT count(*) FROM trials WHERE answered_utc IS NOT NULL"), answered);
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
    const WebReply again = web_->handle(
        "continue", json{{"token", page.token}, {"view", consent["view"]}, {"shown_ms", 1}, {"t_ms", 2}}.dump());
    EXPECT_EQ(again.status, 409);
    EXPECT_EQ(page.state["screen"], "instructions");
    // A key stamped before its screen was shown counts for nothing.
    const WebReply early = web_->handle(
        "continue", json{{"token", page.token}, {"view", page.state["view"]}, {"shown_ms", 5000}, {"t_ms", 4000}}.dump());
    EXPECT_EQ(early.status, 400) << early.body;

    Page no{direct(*web_)};
    no.open({{"participant", "P7"}});
    const json declined = no.call("decline", {{"view", no.state["view"]}, {"shown_ms", 60}, {"t_ms", 900}});
    EXPECT_EQ(declined["screen"], "declined");
    EXPECT_EQ(count("SELECT count(*) FROM sessions s JOIN participants p ON p.id = s.participant_id "
                    "WHERE p.code = 'P7' AND s.status = 'aborted' AND s.consent_utc IS NULL"),
              1);
    EXPECT_EQ(web_->live_sessions(), 1u);
}

// Fifty pages at once through one server (threads calling handle as the HTTP server's
// workers do): every answer stored exactly once, cells from the participant numbers.
TEST_P(Serve, FiftyParticipantsAtOnceLoseAndDuplicateNothing) {
    constexpr int kPages = 50;
    std::vector<std::thread> threads;
    std::atomic<int> finished{0};
    std::vector<std::vector<std::string>> shown(kPages);
    for (int i = 0; i < kPages; ++i)
        threads.emplace_back([&, i] {
            Page page{direct(*web_)};
            page.open({{"participant", "W" + std::to_string(i + 1)}});
            page.run();
            if (page.state["screen"] == "done") ++finished;
            shown[i] = page.shown;
        });
    for (std::thread& t : threads) t.join();
    EXPECT_EQ(finished, kPages);
    const int64_t n = static_cast<int64_t>(planned_trials(protocol_));
    EXPECT_EQ(responses(), kPages * n * static_cast<int64_t>(protocol_.questions.size()));
    EXPECT_EQ(count("SELECT count(*) FROM (SELECT trial_id, question FROM responses GROUP BY "
                    "trial_id, question HAVING count(*) > 1) d"),
              0);
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"), kPages);
    EXPECT_EQ(count("SELECT count(DISTINCT number) FROM participants"), kPages);
    for (int i = 0; i < kPages; ++i) EXPECT_EQ(static_cast<int64_t>(shown[i].size()), n);
}

INSTANTIATE_TEST_SUITE_P(Stores, Serve, ::testing::Values("sqlite", "postgresql"), param_name);

// ---- names, tokens, image paths (no store) ------------------------------------------------
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

TEST(ServeNames, OnlyProtocolPicturesByNameAreImages) {
    const std::map<std::string, WebImage> images = {{"emp1", {1, 1}}, {"b", {1, 1}}};
    EXPECT_EQ(image_of_target("/images/emp1.png", images), "emp1");
    EXPECT_EQ(image_of_target("/images/emp1.png?v=2", images), "emp1");
    EXPECT_EQ(image_of_target("/images/%65mp1.png", images), "emp1");  // an encoded letter
    for (const char* bad :
         {"/images/../study.db", "/images/..%2f..%2fetc%2fpasswd", "/images/%2e%2e/b.png",
          "/images/%2E%2E%2Fb.png", "/images/%252e%252e%252fb.png", "/images/b.png%00.txt",
          "/images//b.png", "/images/sub/b.png", "/images/b.PNG", "/images/c.png", "/b.png",
          "/images/.png", "/images/b.png/", "/images/%zz.png", "/images/b.png%", "/IMAGES/b.png",
          "/images/..\\b.png"})
        EXPECT_FALSE(image_of_target(bad, images)) << bad;
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

}  // namespace
}  // namespace lucent::study
