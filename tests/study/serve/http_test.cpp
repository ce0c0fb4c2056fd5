// The real `lucent serve` over loopback, on every store backend: hostile HTTP requests,
// and 50 simulated participants at once. Expected values come from the study folder the
// test wrote (pictures of known bytes, the protocol's trial count and scales).
#include <OpenImageIO/imageio.h>
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>

#include "study/protocol.h"
#include "study/serve/picture_names.h"
#include "study/study_store.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/serve/serve_process.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::json;
using lucent::test::Page;

class ServeHttp : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        const std::string test =
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::string slug;
        for (char c : test)
            slug +=
                std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
        dir_ = lucent::test::scratch_dir("serve_http_" + slug);
        protocol_ = lucent::test::write_serve_study(dir_);
        if (GetParam() == "sqlite") {
            db_ = (dir_ / "study.db").string();
        } else {
            db_ = lucent::test::new_postgres_database("serve_http_" + slug);
            init_study_store(db_);
        }
        server_ =
            std::make_unique<lucent::test::ServeProcess>(protocol_, db_, dir_.string());
        ASSERT_GT(server_->port(), 0)
            << "lucent serve did not start: " << server_->first_line();
    }
    // Counts read through a store of its own (the server holds its own connection).
    int64_t count(const std::string& sql) {
        StoreOptions options;
        options.journal_path = (dir_ / "reader-journal.db").string();
        return open_study_store(db_, options)->query_int(sql);
    }

    std::filesystem::path dir_;
    std::string protocol_, db_;
    std::unique_ptr<lucent::test::ServeProcess> server_;
};

// A picture file's RGB values (OIIO, independent of the server's own decoding).
std::vector<uint8_t> rgb_pixels(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    const OIIO::ImageSpec spec = in->spec();
    std::vector<uint8_t> rgb(static_cast<size_t>(spec.width) * spec.height * 3);
    in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb.data());
    return rgb;
}

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    return info.param;
}

