// A real headless chromium completes `lucent serve` sessions by pressing keys and
// clicking (DevTools protocol, trusted input events), with and without a reload in the
// middle. Expected ratings are the ones the test pressed, for the trials in the order
// the page showed them; the pictures' sizes are the files' own. Adjust and staircase
// trials (issue 31) are shown from pictures `lucent render --study` wrote: the expected
// series indices and ladder rungs are worked out by hand from the protocol.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

#include "study/serve/picture_names.h"
#include "study/sqlite/sqlite_store.h"
#include "study/web_series.h"
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

// ---- adjustments and staircases from pre-rendered pictures (issue 31) -----------------
// The match of 96 x 96 pixels over a linear series of 21 pictures on [5, 25] (index i
// shows 5 + i), a coarse step of 2 (two pictures), a fine step of 1 (one picture), the
// start 15 (index 10), twice; then a staircase of pairs on a standard at 10 with a ladder
// of deltas k * 0.5 in [0, 5] (11 rungs), 1-up-1-down in steps of 1 from 1.3, 3 trials.
const char* kMatchingProtocol = R"toml(
[study]
name = "browser_matching"
inter_trial_ms = 100
stimulus_size = [96, 96]

[screens]
consent = "Do you agree to take part?"
instructions = "Match, then choose."
debrief = "Thank you."

[randomisation]
counterbalance_blocks = false

[[stimuli]]
id = "target"
technique = "empirical"
params = { thickness_exponent = 12 }

[[stimuli]]
id = "match"
technique = "empirical"
params = { backlight = 0.6 }

[[stimuli]]
id = "std"
technique = "empirical"
params = { thickness_exponent = 10 }

[[blocks]]
id = "m"
task = "adjust"
stimuli = ["target"]
match = "match"
knob = "thickness_exponent"
range = [5, 25]
step = 2
fine_step = 1
series_steps = 21
start = 15
repeats = 2
question = "Change the right object until it looks like the left one."

[[blocks]]
id = "s"
task = "staircase"
stimuli = ["std"]
knob = "thickness_exponent"
question = "Which looks more translucent?"
ladder_step = 0.5

[[blocks.staircases]]
id = "a"
start = 1.3
n_up = 1
n_down = 1
step_sizes = [1]
n_trials = 3
max_trials = 3
max_delta = 5
)toml";

// `lucent render ARGS`, its output to `log`; true when it succeeded.
bool lucent_render(const std::string& args, const std::filesystem::path& log) {
    const std::string command = std::string("'") + LUCENT_EXECUTABLE + "' render " +
                                args + " > '" + log.string() + "' 2>&1";
    return std::system(command.c_str()) == 0;
}

std::string file_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// A key press with Shift held or not (DevTools modifiers: 8 is Shift).
void press_key(lucent::test::DevToolsBrowser& browser, const std::string& key,
               bool shift) {
    const int code = key == "ArrowLeft"    ? 37
                     : key == "ArrowUp"    ? 38
                     : key == "ArrowRight" ? 39
                     : key == "ArrowDown"  ? 40
                                           : 13;
    json down = {{"type", "keyDown"},
                 {"key", key},
                 {"code", key},
                 {"windowsVirtualKeyCode", code},
                 {"modifiers", shift ? 8 : 0}};
    if (key == "Enter") down["text"] = "\r";
    browser.call("Input.dispatchKeyEvent", down);
    down["type"] = "keyUp";
    down.erase("text");
    browser.call("Input.dispatchKeyEvent", down);
}

// The centre of the first element matching `selector`, in CSS pixels.
std::pair<double, double> centre(lucent::test::DevToolsBrowser& browser,
                                 const std::string& selector) {
    const json box = browser.evaluate(
        "(() => { const r = document.querySelector(" + json(selector).dump() +
        ").getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / "
        "2]; })()");
    return {box[0].get<double>(), box[1].get<double>()};
}

