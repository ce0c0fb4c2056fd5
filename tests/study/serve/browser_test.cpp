// A real headless chromium completes `lucent serve` sessions by pressing keys and
// clicking (DevTools protocol, trusted input events), with and without a reload in the
// middle. Expected ratings are the ones the test pressed, for the trials in the order
// the page showed them; the pictures' sizes are the files' own.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "study/sqlite/sqlite_store.h"
#include "tests/study/serve/serve_process.h"
#include "tests/support/devtools.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using nlohmann::json;

class ServeBrowser : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = lucent::test::scratch_dir(
            std::string("serve_browser_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        db_ = (dir_ / "study.db").string();
        server_ = std::make_unique<lucent::test::ServeProcess>(
            lucent::test::write_serve_study(dir_), db_, dir_.string());
        ASSERT_GT(server_->port(), 0)
            << "lucent serve did not start: " << server_->first_line();
        browser_ = std::make_unique<lucent::test::DevToolsBrowser>(1280, 900);
        if (!browser_->ok()) GTEST_SKIP() << browser_->error();
    }
    std::string screen() {
        return browser_->evaluate("document.body.dataset.screen").get<std::string>();
    }
    bool wait_screen(const std::string& name) {
        return browser_->wait_until("document.body.dataset.screen === '" + name + "'");
    }
    // Waits for the next screen after `view`, a text screen or a trial's rating screen.
    std::string next_screen(const std::string& view) {
        browser_->wait_until(
            "document.body.dataset.view !== '" + view +
            "' && ['blank', 'loading'].indexOf(document.body.dataset.screen) < 0");
        return screen();
    }
    std::string view() {
        return browser_->evaluate("document.body.dataset.view").get<std::string>();
    }

    // Rates the trial on screen; the k-th trial shown uses keys, arrows or clicks in
    // turn. Returns the ratings given (question 0, question 1).
    std::pair<int, int> rate(int k) {
        const std::string prompt =
            browser_->evaluate("document.getElementById('prompt').textContent");
        const bool is_catch = prompt.find("Attention") != std::string::npos;
        switch (is_catch ? 0 : k % 3) {
            case 0:  // digits, Enter between the statements and to confirm
                if (is_catch) {
                    browser_->press("5");
                    browser_->press("Enter");
                    browser_->press("5");
                    browser_->press("Enter");
                    return {5, 5};
                }
                browser_->press("3");
                browser_->press("Enter");
                browser_->press("4");
                browser_->press("Enter");
                return {3, 4};
            case 1:  // arrows: the first press picks the middle point (4 of 7, 3 of 5)
                browser_->press("ArrowRight");
                browser_->press("ArrowRight");
                browser_->press("ArrowDown");
                browser_->press("ArrowLeft");
                browser_->press("ArrowLeft");
                browser_->press("Enter");
                return {5, 2};
            default:  // clicks on the scales, then Next
                EXPECT_TRUE(browser_->click("button[data-question='0'][data-value='6']"));
                EXPECT_TRUE(browser_->click("button[data-question='1'][data-value='1']"));
                EXPECT_TRUE(browser_->click("button[data-question='0'][data-value='7']"));
                EXPECT_TRUE(browser_->click("#next"));
                return {7, 1};
        }
    }

    // Runs the page from its current screen until done (or `stop_after` trials), keyed
    // by the trial id the page shows.
    void run_page(std::map<std::string, std::pair<int, int>>& given,
                  int stop_after = 1000) {
        for (int guard = 0; guard < 60; ++guard) {
            const std::string s = screen();
            if (s == "done") return;
            const std::string v = view();
            if (s == "trial") {
                if (static_cast<int>(given.size()) >= stop_after) return;
                const std::string trial =
                    browser_->evaluate("document.body.dataset.trial");
                // Pixel for pixel: the picture's CSS size times the device pixel ratio is
                // the file's size.
                EXPECT_EQ(
                    browser_->evaluate(
                        "(() => { const i = document.querySelector('#picture img'); "
                        "const r = i.getBoundingClientRect(); return [i.naturalWidth, "
                        "i.naturalHeight, r.width * devicePixelRatio, r.height * "
                        "devicePixelRatio]; })()"),
                    json::parse("[64, 48, 64.0, 48.0]"));
                given[trial] = rate(static_cast<int>(given.size()));
            } else {
                browser_->press("Enter");
            }
            next_screen(v);
        }
        ADD_FAILURE() << "the page never reached the end (on '" << screen() << "')";
    }
    // The stored ratings equal what was pressed, for every trial the page showed.
    void expect_stored(const std::map<std::string, std::pair<int, int>>& given) {
        Store store(db_);
        for (const auto& [trial, ratings] : given) {
            for (const auto& [question, rating] :
                 {std::pair<std::string, int>{"translucent", ratings.first},
                  {"realistic", ratings.second}})
                EXPECT_EQ(
                    store.query_int("SELECT count(*) FROM responses r JOIN trials t ON "
                                    "t.id = r.trial_id WHERE t.uuid = '" +
                                    trial + "' AND r.question = '" + question +
                                    "' AND r.rating = " + std::to_string(rating) +
                                    " AND r.rt_ms > 0"),
                    1)
                    << trial << " " << question;
        }
        EXPECT_EQ(store.query_int("SELECT count(*) FROM responses"),
                  static_cast<int64_t>(given.size() * 2));
    }

    std::filesystem::path dir_;
    std::string db_;
    std::unique_ptr<lucent::test::ServeProcess> server_;
    std::unique_ptr<lucent::test::DevToolsBrowser> browser_;
};

