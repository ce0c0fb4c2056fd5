// The nginx harness (app/nginx_proxy.h) the multi-instance serve tests stand
// on: Debian's nginx round-robins over small httplib servers on loopback, routes around
// a stopped one, passes bodies through and takes a new upstream on reload.
#include "app/nginx_proxy.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <chrono>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/study/serve/web_page.h"

namespace lucent::test {
namespace {
using app::NginxProxy;

// A tiny upstream: GET /who answers its name, POST /echo its request body.
class Upstream {
public:
    explicit Upstream(std::string name) : name_(std::move(name)) {
        server_.Get("/who", [this](const httplib::Request&, httplib::Response& res) {
            res.set_content(name_, "text/plain");
        });
        server_.Post("/echo", [](const httplib::Request& req, httplib::Response& res) {
            res.set_content(req.body, "application/octet-stream");
        });
        // stop() waits for open keep-alive connections (nginx keeps some to each
        // upstream) to time out: 1 s, not httplib's 5.
        server_.set_keep_alive_timeout(1);
        port_ = server_.bind_to_any_port("127.0.0.1");
        thread_ = std::thread([this] { server_.listen_after_bind(); });
    }
    ~Upstream() { stop(); }
    void stop() {
        if (!thread_.joinable()) return;
        server_.stop();
        thread_.join();
    }
    int port() const { return port_; }
    const std::string& name() const { return name_; }

private:
    std::string name_;
    httplib::Server server_;
    std::thread thread_;
    int port_ = -1;
};

class NginxProxyTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (!NginxProxy::available())
            GTEST_SKIP() << NginxProxy::kBinary
                         << " not found: install Debian's nginx (scripts/install-deps)";
        a_ = std::make_unique<Upstream>("a");
        b_ = std::make_unique<Upstream>("b");
        ASSERT_GT(a_->port(), 0);
        ASSERT_GT(b_->port(), 0);
    }
    static std::unique_ptr<httplib::Client> client(const NginxProxy& proxy) {
        auto c = std::make_unique<httplib::Client>(proxy.url());
        c->set_connection_timeout(2);
        c->set_read_timeout(5);
        return c;
    }
    // Who answered each of `n` GET /who through the proxy ("error N" for a failure). Each
    // request is retried as the page retries (web_page.h: no reply, 502, 503, 504): on a
    // loaded machine an upstream may be slow enough for nginx to give up on it once,
    // which the page waits out; what is asserted is who finally answers.
    static std::map<std::string, int> who(const NginxProxy& proxy, int n) {
        auto c = client(proxy);
        std::map<std::string, int> seen;
        for (int i = 0; i < n; ++i) {
            auto r = c->Get("/who");
            for (std::size_t attempt = 0;
                 attempt < lucent::test::kRetryDelaysMs.size() &&
                 (!r || lucent::test::transient_status(r->status));
                 ++attempt) {
                std::this_thread::sleep_for(
                    std::chrono::milliseconds(lucent::test::kRetryDelaysMs[attempt]));
                r = c->Get("/who");
            }
            if (!r)
                ++seen["no reply: " + httplib::to_string(r.error())];
            else if (r->status != 200)
                ++seen["status " + std::to_string(r->status)];
            else
                ++seen[r->body];
        }
        return seen;
    }
    std::unique_ptr<Upstream> a_, b_;
};

TEST_F(NginxProxyTest, RoundRobinsOverTheUpstreams) {
    NginxProxy proxy({a_->port(), b_->port()});
    EXPECT_GT(proxy.port(), 0);
    EXPECT_EQ(proxy.url(), "http://127.0.0.1:" + std::to_string(proxy.port()));
    const auto seen = who(proxy, 10);
    ASSERT_EQ(seen.size(), 2u) << "answered by: " << ::testing::PrintToString(seen);
    EXPECT_NEAR(seen.at("a"), 5, 1);
    EXPECT_NEAR(seen.at("b"), 5, 1);
}

TEST_F(NginxProxyTest, RoutesAroundAStoppedUpstream) {
    NginxProxy proxy({a_->port(), b_->port()});
    EXPECT_EQ(who(proxy, 2).size(), 2u);  // both answered, and keep-alive opened to both
    a_->stop();
    const auto seen = who(proxy, 10);
    EXPECT_EQ(seen, (std::map<std::string, int>{{"b", 10}}))
        << "answered by: " << ::testing::PrintToString(seen);
}

TEST_F(NginxProxyTest, PassesRequestBodiesThroughUnchanged) {
    NginxProxy proxy({a_->port(), b_->port()});
    auto c = client(proxy);
    std::string body;
    for (int i = 0; i < 200000; ++i) body += static_cast<char>((i * 7919) % 256);
    for (int i = 0; i < 2; ++i) {  // once to each upstream
        const auto r = c->Post("/echo", body, "application/octet-stream");
        ASSERT_TRUE(r) << httplib::to_string(r.error());
        EXPECT_EQ(r->status, 200);
        EXPECT_TRUE(r->body == body)
            << "a body of " << r->body.size() << " bytes came back";
    }
    // client_max_body_size 1m: larger bodies never reach an instance.
    const auto big = c->Post("/echo", std::string(2 << 20, 'x'), "text/plain");
    ASSERT_TRUE(big) << httplib::to_string(big.error());
    EXPECT_EQ(big->status, 413);
}

TEST_F(NginxProxyTest, ReloadAddsAnUpstream) {
    Upstream c("c");  // running, but not yet behind the proxy
    NginxProxy proxy({a_->port(), b_->port()});
    EXPECT_EQ(who(proxy, 4), (std::map<std::string, int>{{"a", 2}, {"b", 2}}));
    const int port = proxy.port();
    proxy.reload({a_->port(), b_->port(), c.port()});
    EXPECT_EQ(proxy.port(), port);
    EXPECT_TRUE(proxy.running());
    const auto seen = who(proxy, 9);
    ASSERT_EQ(seen.size(), 3u) << "answered by: " << ::testing::PrintToString(seen);
    EXPECT_NEAR(seen.at("c"), 3, 1) << ::testing::PrintToString(seen);
}

TEST_F(NginxProxyTest, RetriesPostsOnlyWhenAsked) {
    const auto config = [](const NginxProxy& proxy) {
        std::ifstream in(proxy.config_path());
        std::ostringstream text;
        text << in.rdbuf();
        return text.str();
    };
    NginxProxy retrying({a_->port()});
    EXPECT_NE(config(retrying).find("http_503 non_idempotent;"), std::string::npos);
    NginxProxy::Options options;
    options.retry_non_idempotent = false;
    NginxProxy plain({a_->port()}, options);
    EXPECT_EQ(config(plain).find("non_idempotent"), std::string::npos);
    EXPECT_EQ(who(plain, 1), (std::map<std::string, int>{{"a", 1}}));
}

TEST_F(NginxProxyTest, LeavesNothingBehind) {
    std::filesystem::path prefix;
    int port = 0;
    {
        NginxProxy proxy({a_->port()});
        prefix = proxy.prefix();
        port = proxy.port();
        EXPECT_TRUE(std::filesystem::exists(proxy.config_path()));
    }
    EXPECT_FALSE(std::filesystem::exists(prefix));
    httplib::Client c("http://127.0.0.1:" + std::to_string(port));
    c.set_connection_timeout(1);
    EXPECT_FALSE(c.Get("/who")) << "something still answers on the proxy's port";
}

}  // namespace
}  // namespace lucent::test