// The picture an <img> shows, as "/images/<stimulus id>.png": its src is a name of the
// trial's (study/serve/picture_names.h), which `names` (the server's key and pictures)
// decodes.
std::string shown_picture(lucent::test::DevToolsBrowser& browser,
                          const lucent::study::PictureNames& names,
                          const std::string& selector) {
    const std::string path = browser
                                 .evaluate("new URL(document.querySelector(" +
                                           json(selector).dump() + ").src).pathname")
                                 .get<std::string>();
    const std::optional<lucent::study::NamedPicture> named = names.picture(path);
    return named ? "/images/" + named->id + ".png" : "(no picture name: " + path + ")";
}

TEST(ServeBrowserMatching,
     AdjustmentsByKeysWheelAndDragAndAStaircaseFromRenderedPictures) {
    const std::filesystem::path dir = lucent::test::scratch_dir("serve_browser_matching");
    const std::filesystem::path protocol = dir / "matching.toml";
    std::ofstream(protocol) << kMatchingProtocol;
    const std::filesystem::path images = dir / "pictures";
    ASSERT_TRUE(lucent_render(
        "--study '" + protocol.string() + "' --out '" + images.string() + "'",
        dir / "render.log"))
        << file_text(dir / "render.log");
    const std::string db = (dir / "study.db").string();
    lucent::test::ServeProcess server(protocol.string(), db, dir.string(),
                                      {"--images", images.string()});
    ASSERT_GT(server.port(), 0) << "lucent serve did not start: " << server.first_line();
    // The names the server gives its pictures, decoded with its key (beside the db).
    const Protocol parsed = parse_protocol(kMatchingProtocol, protocol.string());
    std::vector<std::string> ids;
    for (const Stimulus& s : with_series_pictures(parsed, web_series(parsed)).stimuli)
        ids.push_back(s.id);
    const lucent::study::PictureNames names(file_text(db + "-serve-key"), ids);
    lucent::test::DevToolsBrowser browser(1280, 900);
    if (!browser.ok()) GTEST_SKIP() << browser.error();
    auto screen = [&] {
        return browser.evaluate("document.body.dataset.screen").get<std::string>();
    };
    auto view = [&] {
        return browser.evaluate("document.body.dataset.view").get<std::string>();
    };
    auto wait_screen = [&](const std::string& name) {
        return browser.wait_until("document.body.dataset.screen === '" + name + "'");
    };
    auto wait_trial = [&](const std::string& before) {
        return browser.wait_until("document.body.dataset.view !== '" + before +
                                  "' && document.body.dataset.screen === 'trial'");
    };
    auto wait_index = [&](int index) {
        return browser.wait_until("document.body.dataset.matchIndex === '" +
                                  std::to_string(index) + "'");
    };
    const std::string match_img = "#match img";
    // Index i of the match's series shows thickness_exponent 5 + i.
    auto series_picture = [](int value) {
        return "/images/match@thickness_exponent=" + std::to_string(value) + ".png";
    };

    browser.navigate(server.url() + "/?participant=X1");
    ASSERT_TRUE(wait_screen("consent")) << screen();
    browser.press("Enter");
    ASSERT_TRUE(wait_screen("instructions")) << screen();
    std::string before = view();
    browser.press("Enter");

    // Adjustment 1, from index 10 (15): -> 12 (17) -> 14 (19) by arrows, -> 13 (18) by
    // Shift+ArrowLeft (one picture).
    ASSERT_TRUE(wait_trial(before)) << screen();
    const std::string adjust1 = browser.evaluate("document.body.dataset.trial");
    EXPECT_EQ(shown_picture(browser, names, "#target img"), "/images/target.png");
    EXPECT_EQ(browser.evaluate("document.body.dataset.matchIndex"), "10");
    EXPECT_EQ(shown_picture(browser, names, match_img), series_picture(15));
    // Both pictures pixel for pixel, side by side, the question above.
    EXPECT_EQ(
        browser.evaluate("[...document.querySelectorAll('#adjust-row img')].map("
                         "(i) => [i.naturalWidth, i.getBoundingClientRect().width])"),
        json::parse("[[96, 96.0], [96, 96.0]]"));
    EXPECT_EQ(browser.evaluate("document.getElementById('adjust-question').textContent"),
              "Change the right object until it looks like the left one.");
    press_key(browser, "ArrowRight", false);
    ASSERT_TRUE(wait_index(12));
    press_key(browser, "ArrowRight", false);
    ASSERT_TRUE(wait_index(14));
    press_key(browser, "ArrowLeft", true);
    ASSERT_TRUE(wait_index(13));
    const std::string confirmed1 = shown_picture(browser, names, match_img);
    EXPECT_EQ(confirmed1, series_picture(18));
    before = view();
    press_key(browser, "Enter", false);

    // Adjustment 2, from index 10 again: a wheel notch up (a coarse step) -> 12 (17); a
    // drag a quarter of the match's width left (a quarter of the range, 5 pictures) ->
    // 7 (12); Shift+ArrowRight -> 8 (13).
    ASSERT_TRUE(wait_trial(before)) << screen();
    const std::string adjust2 = browser.evaluate("document.body.dataset.trial");
    EXPECT_NE(adjust2, adjust1);
    EXPECT_EQ(browser.evaluate("document.body.dataset.matchIndex"), "10");
    const auto [mx, my] = centre(browser, "#match");
    browser.call(
        "Input.dispatchMouseEvent",
        {{"type", "mouseWheel"}, {"x", mx}, {"y", my}, {"deltaX", 0}, {"deltaY", -100}});
    ASSERT_TRUE(wait_index(12));
    ASSERT_EQ(browser.evaluate("document.getElementById('match').getBoundingClientRect()"
                               ".width"),
              96);
    browser.call("Input.dispatchMouseEvent",
                 {{"type", "mouseMoved"}, {"x", mx}, {"y", my}, {"buttons", 0}});
    browser.call("Input.dispatchMouseEvent", {{"type", "mousePressed"},
                                              {"x", mx},
                                              {"y", my},
                                              {"button", "left"},
                                              {"buttons", 1},
                                              {"clickCount", 1}});
    browser.call("Input.dispatchMouseEvent", {{"type", "mouseMoved"},
                                              {"x", mx - 24},
                                              {"y", my},
                                              {"button", "left"},
                                              {"buttons", 1}});
    browser.call("Input.dispatchMouseEvent", {{"type", "mouseReleased"},
                                              {"x", mx - 24},
                                              {"y", my},
                                              {"button", "left"},
                                              {"buttons", 0},
                                              {"clickCount", 1}});
    ASSERT_TRUE(wait_index(7));
    press_key(browser, "ArrowRight", true);
    ASSERT_TRUE(wait_index(8));
    const std::string confirmed2 = shown_picture(browser, names, match_img);
    EXPECT_EQ(confirmed2, series_picture(13));
    before = view();
    press_key(browser, "Enter", false);

    // The staircase: the comparison (the standard 10 plus the delta's rung) at the slot's
    // planned place, the standard at the other. 1.3 is shown as its nearest rung 1.5;
    // the first answer wrong (up a step: 2.5), the next two right (down: 1.5).
    const std::vector<double> rungs = {1.5, 2.5, 1.5};
    const std::vector<bool> right = {false, true, true};
    std::vector<std::string> staircase_trials;
    for (size_t k = 0; k < rungs.size(); ++k) {
        ASSERT_TRUE(wait_trial(before)) << k << " " << screen();
        const std::string uuid = browser.evaluate("document.body.dataset.trial");
        staircase_trials.push_back(uuid);
        int expected = 0;
        {
            Store store(db);
            for (const TrialRow& t :
                 store.trials(store.query_int("SELECT max(id) FROM sessions")))
                if (t.uuid == uuid) expected = t.expected;
        }
        ASSERT_TRUE(expected == 1 || expected == 2) << uuid;
        const int other = 3 - expected;
        const std::string group = "#alternatives .group[data-alternative='";
        char comparison[64];
        std::snprintf(comparison, sizeof comparison, "%g", 10 + rungs[k]);
        EXPECT_EQ(
            shown_picture(browser, names, group + std::to_string(expected) + "'] img"),
            std::string("/images/std@thickness_exponent=") + comparison + ".png")
            << k;
        EXPECT_EQ(shown_picture(browser, names, group + std::to_string(other) + "'] img"),
                  "/images/std.png")
            << k;
        const int pick = right[k] ? expected : other;
        before = view();
        if (k == 1) {  // a click
            ASSERT_TRUE(browser.click(group + std::to_string(pick) + "'] img"));
        } else {  // a digit, then Enter
            browser.press(std::to_string(pick));
            ASSERT_TRUE(browser.wait_until("document.body.dataset.choice === '" +
                                           std::to_string(pick) + "'"));
            browser.press("Enter");
        }
    }
    ASSERT_TRUE(browser.wait_until("document.body.dataset.view !== '" + before +
                                   "' && document.body.dataset.screen === 'debrief'"))
        << screen();
    browser.press("Enter");
    ASSERT_TRUE(wait_screen("done")) << screen();

    Store store(db);
    const int64_t session = store.query_int("SELECT id FROM sessions");
    const std::vector<TrialRow> trials = store.trials(session);
    ASSERT_EQ(trials.size(), 5u);
    for (const TrialRow& t : trials) EXPECT_TRUE(t.answered) << t.uuid;
    std::map<std::string, TrialRow> by_uuid;
    for (const TrialRow& t : trials) by_uuid[t.uuid] = t;
    // The adjustments: started at 15, ended where the keys, wheel and drag took them.
    const std::map<std::string, double> finals = {{adjust1, 18}, {adjust2, 13}};
    for (const auto& [uuid, final] : finals) {
        const TrialRow& t = by_uuid[uuid];
        EXPECT_EQ(t.task, Task::adjust);
        ASSERT_TRUE(t.start_value && t.final_value) << uuid;
        EXPECT_EQ(*t.start_value, 15.0);
        EXPECT_EQ(*t.final_value, final);
    }
    // The picture shown at Enter is the stored final value's.
    EXPECT_EQ(confirmed1,
              series_picture(static_cast<int>(*by_uuid[adjust1].final_value)));
    EXPECT_EQ(confirmed2,
              series_picture(static_cast<int>(*by_uuid[adjust2].final_value)));
    auto adjustment = [&](const std::string& uuid, double value,
                          const std::string& input) {
        return store.query_int(
            "SELECT count(*) FROM adjustments a JOIN trials t ON t.id = a.trial_id WHERE "
            "t.uuid = '" +
            uuid + "' AND abs(a.value - " + std::to_string(value) +
            ") < 1e-9 AND a.input = '" + input + "' AND a.t_ns > 0");
    };
    EXPECT_EQ(adjustment(adjust1, 17, "key"), 1);
    EXPECT_EQ(adjustment(adjust1, 19, "key"), 1);
    EXPECT_EQ(adjustment(adjust1, 18, "fine_key"), 1);
    EXPECT_EQ(adjustment(adjust2, 17, "wheel"), 1);
    EXPECT_EQ(adjustment(adjust2, 12, "drag"), 1);
    EXPECT_EQ(adjustment(adjust2, 13, "fine_key"), 1);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM adjustments"), 6);
    // In the order made.
    EXPECT_EQ(
        store.query_int(
            "SELECT count(*) FROM adjustments a JOIN adjustments b ON a.trial_id = "
            "b.trial_id WHERE a.t_ns < b.t_ns AND NOT ((a.value = 17 AND b.value IN "
            "(19, 18, 12, 13)) OR (a.value = 19 AND b.value = 18) OR (a.value = 12 "
            "AND b.value = 13))"),
        0);
    // The staircase: each delta shown is its rung, and the answers are the picks.
    for (size_t k = 0; k < staircase_trials.size(); ++k) {
        const TrialRow& t = by_uuid[staircase_trials[k]];
        EXPECT_EQ(t.task, Task::staircase);
        ASSERT_TRUE(t.intensity) << k;
        EXPECT_EQ(*t.intensity, rungs[k]) << k;
        EXPECT_EQ(std::fmod(*t.intensity, 0.5), 0.0) << k;  // a rung k * 0.5
        ASSERT_TRUE(t.choice) << k;
        EXPECT_EQ(*t.choice == t.expected, right[k]) << k;
    }
    EXPECT_EQ(store.query_int("SELECT count(*) FROM responses WHERE rt_ms > 0"), 5);
    EXPECT_EQ(store.query_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              1);
}