TEST_P(ServeHttp, HostileRequestsGetA4xxWithOneLineAndNothingIsServedOrStored) {
    httplib::Client http("127.0.0.1", server_->port());
    // The page and a picture, as the browser asks for them.
    auto page = http.Get("/?participant=P1");
    ASSERT_TRUE(page);
    EXPECT_EQ(page->status, 200);
    EXPECT_NE(page->body.find("<script src=\"/lucent.js\">"), std::string::npos);
    EXPECT_EQ(page->get_header_value("X-Content-Type-Options"), "nosniff");

    // Paths out of the pictures, plain and encoded: never a file, always a 404.
    std::ofstream(dir_ / "secret.txt") << "not for participants";
    const std::string db_name = std::filesystem::path(db_).filename().string();
    for (const std::string& target : std::vector<std::string>{
             "/images/../study.toml", "/images/..%2fstudy.toml",
             "/images/%2e%2e%2fstudy.toml", "/images/%2E%2E/secret.txt",
             "/images/%252e%252e%252fsecret.txt", "/images/a.png%00.txt",
             "/../secret.txt", "/%2e%2e/secret.txt", "/images/..%5csecret.txt",
             "/images/" + db_name, "/images/../" + db_name, "/etc/passwd",
             "/../../../../etc/passwd", "/images/a.png/../../secret.txt", "/secret.txt",
             "/study.toml", "/a.png", "/images/a.png"}) {
        auto r = http.Get(target.c_str());
        ASSERT_TRUE(r) << target;
        EXPECT_EQ(r->status, 404) << target;
        EXPECT_EQ(r->body.find("not for participants"), std::string::npos) << target;
        EXPECT_EQ(r->body.find("SQLite"), std::string::npos) << target;
        EXPECT_EQ(r->body.find("root:"), std::string::npos) << target;
        EXPECT_EQ(r->body.find('\n'), std::string::npos) << target;
    }
    // No endpoint reads data out: unknown API names, other methods.
    for (const char* name : {"export", "responses", "participants", "sessions", "dump"}) {
        auto r =
            http.Post((std::string("/api/") + name).c_str(), "{}", "application/json");
        ASSERT_TRUE(r);
        EXPECT_EQ(r->status, 404) << name;
    }
    auto get_api = http.Get("/api/session");
    ASSERT_TRUE(get_api);
    EXPECT_EQ(get_api->status, 404);
    auto put = http.Put("/api/session", "{}", "application/json");
    ASSERT_TRUE(put);
    EXPECT_GE(put->status, 400);
    EXPECT_LT(put->status, 500);

    // Bodies and fields out of bounds, malformed JSON, bad codes: 4xx, one line.
    auto post = [&](const std::string& endpoint, const std::string& body, int status) {
        auto r = http.Post(("/api/" + endpoint).c_str(), body, "application/json");
        ASSERT_TRUE(r) << body.substr(0, 80);
        EXPECT_EQ(r->status, status) << body.substr(0, 80) << " -> " << r->body;
        const json reply = json::parse(r->body, nullptr, false);
        EXPECT_TRUE(reply.is_object() && reply.contains("error")) << r->body;
        EXPECT_EQ(r->body.find('\n'), std::string::npos);
    };
    post("session", std::string(100 * 1024, '{'), 413);
    post("session", "{\"participant\": ", 400);
    post("session", "{\"participant\": \"\xff\"}", 400);
    post("session", json{{"participant", "../../P1"}, {"t_ms", 1}}.dump(), 400);
    post("session", json{{"participant", std::string(1000, 'x')}, {"t_ms", 1}}.dump(),
         400);
    // A number beyond a double: 400 naming the field, not a 500 (issue 26 item 10).
    post("session", "{\"participant\": \"P1\", \"t_ms\": 1e999}", 400);
    {
        auto r = http.Post("/api/session", "{\"participant\": \"P1\", \"t_ms\": -1e999}",
                           "application/json");
        ASSERT_TRUE(r);
        EXPECT_NE(r->body.find("'t_ms'"), std::string::npos) << r->body;
    }
    // A participant with a session, then someone else's requests against it.
    Page p1{lucent::test::over_http(http)};
    p1.catch_rating = 5;  // the catch trial asks for 5 (the 5-point scale's top)
    p1.open({{"participant", "P1"}});
    ASSERT_EQ(p1.state["screen"], "consent");
    p1.run(1);  // consent, instructions, the practice trial, the practice-done screen
    ASSERT_EQ(p1.state["screen"], "trial");
    // The trial's picture, by the name the page was given (never by its stimulus id:
    // "/images/a.png" is a 404 above); asked again, the same bytes.
    const std::string picture_url = p1.state["trial"]["image"];
    auto picture = http.Get(picture_url.c_str());
    ASSERT_TRUE(picture);
    EXPECT_EQ(picture->status, 200);
    EXPECT_EQ(picture->get_header_value("Content-Type"), "image/png");
    EXPECT_EQ(picture->body.substr(1, 3), "PNG");
    auto again = http.Get(picture_url.c_str());
    ASSERT_TRUE(again);
    EXPECT_EQ(again->body, picture->body);
    // Another serving of the picture (the name another trial gets, minted with the
    // server's key): other bytes, and both the file's picture within one step per
    // channel (issue 44, item 4).
    {
        const std::string key =
            GetParam() == "sqlite" ? db_ + "-serve-key" : (dir_ / "serve.key").string();
        std::ifstream key_in(key, std::ios::binary);
        const std::string secret(std::istreambuf_iterator<char>(key_in), {});
        std::vector<std::string> ids;
        for (const Stimulus& s : load_protocol_file(protocol_).stimuli)
            ids.push_back(s.id);
        const PictureNames names(secret, ids);
        const std::optional<NamedPicture> named = names.picture(picture_url);
        ASSERT_TRUE(named) << picture_url;
        auto other = http.Get(names.url("another trial", 0, named->id).c_str());
        ASSERT_TRUE(other);
        ASSERT_EQ(other->status, 200);
        EXPECT_NE(other->body, picture->body);
        const std::vector<uint8_t> file =
            rgb_pixels((dir_ / (named->id + ".png")).string());
        for (const std::string& png : {picture->body, other->body}) {
            const std::string path = (dir_ / "served.png").string();
            std::ofstream(path, std::ios::binary) << png;
            const std::vector<uint8_t> served = rgb_pixels(path);
            ASSERT_EQ(served.size(), file.size());
            int largest = 0;
            for (size_t i = 0; i < file.size(); ++i)
                largest = std::max(largest, std::abs(int(served[i]) - int(file[i])));
            EXPECT_EQ(largest, 1);
        }
    }
    json bad = p1.answer_body(1);
    bad["token"] = p1.token;
    bad["events"][0]["value"] = 8;
    post("answer", bad.dump(), 400);
    bad["events"][0]["value"] = 0;
    post("answer", bad.dump(), 400);
    bad = p1.answer_body(1);
    bad["token"] = "P1." + std::string(64, 'f');
    post("answer", bad.dump(), 403);
    bad["token"] = p1.token;
    bad["trial"] = p1.shown[0];
    {
        // The answered practice trial again (a retried request): stored once, 200.
        auto r = http.Post("/api/answer", bad.dump(), "application/json");
        ASSERT_TRUE(r);
        EXPECT_EQ(r->status, 200) << r->body;
        EXPECT_EQ(json::parse(r->body)["already_answered"], true) << r->body;
    }
    post("session", json{{"participant", "P1"}, {"t_ms", 1}}.dump(), 403);  // no key
    // A URI too long for the server: refused before routing.
    auto long_uri = http.Get(("/images/" + std::string(20000, 'a') + ".png").c_str());
    ASSERT_TRUE(long_uri);
    EXPECT_EQ(long_uri->status, 414);

    EXPECT_EQ(count("SELECT count(*) FROM responses"), 2);  // the practice trial only
    EXPECT_EQ(count("SELECT count(*) FROM participants"), 1);
    p1.answer(1);
    EXPECT_EQ(count("SELECT count(*) FROM responses"), 4);
    EXPECT_EQ(server_->stop(), 0);
}

