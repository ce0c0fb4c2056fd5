// Several `lucent serve` instances behind Debian's nginx on one PostgreSQL server, as a
// study is deployed (docs/deploy.md), driven through the proxy by scripted participants
// speaking the JSON API as lucent.js does (retries with backoff on a network error, 502,
// 503 and 504; a restart with the token on 409), with think times scaled down. In the
// middle one instance is killed with SIGKILL and restarted, or the PostgreSQL server is
// restarted (fast shutdown, start). Afterwards every participant has completed, every
// answer is stored exactly once, and the counterbalancing cells are balanced.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "app/nginx_proxy.h"
#include "study/postgres/local_server.h"
#include "study/protocol.h"
#include "study/study_store.h"
#include "study/trial_plan.h"
#include "tests/study/serve/serve_process.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::Page;
using nlohmann::json;

// The serve test study with its one block split in two: two counterbalancing cells.
std::string write_two_block_study(const std::filesystem::path& dir) {
    const std::string path = lucent::test::write_serve_study(dir);
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    const std::string main =
        "[[blocks]]\nid = \"main\"\nstimuli = [\"a\", \"b\", \"c\"]\n";
    text.replace(text.find(main), main.size(),
                 "[[blocks]]\nid = \"main\"\nstimuli = [\"a\", \"b\"]\n\n"
                 "[[blocks]]\nid = \"second\"\nstimuli = [\"c\"]\n");
    std::ofstream(path) << text;
    return path;
}

// What a participant's page met on its way (for the test's report).
struct Encounters {
    lucent::test::Retries retries;   // network errors, 502, 503, 504: sent again
    std::atomic<int> restarted{0};   // 409: started again with the token
    std::atomic<int> duplicates{0};  // an answer already stored (a retry's twin)
};

// The API over one keep-alive connection to the proxy, each request sent again on a
// network error, 502, 503 or 504 exactly as lucent.js does (web_page.h's retrying).
lucent::test::Transport retrying(httplib::Client& client, Encounters& seen) {
    return lucent::test::retrying(lucent::test::over_http(client), &seen.retries);
}

// One scripted participant from the link to the completion screen: Enter on text
// screens, every trial rated by clicks, a think time before each action. "" when done,
// else why not.
std::string run_participant(const std::string& base_url, const std::string& code,
                            std::mt19937& rng, Encounters& seen) {
    httplib::Client client(base_url);
    client.set_keep_alive(true);
    client.set_connection_timeout(2);
    client.set_read_timeout(30);
    Page page{retrying(client, seen)};
    page.catch_rating = 5;  // the catch trial asks for 5 (the 5-point scale's top)
    std::uniform_int_distribution<int> think_ms(5, 25);
    auto think = [&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(think_ms(rng)));
    };
    auto open = [&]() -> std::string {
        json link{{"participant", code}, {"t_ms", page.now}};
        if (!page.token.empty()) link["token"] = page.token;
        page.who = {{"participant", code}};
        const study::WebReply r = page.request("session", link);
        if (r.status != 200) return "session: " + std::to_string(r.status) + " " + r.body;
        page.state = json::parse(r.body);
        if (page.state.contains("token")) page.token = page.state["token"];
        return "";
    };
    if (std::string why = open(); !why.empty()) return why;
    for (int step = 0; step < 60; ++step) {
        const std::string screen = page.state.value("screen", "");
        if (screen == "done") return "";
        think();
        study::WebReply r;
        if (screen == "trial") {
            json body = page.answer_body(static_cast<int>(page.shown.size()));
            const std::string trial = page.state["trial"]["id"];
            page.now = body["onset_ms"].get<double>() + 1000;
            r = page.request("answer", body);
            if (r.status == 200) {
                const json reply = json::parse(r.body);
                if (reply.value("already_answered", false)) ++seen.duplicates;
                if (page.shown.empty() || page.shown.back() != trial)
                    page.shown.push_back(trial);
            }
        } else {
            const double shown_at = page.now;
            page.now += 300;
            r = page.request("continue", {{"view", page.state["view"]},
                                          {"shown_ms", shown_at},
                                          {"t_ms", page.now}});
        }
        if (r.status == 200) {
            page.state = json::parse(r.body);
            continue;
        }
        if (r.status == 409) {  // behind the server: start again with the token
            ++seen.restarted;
            if (std::string why = open(); !why.empty()) return why;
            continue;
        }
        return screen + ": " + std::to_string(r.status) + " " + r.body;
    }
    return "no completion after 60 actions (screen " + page.state.dump().substr(0, 80) +
           ")";
}

class ServeInstances : public ::testing::Test {
protected:
    static constexpr int kInstances = 3;
    static constexpr int kParticipants = 300;
    static constexpr int kConcurrent = 40;  // pages open at once