// Not a test by default: LUCENT_DOC_SCREENSHOTS=1 renders the built-in studies
// "matching" (about 25 s) and "jnd", serves them and saves the first adjust screen and
// the first staircase screen as Chromium shows them in a 1024 x 640 window to
// docs/matching-browser-adjust.png and docs/matching-browser-staircase.png.
std::string base64_decode(const std::string& text) {
    static const std::string alphabet =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    int bits = 0, value = 0;
    for (char c : text) {
        const size_t at = alphabet.find(c);
        if (at == std::string::npos) continue;  // '=' padding, whitespace
        value = (value << 6) | static_cast<int>(at);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out.push_back(static_cast<char>((value >> bits) & 0xff));
        }
    }
    return out;
}

TEST(ServeBrowserMatching, DocScreenshots) {
    const char* wanted = std::getenv("LUCENT_DOC_SCREENSHOTS");
    if (!wanted || std::string(wanted) != "1")
        GTEST_SKIP() << "set LUCENT_DOC_SCREENSHOTS=1 to write the docs' screenshots";
    const std::filesystem::path dir =
        lucent::test::scratch_dir("serve_browser_doc_shots");
    const struct {
        const char* preset;
        const char* file;
    } shots[] = {{"matching", "matching-browser-adjust.png"},
                 {"jnd", "matching-browser-staircase.png"}};
    for (const auto& shot : shots) {
        const std::filesystem::path images = dir / shot.preset;
        ASSERT_TRUE(lucent_render(std::string("--study-preset ") + shot.preset +
                                      " --out '" + images.string() + "'",
                                  dir / "render.log"))
            << file_text(dir / "render.log");
        const std::string db = (dir / (std::string(shot.preset) + ".db")).string();
        lucent::test::ServeProcess server(
            "", db, dir.string(), {"--preset", shot.preset, "--images", images.string()});
        ASSERT_GT(server.port(), 0) << server.first_line();
        lucent::test::DevToolsBrowser browser(1024, 640);
        if (!browser.ok()) GTEST_SKIP() << browser.error();
        // The page itself 1024 x 640 (the window's size holds the browser's own bars).
        browser.call("Emulation.setDeviceMetricsOverride", {{"width", 1024},
                                                            {"height", 640},
                                                            {"deviceScaleFactor", 1},
                                                            {"mobile", false}});
        browser.navigate(server.url() + "/?participant=DOC1");
        for (int guard = 0; guard < 10; ++guard) {
            ASSERT_TRUE(browser.wait_until(
                "['blank', 'loading'].indexOf(document.body.dataset.screen) < 0"));
            if (browser.evaluate("document.body.dataset.screen") == "trial") break;
            const std::string v = browser.evaluate("document.body.dataset.view");
            browser.press("Enter");
            browser.wait_until("document.body.dataset.view !== '" + v + "'");
        }
        ASSERT_EQ(browser.evaluate("document.body.dataset.screen"), "trial");
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        const json png = browser.call("Page.captureScreenshot", {{"format", "png"}});
        const std::filesystem::path out =
            std::filesystem::path(LUCENT_SOURCE_DIR) / "docs" / shot.file;
        std::ofstream(out, std::ios::binary) << base64_decode(png["data"]);
        std::printf("wrote %s\n", out.c_str());
    }
}

}  // namespace
}  // namespace lucent::study