// 50 pages at once over loopback, each on its own connection and retrying a 503 (every
// pooled connection busy) as lucent.js does; every answer stored once. The time taken
// is printed, not asserted.
TEST_P(ServeHttp, FiftyParticipantsAtOnceOverHttpLoseAndDuplicateNothing) {
    constexpr int kPages = 50;
    std::atomic<int> done{0};
    lucent::test::Retries retries;
    std::vector<std::thread> threads;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < kPages; ++i)
        threads.emplace_back([&, i] {
            httplib::Client http("127.0.0.1", server_->port());
            http.set_keep_alive(true);
            http.set_read_timeout(60);
            Page page{lucent::test::retrying(lucent::test::over_http(http), &retries)};
            page.catch_rating = 5;
            page.open({{"participant", "W" + std::to_string(i + 1)}});
            page.run();
            if (page.state["screen"] == "done" &&
                page.state["completion"]["code"] == "C0DE42" &&
                page.shown.size() == size_t(lucent::test::kServeStudyTrials))
                ++done;
        });
    for (std::thread& t : threads) t.join();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(done, kPages);
    std::printf(
        "[ measured ] %d participants x %d trials over HTTP (%s): %.2f s, %.0f "
        "trials/s, %d requests sent again\n",
        kPages, lucent::test::kServeStudyTrials, GetParam().c_str(), seconds,
        kPages * lucent::test::kServeStudyTrials / seconds, retries.sent_again.load());
    EXPECT_EQ(server_->stop(), 0);
    EXPECT_EQ(count("SELECT count(*) FROM responses"),
              kPages * lucent::test::kServeStudyTrials * 2);
    EXPECT_EQ(
        count("SELECT count(*) FROM (SELECT trial_id, question FROM responses GROUP BY "
              "trial_id, question HAVING count(*) > 1) d"),
        0);
    EXPECT_EQ(count("SELECT count(*) FROM sessions WHERE status = 'completed'"), kPages);
    // Catch trials answered as asked (5 on both scales), so nobody is excluded.
    EXPECT_EQ(count("SELECT count(*) FROM responses r JOIN trials t ON t.id = r.trial_id "
                    "WHERE t.catch = 1 AND r.rating = 5"),
              kPages * 2);
}