TEST_F(ServeBrowser, ChromiumCompletesAWholeSessionWithKeysArrowsAndClicks) {
    browser_->navigate(server_->url() + "/?participant=B1");
    ASSERT_TRUE(wait_screen("consent")) << screen();
    EXPECT_EQ(browser_->evaluate("document.getElementById('text').textContent"),
              "Do you agree to take part?");
    // The page measures the refresh over its first 60 frames and posts it while the
    // consent is read (kept by the server until they agree; nothing is stored before);
    // a participant reading the consent takes longer than that, this scripted one would
    // not: wait for it as a person would.
    ASSERT_TRUE(browser_->wait_until("document.body.dataset.refreshSent === '1'"));
    EXPECT_EQ(Store(db_).query_int("SELECT count(*) FROM session_segments"), 0);
    std::map<std::string, std::pair<int, int>> given;
    run_page(given);
    ASSERT_EQ(screen(), "done");
    EXPECT_EQ(browser_->evaluate("document.body.dataset.completionCode"), "C0DE42");
    EXPECT_EQ(given.size(), size_t(lucent::test::kServeStudyTrials));
    expect_stored(given);
    Store store(db_);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              1);
    // The browser's own details, with the segment.
    EXPECT_EQ(
        store.query_int("SELECT count(*) FROM session_segments WHERE gl_vendor = "
                        "'web browser' AND gl_renderer LIKE '%Chrome/%' AND display_mode "
                        "LIKE 'browser window 1280x%devicePixelRatio 1%'"),
        1);
    EXPECT_EQ(store.query_int(
                  "SELECT count(*) FROM session_segments WHERE measured_refresh_hz > 1"),
              1);
}

TEST_F(ServeBrowser, AReloadInTheMiddleResumesAtTheFirstUnansweredTrial) {
    browser_->navigate(server_->url() + "/?participant=B2");
    ASSERT_TRUE(wait_screen("consent"));
    std::map<std::string, std::pair<int, int>> given;
    run_page(given, 2);
    ASSERT_EQ(given.size(), 2u);
    ASSERT_EQ(screen(), "trial");
    browser_->reload();
    // Consent is on record: the reload goes straight to the first unanswered trial.
    ASSERT_TRUE(
        browser_->wait_until("document.body.dataset.screen === 'trial' || "
                             "document.body.dataset.screen === 'break'"))
        << screen();
    {
        Store store(db_);
        const int64_t session = store.query_int("SELECT id FROM sessions");
        for (const TrialRow& t : store.trials(session))
            if (!t.answered) {
                if (screen() == "trial") {
                    EXPECT_EQ(browser_->evaluate("document.body.dataset.trial"), t.uuid);
                }
                break;
            }
    }
    run_page(given);
    ASSERT_EQ(screen(), "done");
    EXPECT_EQ(given.size(), size_t(lucent::test::kServeStudyTrials));
    expect_stored(given);
    Store store(db_);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM session_segments"), 2);
}

