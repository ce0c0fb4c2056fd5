// A real headless chromium through Debian's nginx in front of two `lucent serve`
// instances on one PostgreSQL database (issue 32, docs/deploy.md): one instance is
// killed with SIGKILL in the middle of the session (nginx fails over to the other), then
// the other one too while instance 0 is restarted on its port (nginx answers 502 and
// lucent.js retries with backoff). The page, pressed on as a person would, reaches the
// completion screen by itself; every answer is stored once, as pressed. Nothing waits a
// fixed time: nginx keeps a dead instance in its rotation (max_fails=0), so the page's
// next requests meet it without waiting out fail_timeout, and instance 0 comes back once
// the page has been seen retrying; a minute is only where a wait gives up.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/nginx_proxy.h"
#include "study/postgres/local_server.h"
#include "study/study_store.h"
#include "tests/study/serve/serve_process.h"
#include "tests/support/devtools.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using nlohmann::json;

TEST(ServeBrowserProxy,
     AChromiumPageThroughNginxRecoversByItselfWhenItsInstanceIsKilled) {
    if (!lucent::app::NginxProxy::available())
        GTEST_SKIP() << "Debian's nginx is not installed (scripts/install-deps)";
    if (LocalPostgres::binary_dir().empty())
        GTEST_SKIP() << "no PostgreSQL server binaries (scripts/install-deps)";
    const auto started = std::chrono::steady_clock::now();
    const std::filesystem::path dir = lucent::test::scratch_dir("serve_browser_proxy");
    LocalPostgres pg;
    const std::string uri = pg.create_database("browser_proxy");
    init_study_store(uri);
    const std::string protocol = lucent::test::write_serve_study(dir);
    const std::string key = lucent::test::write_serve_key(dir);
    const int ports[2] = {lucent::test::free_loopback_port(),
                          lucent::test::free_loopback_port()};
    auto start_instance = [&](int i) {
        return lucent::test::start_serve_instance(protocol, uri, dir, i, ports[i], key);
    };
    std::unique_ptr<lucent::test::ServeProcess> instances[2] = {start_instance(0),
                                                                start_instance(1)};
    for (int i = 0; i < 2; ++i)
        ASSERT_EQ(instances[i]->port(), ports[i])
            << "instance " << i << " did not start: " << instances[i]->first_line();
    lucent::app::NginxProxy::Options proxy_options;
    proxy_options.max_fails = 0;  // a dead instance stays in the rotation: met again
    lucent::app::NginxProxy proxy({ports[0], ports[1]}, proxy_options);
    auto since = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - started)
            .count();
    };
    std::cout << "[ proxy] PostgreSQL, two instances and nginx up after " << since()
              << " s\n";
    lucent::test::DevToolsBrowser browser(1280, 900);
    if (!browser.ok()) GTEST_SKIP() << browser.error();

    auto screen = [&] {
        return browser.evaluate("document.body.dataset.screen").get<std::string>();
    };
    auto view = [&] {
        return browser.evaluate("document.body.dataset.view").get<std::string>();
    };
    auto page_retries = [&] {
        return std::stoi(
            browser.evaluate("document.body.dataset.retries || '0'").get<std::string>());
    };
    constexpr auto kGiveUp = std::chrono::seconds(60);  // never the assertion
    // Digits, arrows (the first press picks the middle point) or clicks in turn; the
    // catch trial by digits as its prompt asks. Returns the ratings given.
    auto rate = [&](int k) -> std::pair<int, int> {
        const std::string prompt =
            browser.evaluate("document.getElementById('prompt').textContent");
        if (prompt.find("Attention") != std::string::npos) {
            for (const char* key : {"5", "Enter", "5", "Enter"}) browser.press(key);
            return {5, 5};
        }
        switch (k % 3) {
            case 0:
                for (const char* key : {"3", "Enter", "4", "Enter"}) browser.press(key);
                return {3, 4};
            case 1:
                for (const char* key : {"ArrowRight", "ArrowRight", "ArrowDown",
                                        "ArrowLeft", "ArrowLeft", "Enter"})
                    browser.press(key);
                return {5, 2};
            default:
                EXPECT_TRUE(browser.click("button[data-question='0'][data-value='6']"));
                EXPECT_TRUE(browser.click("button[data-question='1'][data-value='1']"));
                EXPECT_TRUE(browser.click("button[data-question='0'][data-value='7']"));
                EXPECT_TRUE(browser.click("#next"));
                return {7, 1};
        }
    };

    browser.navigate(proxy.url() + "/?participant=BP1");
    ASSERT_TRUE(browser.wait_until("document.body.dataset.screen === 'consent'", kGiveUp))
        << screen();
    // Ratings given by trial id, in the order shown; the instance is killed once the
    // practice trial and the first main trial are answered.
    std::map<std::string, std::pair<int, int>> given;
    bool killed = false, both_down = false, restart_after_press = false;
    int retries_while_down = 0, retries_before_down = 0;
    for (int guard = 0; guard < 40 && screen() != "done"; ++guard) {
        const std::string s = screen(), v = view();
        if (s == "trial") {
            const std::string trial = browser.evaluate("document.body.dataset.trial");
            given[trial] = rate(static_cast<int>(given.size()));
        } else {
            browser.press("Enter");
        }
        if (restart_after_press) {
            // No instance answers: nginx says 502 and the page retries with backoff
            // until instance 0 is back on its port; it comes back once the page has
            // been seen retrying.
            EXPECT_TRUE(
                browser.wait_until("Number(document.body.dataset.retries || 0) > " +
                                       std::to_string(retries_before_down),
                                   kGiveUp))
                << "the page did not retry while no instance answered";
            retries_while_down = page_retries() - retries_before_down;
            instances[0] = start_instance(0);
            ASSERT_EQ(instances[0]->port(), ports[0]) << instances[0]->first_line();
            restart_after_press = false;
        }
        if (given.size() == 2 && !killed) {
            // The answer is on its way (or back): kill instance 0 at once.
            EXPECT_EQ(instances[0]->kill_now(), 128 + SIGKILL);
            killed = true;
        }
        // The next screen: a text screen, a trial's rating screen or the end (the page
        // may be retrying or starting again meanwhile).
        browser.wait_until("document.body.dataset.view !== '" + v +
                               "' && ['blank', 'loading'].indexOf("
                               "document.body.dataset.screen) < 0",
                           kGiveUp);
        if (given.size() == 3 && !both_down && screen() != "done") {
            // Then instance 1 dies too: the page's next call finds no instance at all.
            retries_before_down = page_retries();
            EXPECT_EQ(instances[1]->kill_now(), 128 + SIGKILL);
            both_down = restart_after_press = true;
        }
    }
    std::cout << "[ proxy] the page completed after " << since() << " s\n";
    ASSERT_EQ(screen(), "done") << "text: "
                                << browser.evaluate(
                                       "document.getElementById('message-text')."
                                       "textContent");
    EXPECT_TRUE(killed);
    EXPECT_EQ(browser.evaluate("document.body.dataset.completionCode"), "C0DE42");
    EXPECT_EQ(given.size(), size_t(lucent::test::kServeStudyTrials));
    EXPECT_TRUE(both_down);
    EXPECT_GE(retries_while_down, 1)
        << "the page did not retry while no instance answered";
    const json retries = browser.evaluate("document.body.dataset.retries || '0'");
    // nginx met the dead instance (and sent the request on to the other one).
    int failed = 0, api_failed = 0;
    {
        std::ifstream log(proxy.error_log_path());
        const std::string upstream = "127.0.0.1:" + std::to_string(ports[0]);
        for (std::string line; std::getline(log, line);)
            if (line.find("[error]") != std::string::npos &&
                line.find(upstream) != std::string::npos) {
                ++failed;
                api_failed += line.find("POST /api/") != std::string::npos;
            }
    }
    EXPECT_GE(failed, 1) << "no request of the page reached the killed instance";
    std::cout << "[ proxy] nginx met the killed instance " << failed << " times ("
              << api_failed << " API calls); the page retried "
              << retries.get<std::string>() << " requests (" << retries_while_down
              << " while no instance answered)\n";

    // Instance 1 again on its port; the completed participant's link, opened anew
    // through the proxy (either instance), shows the completion screen again.
    instances[1] = start_instance(1);
    ASSERT_EQ(instances[1]->port(), ports[1]) << instances[1]->first_line();
    for (int again = 0; again < 2; ++again) {
        browser.navigate(proxy.url() + "/?participant=BP1");
        EXPECT_TRUE(
            browser.wait_until("document.body.dataset.screen === 'done'", kGiveUp))
            << screen();
        EXPECT_EQ(browser.evaluate("document.body.dataset.completionCode"), "C0DE42");
    }

    const std::unique_ptr<StudyStore> store = open_study_store(uri);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM sessions"), 1);
    EXPECT_EQ(
        store->query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"), 1);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM responses"),
              lucent::test::kServeStudyTrials * 2);
    EXPECT_EQ(store->query_int("SELECT count(*) FROM (SELECT trial_id, question FROM "
                               "responses GROUP BY trial_id, question HAVING count(*) > "
                               "1) d"),
              0);
    for (const auto& [trial, ratings] : given)
        for (const auto& [question, rating] :
             {std::pair<std::string, int>{"translucent", ratings.first},
              {"realistic", ratings.second}})
            EXPECT_EQ(
                store->query_int("SELECT count(*) FROM responses r JOIN trials t ON "
                                 "t.id = r.trial_id WHERE t.uuid = '" +
                                 trial + "' AND r.question = '" + question +
                                 "' AND r.rating = " + std::to_string(rating) +
                                 " AND r.rt_ms > 0"),
                1)
                << trial << " " << question;
    std::cout << "[ proxy] " << since() << " s in all\n";
}

}  // namespace
}  // namespace lucent::study