    void SetUp() override {
        if (!lucent::app::NginxProxy::available())
            GTEST_SKIP() << "Debian's nginx is not installed (scripts/install-deps)";
        if (LocalPostgres::binary_dir().empty())
            GTEST_SKIP() << "no PostgreSQL server binaries (scripts/install-deps)";
        dir_ = lucent::test::scratch_dir(
            std::string("serve_instances_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        pg_ = std::make_unique<LocalPostgres>();
        uri_ = pg_->create_database("instances");
        init_study_store(uri_);
        protocol_ = write_two_block_study(dir_);
        key_ = lucent::test::write_serve_key(dir_);
        for (int i = 0; i < kInstances; ++i) {
            ports_.push_back(lucent::test::free_loopback_port());
            start_instance(i);
        }
        proxy_ = std::make_unique<lucent::app::NginxProxy>(ports_);
    }
    void start_instance(int i) {
        instances_.resize(kInstances);
        instances_[i].reset();
        instances_[i] =
            lucent::test::start_serve_instance(protocol_, uri_, dir_, i, ports_[i], key_);
        ASSERT_EQ(instances_[i]->port(), ports_[i])
            << "instance " << i << " did not start: " << instances_[i]->first_line();
    }
    int64_t count(const std::string& sql) {
        return open_study_store(uri_)->query_int(sql);
    }

    // kParticipants through the proxy, kConcurrent at a time; `midway` runs once a third
    // of them completed. Checks that every one completed and every answer is stored once.
    void run_study(const std::function<void()>& midway) {
        std::atomic<int> next{0}, completed{0};
        std::mutex failures_mutex;
        std::vector<std::string> failures;
        Encounters seen;
        const auto started = std::chrono::steady_clock::now();
        std::vector<std::thread> pages;
        for (int t = 0; t < kConcurrent; ++t)
            pages.emplace_back([&, t] {
                std::mt19937 rng(1000 + t);
                for (int i; (i = next++) < kParticipants;) {
                    const std::string why = run_participant(
                        proxy_->url(), "S" + std::to_string(i + 1), rng, seen);
                    if (why.empty()) {
                        ++completed;
                    } else {
                        std::lock_guard lock(failures_mutex);
                        failures.push_back("S" + std::to_string(i + 1) + ": " + why);
                    }
                }
            });
        while (completed < kParticipants / 3 && next < kParticipants)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        const int completed_before = completed;
        midway();
        for (std::thread& t : pages) t.join();
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started)
                .count();
        std::cout << "[ instances] " << kParticipants << " participants, " << kConcurrent
                  << " at once, through nginx over " << kInstances << " instances in "
                  << seconds << " s; " << completed_before
                  << " had completed at the failure; retried " << seen.retries.sent_again
                  << " requests, restarted " << seen.restarted << " pages, "
                  << seen.duplicates << " answers arrived twice (stored once)\n";
        for (const std::string& f : failures) ADD_FAILURE() << f;
        EXPECT_EQ(completed, kParticipants);

        const Protocol protocol = load_protocol_file(protocol_);
        const int64_t trials =
            static_cast<int64_t>(plan_trials(protocol, 0, 0).trials.size());
        const int64_t questions = static_cast<int64_t>(protocol.questions.size());
        EXPECT_EQ(count("SELECT count(*) FROM participants"), kParticipants);
        EXPECT_EQ(count("SELECT count(*) FROM sessions"), kParticipants);
        EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"),
                  kParticipants);
        EXPECT_EQ(count("SELECT count(*) FROM responses"),
                  kParticipants * trials * questions);
        EXPECT_EQ(count("SELECT count(*) FROM (SELECT trial_id, question FROM responses "
                        "GROUP BY trial_id, question HAVING count(*) > 1) d"),
                  0);
        EXPECT_EQ(count("SELECT count(*) FROM trials WHERE answered_utc IS NULL"), 0);
        EXPECT_EQ(count("SELECT count(DISTINCT number) FROM participants"),
                  kParticipants);
        // Two cells, handed out by arrival to the one with fewer sessions.
        const int64_t first = count("SELECT count(*) FROM sessions WHERE cell = 0");
        const int64_t second = count("SELECT count(*) FROM sessions WHERE cell = 1");
        EXPECT_EQ(first + second, kParticipants);
        EXPECT_LE(std::abs(first - second), 1) << first << " vs " << second;
    }

    std::filesystem::path dir_;
    std::unique_ptr<LocalPostgres> pg_;
    std::string uri_, protocol_, key_;
    std::vector<int> ports_;
    std::vector<std::unique_ptr<lucent::test::ServeProcess>> instances_;
    std::unique_ptr<lucent::app::NginxProxy> proxy_;
};

TEST_F(ServeInstances, ThreeInstancesLoseNothingWhenOneIsKilledAndRestarted) {
    run_study([&] {
        EXPECT_EQ(instances_[1]->kill_now(), 128 + SIGKILL);
        std::this_thread::sleep_for(std::chrono::seconds(1));
        start_instance(1);  // on its port again: the proxy sends it requests anew
    });
}