TEST_F(ServeBrowser, AWindowTooSmallForThePictureIsToldSoAndWaits) {
    browser_->call(
        "Emulation.setDeviceMetricsOverride",
        {{"width", 60}, {"height", 40}, {"deviceScaleFactor", 1}, {"mobile", false}});
    browser_->navigate(server_->url() + "/?participant=B3");
    ASSERT_TRUE(wait_screen("consent"));
    browser_->press("Enter");
    ASSERT_TRUE(wait_screen("instructions"));
    browser_->press("Enter");
    ASSERT_TRUE(wait_screen("too-small")) << screen();
    EXPECT_NE(browser_->evaluate("document.getElementById('message-text').textContent")
                  .get<std::string>()
                  .find("64 x 48"),
              std::string::npos);
    browser_->call(
        "Emulation.setDeviceMetricsOverride",
        {{"width", 1280}, {"height", 900}, {"deviceScaleFactor", 1}, {"mobile", false}});
    EXPECT_TRUE(wait_screen("trial")) << screen();
}

// ---- forced choices (issue 30)
// --------------------------------------------------------- Four pictures of 128 x 128
// pixels; a pair and a triad side by side, a quadruple in sequence, one trial each, in
// the protocol's order.
std::string write_choice_study(const std::filesystem::path& dir) {
    for (int k = 0; k < 4; ++k) {
        std::vector<unsigned char> pixels(128 * 128 * 3);
        for (size_t i = 0; i < pixels.size(); ++i)
            pixels[i] = static_cast<unsigned char>(40 + 60 * k + (i % 3) * 10);
        const std::string path = (dir / ("q" + std::to_string(k + 1) + ".png")).string();
        auto out = OIIO::ImageOutput::create(path);
        out->open(path, OIIO::ImageSpec(128, 128, 3, OIIO::TypeDesc::UINT8));
        out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
        out->close();
    }
    const std::string protocol = (dir / "choices.toml").string();
    std::ofstream out(protocol);
    out << R"toml(
[study]
name = "web_choices"
inter_trial_ms = 100

[screens]
consent = "Do you agree to take part?"
instructions = "Choose."
debrief = "Thank you."

[randomisation]
counterbalance_blocks = false
)toml";
    for (int k = 1; k <= 4; ++k)
        out << "\n[[stimuli]]\nid = \"q" << k << "\"\nimage = \"q" << k << ".png\"\n";
    out << R"toml(
[[blocks]]
id = "pairs"
task = "pair"
stimuli = ["q1", "q2"]
question = "Which looks more translucent?"
question_id = "more_translucent"

[[blocks]]
id = "triads"
task = "triad"
stimuli = ["q1", "q2", "q3"]
question = "Which pair differs more?"
question_id = "triad_differs"

[[blocks]]
id = "quads"
task = "quadruple"
stimuli = ["q1", "q2", "q3", "q4"]
question = "Which pair differs more?"
question_id = "quad_differs"
presentation = "sequential"
duration_ms = 1000
blank_ms = 300
)toml";
    return protocol;
}