// Issue 26 item 10: slow clients trickling header lines are cut at the request deadline,
// so two of them cannot hold a 2-worker server; a normal request is answered. The slow
// clients trickle until the server closes them (a minute only as the point where the
// test gives up), so the normal request is answered while they would still be
// trickling, or only because the server cut them; how long either took is not asserted.
TEST_P(ServeHttp, SlowClientsTricklingHeadersAreCutAndANormalRequestIsAnswered) {
    if (GetParam() != "sqlite")
        GTEST_SKIP() << "the HTTP layer is the same for every store";
    server_.reset();
    server_ = std::make_unique<lucent::test::ServeProcess>(
        protocol_, db_, dir_.string(),
        std::vector<std::string>{"--threads", "2", "--request-timeout", "0.5"});
    ASSERT_GT(server_->port(), 0) << server_->first_line();
    auto connect_slow = [&] {
        const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(static_cast<uint16_t>(server_->port()));
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
        const std::string line = "POST /api/session HTTP/1.1\r\nHost: x\r\n";
        ::send(fd, line.data(), line.size(), MSG_NOSIGNAL);
        return fd;
    };
    const int slow[2] = {connect_slow(), connect_slow()};
    std::atomic<int> trickled{0};  // header lines sent after the request line
    std::atomic<int> cut{0};
    std::atomic<int> gave_up{0};
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    // Each slow client sends one more header line every 200 ms (well within the read
    // timeout) until the server closes its connection.
    std::vector<std::thread> trickle;
    for (int fd : slow)
        trickle.emplace_back([&, fd] {
            for (;;) {
                if (std::chrono::steady_clock::now() > give_up) {
                    ++gave_up;
                    return;
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(200));
                const std::string header = "X-Slow: 1\r\n";
                char byte = 0;
                const bool closed =
                    ::send(fd, header.data(), header.size(), MSG_NOSIGNAL) < 0 ||
                    ::recv(fd, &byte, 1, MSG_DONTWAIT) == 0;
                if (closed) {
                    ++cut;
                    return;
                }
                ++trickled;
            }
        });
    // Both slow requests under way (each has trickled a line, or was cut already).
    while (trickled + cut < 2 && std::chrono::steady_clock::now() < give_up)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    // The normal request, retried as lucent.js retries a network error or a 502/503/504.
    httplib::Client http("127.0.0.1", server_->port());
    http.set_read_timeout(60);
    const lucent::test::Transport get_page =
        lucent::test::retrying([&http](const std::string&, const std::string&) {
            const httplib::Result r = http.Get("/");
            return r ? WebReply{r->status, r->body}
                     : WebReply{0, "no reply: " + httplib::to_string(r.error())};
        });
    const auto asked = std::chrono::steady_clock::now();
    const WebReply page = get_page("/", "");
    const double answered_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
    const int slow_still_held = 2 - cut.load();  // neither cut nor given up yet
    for (std::thread& t : trickle) t.join();
    for (int fd : slow) ::close(fd);
    EXPECT_EQ(page.status, 200) << page.body;
    // The server closed both slow clients; neither trickled until the test gave up.
    EXPECT_EQ(cut, 2);
    EXPECT_EQ(gave_up, 0);
    std::printf(
        "[ measured ] a normal request answered after %.2f s beside 2 slow clients (%d "
        "still trickling then)\n",
        answered_s, slow_still_held);
    EXPECT_EQ(server_->stop(), 0);
}

INSTANTIATE_TEST_SUITE_P(Stores, ServeHttp, ::testing::Values("sqlite", "postgresql"),
                         param_name);

}  // namespace
}  // namespace lucent::study