TEST_F(ServeInstances, ParticipantsWaitOutAPostgresRestartAndLoseNothing) {
    run_study([&] {
        pg_->stop();  // fast shutdown: every connection cut, committed data kept
        std::this_thread::sleep_for(std::chrono::seconds(1));
        pg_->start();
    });
}

// docs/deploy.md's change of instances while a study runs: the proxy starts over two
// instances; a third is added (a reload), then the first two are drained (a reload
// without them) and stopped. The rest of the study goes through the new one alone, and
// nothing is lost or doubled.
TEST_F(ServeInstances, AnInstanceAddedWhileAStudyRunsTakesItOverFromTheOthers) {
    proxy_->reload({ports_[0], ports_[1]});
    run_study([&] {
        proxy_->reload(ports_);       // add instance 2
        proxy_->reload({ports_[2]});  // drain 0 and 1
        EXPECT_EQ(instances_[0]->stop(), 0);
        EXPECT_EQ(instances_[1]->stop(), 0);
    });
}

// Today's hostile requests across instances: a token answers only for its own
// participant on every instance (directly and through the proxy), a refusal stores
// nothing, and an instance that cannot reach PostgreSQL says so (503 with Retry-After,
// /healthz failing) instead of accepting an answer.
TEST_F(ServeInstances, TokensHoldOnEveryInstanceAndNoInstanceAcceptsWithoutTheServer) {
    httplib::Client via_proxy(proxy_->url());
    Encounters seen;
    Page a{retrying(via_proxy, seen)}, b{retrying(via_proxy, seen)};
    a.catch_rating = b.catch_rating = 5;
    a.open({{"participant", "H1"}});
    b.open({{"participant", "H2"}});
    a.run(1);
    b.run(1);
    while (a.state["screen"] != "trial") a.enter();
    while (b.state["screen"] != "trial") b.enter();
    const int64_t stored = count("SELECT count(*) FROM responses");
    std::vector<std::unique_ptr<httplib::Client>> direct;
    for (int port : ports_)
        direct.push_back(std::make_unique<httplib::Client>("127.0.0.1", port));
    direct.push_back(std::make_unique<httplib::Client>(proxy_->url()));
    for (size_t i = 0; i < direct.size(); ++i) {
        httplib::Client& http = *direct[i];
        const std::string where =
            i < ports_.size() ? "instance " + std::to_string(i) : "proxy";
        auto post = [&](const json& body) {
            const auto r = http.Post("/api/answer", body.dump(), "application/json");
            EXPECT_TRUE(r) << where;
            return r ? r->status : 0;
        };
        json answer = a.answer_body(static_cast<int>(a.shown.size()));
        answer["token"] = b.token;  // B's token on A's trial
        EXPECT_EQ(post(answer), 404) << where;
        answer["token"] = "H1.x";  // an earlier serve's form, not H1's
        EXPECT_EQ(post(answer), 403) << where;
        // A's token with B's code put in front: the signature no longer holds.
        answer["token"] = "H2" + a.token.substr(a.token.find('.'));
        EXPECT_EQ(post(answer), 403) << where;
        answer["token"] =
            a.token.substr(0, a.token.size() - 1) + (a.token.back() == '0' ? "1" : "0");
        EXPECT_EQ(post(answer), 403) << where;
        const auto health = http.Get("/healthz");
        ASSERT_TRUE(health) << where;
        EXPECT_EQ(health->status, 200) << where << ": " << health->body;
    }
    EXPECT_EQ(count("SELECT count(*) FROM responses"), stored);

    pg_->stop();
    for (size_t i = 0; i < ports_.size(); ++i) {
        httplib::Client& http = *direct[i];
        const auto health = http.Get("/healthz");
        ASSERT_TRUE(health);
        EXPECT_EQ(health->status, 503) << "instance " << i << ": " << health->body;
        json answer = a.answer_body(static_cast<int>(a.shown.size()));
        answer["token"] = a.token;
        const auto r = http.Post("/api/answer", answer.dump(), "application/json");
        ASSERT_TRUE(r);
        EXPECT_EQ(r->status, 503) << "instance " << i << ": " << r->body;
        EXPECT_EQ(r->get_header_value("Retry-After"), "1");
    }
    pg_->start();
    EXPECT_EQ(count("SELECT count(*) FROM responses"), stored);
    for (size_t i = 0; i < ports_.size(); ++i) {
        const auto health = direct[i]->Get("/healthz");
        ASSERT_TRUE(health);
        EXPECT_EQ(health->status, 200) << "instance " << i << ": " << health->body;
    }
    // The page goes on once the server is back: the answer it could not send, then on.
    a.run();
    EXPECT_EQ(a.state["screen"], "done");
}

}  // namespace
}  // namespace lucent::study