TEST(ServeBrowserChoices, APairByAClickATriadByArrowsAndASequenceEachDrawnAtItsSize) {
    const std::filesystem::path dir = lucent::test::scratch_dir("serve_browser_choices");
    const std::string db = (dir / "study.db").string();
    lucent::test::ServeProcess server(write_choice_study(dir), db, dir.string());
    ASSERT_GT(server.port(), 0) << "lucent serve did not start: " << server.first_line();
    lucent::test::DevToolsBrowser browser(1280, 900);
    if (!browser.ok()) GTEST_SKIP() << browser.error();
    auto screen = [&] {
        return browser.evaluate("document.body.dataset.screen").get<std::string>();
    };
    auto wait_screen = [&](const std::string& name) {
        return browser.wait_until("document.body.dataset.screen === '" + name + "'");
    };
    auto view = [&] {
        return browser.evaluate("document.body.dataset.view").get<std::string>();
    };
    // The next trial's answer screen after `before`.
    auto wait_answer = [&](const std::string& before) {
        return browser.wait_until("document.body.dataset.view !== '" + before +
                                  "' && document.body.dataset.screen === 'trial'");
    };
    // Every picture drawn pixel for pixel: its natural size is its size on the page.
    auto pictures = [&] {
        return browser.evaluate(
            "[...document.querySelectorAll('#alternatives img')].map((i) => "
            "[i.naturalWidth, i.clientWidth, i.naturalHeight, i.clientHeight])");
    };
    const json at_size = json::array({128, 128, 128, 128});

    // A window too narrow for the pair side by side waits, as for a rating's picture.
    browser.call(
        "Emulation.setDeviceMetricsOverride",
        {{"width", 320}, {"height", 900}, {"deviceScaleFactor", 1}, {"mobile", false}});
    browser.navigate(server.url() + "/?participant=C1");
    ASSERT_TRUE(wait_screen("consent")) << screen();
    browser.press("Enter");
    ASSERT_TRUE(wait_screen("instructions")) << screen();
    const std::string instructions = view();
    browser.press("Enter");
    ASSERT_TRUE(wait_screen("too-small")) << screen();
    EXPECT_NE(browser.evaluate("document.getElementById('message-text').textContent")
                  .get<std::string>()
                  .find("128 x 128"),
              std::string::npos);
    browser.call(
        "Emulation.setDeviceMetricsOverride",
        {{"width", 1280}, {"height", 900}, {"deviceScaleFactor", 1}, {"mobile", false}});
    ASSERT_TRUE(wait_answer(instructions)) << screen();

    // The pair: two pictures at their size, the question above; a click on the second.
    EXPECT_EQ(pictures(), json::array({at_size, at_size}));
    EXPECT_EQ(browser.evaluate("document.getElementById('question').textContent"),
              "Which looks more translucent?");
    const std::string pair = view();
    ASSERT_TRUE(browser.click("#alternatives .group[data-alternative='2'] img"));

    // The triad: three pictures; the arrows pick the pair on their side, Enter confirms.
    ASSERT_TRUE(wait_answer(pair)) << screen();
    EXPECT_EQ(pictures(), json::array({at_size, at_size, at_size}));
    const std::string triad = view();
    browser.press("ArrowRight");
    EXPECT_TRUE(browser.wait_until("document.body.dataset.choice === '2'"));
    EXPECT_EQ(
        browser.evaluate("document.querySelectorAll('#alternatives .chosen').length"),
        3);  // the bracket and its pair's two pictures
    browser.press("ArrowLeft");
    EXPECT_TRUE(browser.wait_until("document.body.dataset.choice === '1'"));
    browser.press("Enter");

    // The quadruple in sequence: keys while it is shown answer nothing; then the two
    // answers alone, the second clicked.
    ASSERT_TRUE(wait_screen("sequence")) << screen();
    EXPECT_EQ(pictures(), json::array({at_size, at_size}));  // its first pair
    browser.press("ArrowLeft");
    browser.press("Enter");
    ASSERT_TRUE(wait_answer(triad)) << screen();
    EXPECT_EQ(pictures(), json::array());
    EXPECT_EQ(browser.evaluate("document.body.dataset.choice"), "");
    ASSERT_TRUE(browser.click("#alternatives button[data-alternative='2']"));
    ASSERT_TRUE(wait_screen("debrief")) << screen();
    browser.press("Enter");
    ASSERT_TRUE(wait_screen("done")) << screen();

    Store store(db);
    auto stored = [&](const std::string& task, const std::string& question, int choice) {
        return store.query_int(
            "SELECT count(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE "
            "t.task = '" +
            task + "' AND r.question = '" + question +
            "' AND r.rating = " + std::to_string(choice) + " AND r.rt_ms > 0");
    };
    EXPECT_EQ(stored("pair", "more_translucent", 2), 1);
    EXPECT_EQ(stored("triad", "triad_differs", 1), 1);
    EXPECT_EQ(stored("quadruple", "quad_differs", 2), 1);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM responses"), 3);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              1);
}

}  // namespace
}  // namespace lucent::study
