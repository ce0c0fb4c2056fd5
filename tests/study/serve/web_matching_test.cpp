// lucent serve's adjust and staircase trials (issue 31) over every store backend: the
// match moves over its pre-rendered series and each staircase comparison is its ladder's
// nearest rung. Expected values are worked out by hand from the protocol below (a log
// range [1, 100] in fine steps of 0.01: 201 pictures, index i at 10^(i / 100); a ladder
// of deltas k * 0.5), never read back from the server under test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "study/serve/web_study.h"
#include "study/study_store.h"
#include "study/web_series.h"
#include "tests/study/postgres/server_environment.h"
#include "tests/study/serve/web_page.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

using lucent::test::direct;
using lucent::test::Page;
using nlohmann::json;

// An adjust block starting on the series' middle (10: log10 1 of [0, 2]), one starting
// at random, a staircase of pairs and one of odd ones out, in this order.
const char* kProtocol = R"toml(
[study]
name = "web_matching"
inter_trial_ms = 100

[screens]
consent = "Do you agree?"
instructions = "Match, then choose."
debrief = "Thank you."

[randomisation]
counterbalance_blocks = false

[[questions]]
id = "translucent"
text = "The object looks translucent."

[[stimuli]]
id = "thin"
technique = "empirical"
params = { thickness_exponent = 3 }

[[stimuli]]
id = "thick"
technique = "empirical"
params = { thickness_exponent = 40 }

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
stimuli = ["thin", "thick"]
match = "match"
knob = "thickness_exponent"
range = [1, 100]
scale = "log"
step = 0.1
fine_step = 0.01
start = 10
question = "Turn the right object until it looks like the left one."

[[blocks]]
id = "r"
task = "adjust"
stimuli = ["thin"]
match = "match"
knob = "thickness_exponent"
range = [1, 100]
scale = "log"
step = 0.1
fine_step = 0.01
question = "Once more."

[[blocks]]
id = "j"
task = "staircase"
stimuli = ["std"]
knob = "thickness_exponent"
question = "Which looks more translucent?"
ladder_step = 0.5

[[blocks.staircases]]
id = "a"
start = 0.65
n_up = 1
n_down = 3
step_sizes = [0.5, 0.25]
n_trials = 4
max_delta = 4
max_trials = 4

[[blocks]]
id = "o"
task = "staircase"
trial = "oddity"
stimuli = ["std"]
knob = "thickness_exponent"
question = "Which one differs?"
ladder_step = 0.5

[[blocks.staircases]]
id = "a"
start = 0.65
n_up = 1
n_down = 3
step_sizes = [0.5, 0.25]
n_trials = 4
max_delta = 4
max_trials = 4
)toml";

// The series value at index i: 10^(2 i / 200), its ends exact.
double series_value(int i) {
    if (i == 0) return 1;
    if (i == 200) return 100;
    return std::pow(10.0, 2.0 * i / 200);
}

std::string digits(double v) {
    char out[40];
    std::snprintf(out, sizeof out, "%.17g", v);
    return out;
}

class ServeMatching : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override {
        std::string slug;
        for (char c :
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()))
            slug +=
                std::isalnum(static_cast<unsigned char>(c)) ? char(std::tolower(c)) : '_';
        dir_ = lucent::test::scratch_dir("serve_matching_" + slug);
        if (GetParam() == "sqlite") {
            db_ = (dir_ / "study.db").string();
        } else {
            db_ = lucent::test::new_postgres_database("serve_matching_" + slug);
            init_study_store(db_);
        }
        protocol_ = parse_protocol(kProtocol, "web_matching.toml");
        StoreOptions options;
        options.journal_path = (dir_ / "journal.db").string();
        options.retry_interval_ms = 0;
        store_ = open_study_store(db_, options);
        web_ = std::make_unique<WebStudy>(protocol_, *store_, options_for(protocol_));
    }
    static WebStudyOptions options_for(const Protocol& protocol) {
        WebStudyOptions o;
        o.secret = "test secret";
        o.environment.machine_id = "server-machine";
        o.environment.software_version = "test";
        o.environment.build_hash = "test";
        for (const Stimulus& s : protocol.stimuli) o.images[s.id] = {64, 48};
        o.series = web_series(protocol);
        for (const KnobSeries& s : o.series.series)
            for (const std::string& id : s.pictures) o.images[id] = {64, 48};
        return o;
    }
    int64_t count(const std::string& sql) { return store_->query_int(sql); }
    // The picture a URL the page was given names (the server decodes it).
    std::string picture_id(const json& url) {
        const std::optional<NamedPicture> named = web_->picture(url.get<std::string>());
        EXPECT_TRUE(named) << url;
        return named ? named->id : std::string();
    }
    // A trial's picture names say nothing of what they show: opaque, all different,
    // and none given before in this test (issue 44, item 4).
    void expect_opaque(const json& trial) {
        for (const json& shown : trial["shown"]) {
            const std::string url = shown["image"];
            EXPECT_EQ(url.size(), std::string("/images/.png").size() + 40) << url;
            EXPECT_EQ(url.find_first_of("@="), std::string::npos) << url;
            EXPECT_EQ(url.find("std"), std::string::npos) << url;
            EXPECT_TRUE(names_given_.insert(url).second) << url << " given twice";
        }
    }
    int64_t responses() { return count("SELECT count(*) FROM responses"); }
    int64_t adjustments() { return count("SELECT count(*) FROM adjustments"); }
    TrialRow stored(const std::string& uuid) {
        const int64_t session = count("SELECT max(id) FROM sessions");
        for (const TrialRow& t : store_->trials(session))
            if (t.uuid == uuid) return t;
        ADD_FAILURE() << "no trial " << uuid;
        return {};
    }
    // One adjustment of the trial: its value, time and input.
    int64_t adjustment(const std::string& uuid, double value, double t_ms,
                       const std::string& input) {
        return count(
            "SELECT count(*) FROM adjustments a JOIN trials t ON t.id = a.trial_id WHERE "
            "t.uuid = '" +
            uuid + "' AND abs(a.value - " + digits(value) + ") <= 1e-12 * " +
            digits(value) + " AND a.t_ns = " + std::to_string(std::llround(t_ms * 1e6)) +
            " AND a.input = '" + input + "'");
    }
    // The answer to the adjustment on screen: `events` (t_ms added, 100 ms apart from
    // 100 ms after the onset), then Enter.
    json adjust_body(Page& page, json events) {
        const json& trial = page.state["trial"];
        const double onset = page.now + trial["blank_ms"].get<double>() + 20;
        double t = onset;
        events.push_back({{"type", "key"}, {"key", "Enter"}});
        for (json& e : events) e["t_ms"] = t += 100;
        return {{"token", page.token},
                {"trial", trial["id"]},
                {"view", page.state["view"]},
                {"onset_ms", onset},
                {"events", events}};
    }
    void answer(Page& page, const json& body) {
        page.now = body["events"].back()["t_ms"].get<double>() + 500;
        page.state = page.call("answer", body);
    }
    // Continues text screens until a trial (or the end) is shown.
    void to_trial(Page& page) {
        for (int guard = 0; guard < 20 && page.state["screen"] != "trial" &&
                            page.state["screen"] != "done";
             ++guard)
            page.enter();
    }
    void refused(const json& body, const std::string& reason) {
        const int64_t before = responses(), moves = adjustments();
        const WebReply r = web_->handle("answer", body.dump());
        EXPECT_EQ(r.status, 400) << body.dump() << " -> " << r.body;
        const json reply = json::parse(r.body, nullptr, false);
        ASSERT_TRUE(reply.is_object() && reply.contains("error")) << r.body;
        const std::string line = reply["error"];
        EXPECT_EQ(line.find('\n'), std::string::npos);
        EXPECT_NE(line.find(reason), std::string::npos) << line;
        EXPECT_EQ(responses(), before);
        EXPECT_EQ(adjustments(), moves);
    }

    std::filesystem::path dir_;
    std::string db_;
    std::set<std::string> names_given_;
    Protocol protocol_;
    std::unique_ptr<StudyStore> store_;
    std::unique_ptr<WebStudy> web_;
};

TEST_P(ServeMatching, TheMatchMovesOverItsSeriesAsInTheLabAndEveryChangeIsStored) {
    Page page{direct(*web_)};
    page.open({{"participant", "M1"}});
    to_trial(page);
    ASSERT_EQ(page.state["screen"], "trial");
    json trial = page.state["trial"];
    ASSERT_EQ(trial["task"], "adjust") << trial.dump();

    // The state: the target, the match's 201 pictures, the scale (log10 of [1, 100]).
    const std::string target = picture_id(trial["target"]["image"]);
    EXPECT_TRUE(target == "thin" || target == "thick") << target;
    EXPECT_EQ(trial["target"]["width"], 64);
    EXPECT_EQ(trial["target"]["height"], 48);
    EXPECT_EQ(trial["match"], json({{"width", 64}, {"height", 48}}));
    ASSERT_EQ(trial["series"].size(), 201u);
    EXPECT_EQ(picture_id(trial["series"][0]), "match@thickness_exponent=1");
    EXPECT_EQ(picture_id(trial["series"][100]), "match@thickness_exponent=10");
    EXPECT_EQ(picture_id(trial["series"][200]), "match@thickness_exponent=100");
    // 202 names, all different, none saying which knob value it shows.
    std::set<std::string> names = {trial["target"]["image"].get<std::string>()};
    for (const json& url : trial["series"]) {
        names.insert(url.get<std::string>());
        EXPECT_EQ(url.get<std::string>().find_first_of("@="), std::string::npos) << url;
    }
    EXPECT_EQ(names.size(), 202u);
    EXPECT_EQ(trial["low"], 0.0);
    EXPECT_EQ(trial["high"], 2.0);
    EXPECT_EQ(trial["coarse"], 0.1);
    EXPECT_EQ(trial["fine"], 0.01);
    EXPECT_EQ(trial["start_index"], 100);  // start = 10: log10 1, the middle of [0, 2]
    EXPECT_EQ(trial["question"], protocol_.blocks[0].question);
    EXPECT_EQ(trial["practice"], false);
    EXPECT_EQ(trial["blank_ms"], 100);
    EXPECT_EQ(trial["screen"], "adjust");
    // Nothing more: never the target's value (its picture is named by its id).
    std::set<std::string> keys;
    for (const auto& [key, value] : trial.items()) keys.insert(key);
    EXPECT_EQ(keys, (std::set<std::string>{"id", "task", "screen", "target", "match",
                                           "series", "low", "high", "coarse", "fine",
                                           "start_index", "question", "practice",
                                           "prompt", "blank_ms", "max_events"}));

    // Hostile events: each a 400 naming what is wrong, nothing stored.
    auto with = [&](const json& event) {
        return adjust_body(page, json::array({event}));
    };
    refused(with({{"type", "wheel"}, {"notches", nullptr}}),
            "field 'notches' is required");
    refused(with({{"type", "wheel"}, {"notches", 101}}), "field 'notches' must lie in");
    refused(with({{"type", "wheel"}, {"notches", "1"}}),
            "field 'notches' must be a number");
    refused(with({{"type", "drag"}, {"dx", 10}, {"width", 0}}),
            "field 'width' must lie in [1, 100000]");
    refused(with({{"type", "drag"}, {"dx", 10}, {"width", 1e-300}}), "field 'width'");
    refused(with({{"type", "drag"}, {"dx", 1e6}, {"width", 64}}),
            "field 'dx' must lie in");
    refused(with({{"type", "drag"}, {"width", 64}}), "field 'dx' is required");
    refused(with({{"type", "key"}, {"key", "a"}}),
            "field 'key': 'a' does not adjust the match");
    refused(with({{"type", "key"}, {"key", "1"}}), "field 'key': '1'");
    refused(with({{"type", "key"}, {"key", "ArrowUp"}, {"shift", "yes"}}),
            "field 'shift' must be true or false");
    refused(with({{"type", "choice"}, {"alternative", 1}}),
            "field 'type': a 'choice' event answers a forced choice; this trial is an "
            "adjustment");
    refused(with({{"type", "point"}, {"question", 0}, {"value", 2}}),
            "field 'type': a 'point' event answers a rating");
    refused(with({{"type", "pinch"}}), "unknown event type 'pinch'");
    json unconfirmed = with({{"type", "wheel"}, {"notches", 1}});
    unconfirmed["events"].erase(1);
    refused(unconfirmed, "the events do not confirm the match (Enter)");
    {  // NaN is no JSON: the parser refuses it
        const WebReply r = web_->handle(
            "answer", R"({"events": [{"type": "wheel", "notches": NaN, "t_ms": 1}]})");
        EXPECT_EQ(r.status, 400) << r.body;
    }
    EXPECT_EQ(responses(), 0);

    // Three coarse steps up (10 series steps each) and one fine step down, from 100.
    const std::string first = trial["id"];
    json body =
        adjust_body(page, {{{"type", "key"}, {"key", "ArrowRight"}},
                           {{"type", "key"}, {"key", "ArrowUp"}, {"shift", false}},
                           {{"type", "key"}, {"key", "ArrowRight"}},
                           {{"type", "key"}, {"key", "ArrowLeft"}, {"shift", true}}});
    const double onset = body["onset_ms"];
    answer(page, body);
    TrialRow t = stored(first);
    ASSERT_TRUE(t.answered);
    ASSERT_TRUE(t.start_value && t.final_value);
    EXPECT_EQ(*t.start_value, 10.0);
    EXPECT_DOUBLE_EQ(*t.final_value, series_value(129));
    EXPECT_EQ(count("SELECT count(*) FROM adjustments"), 4);
    EXPECT_EQ(adjustment(first, series_value(110), onset + 100, "key"), 1);
    EXPECT_EQ(adjustment(first, series_value(120), onset + 200, "key"), 1);
    EXPECT_EQ(adjustment(first, series_value(130), onset + 300, "key"), 1);
    EXPECT_EQ(adjustment(first, series_value(129), onset + 400, "fine_key"), 1);
    EXPECT_EQ(count("SELECT count(*) FROM responses WHERE rating = 1 AND abs(rt_ms - "
                    "500) < 0.001"),
              1);

    // The wheel (a coarse step a notch) and drags (the match's width spans the range):
    // 100 -> 110 -> 200 (clamped) -> no change at the end -> 100.
    trial = page.state["trial"];
    ASSERT_EQ(trial["task"], "adjust");
    ASSERT_EQ(trial["start_index"], 100);
    const std::string second = trial["id"];
    body = adjust_body(page, {{{"type", "wheel"}, {"notches", 1}},
                              {{"type", "drag"}, {"dx", 32}, {"width", 64}},
                              {{"type", "wheel"}, {"notches", 1}},
                              {{"type", "drag"}, {"dx", -32}, {"width", 64}}});
    const double onset2 = body["onset_ms"];
    answer(page, body);
    t = stored(second);
    ASSERT_TRUE(t.final_value);
    EXPECT_EQ(*t.final_value, 10.0);
    EXPECT_EQ(count("SELECT count(*) FROM adjustments"), 4 + 3);
    EXPECT_EQ(adjustment(second, series_value(110), onset2 + 100, "wheel"), 1);
    EXPECT_EQ(adjustment(second, 100.0, onset2 + 200, "drag"), 1);
    EXPECT_EQ(adjustment(second, 10.0, onset2 + 400, "drag"), 1);

    // A random start is drawn on the series: the picture shown first is its value.
    trial = page.state["trial"];
    ASSERT_EQ(trial["task"], "adjust");
    const int start = trial["start_index"];
    ASSERT_GE(start, 0);
    ASSERT_LE(start, 200);
    const std::string third = trial["id"];
    t = stored(third);
    ASSERT_TRUE(t.start_value);
    EXPECT_EQ(*t.start_value, web_series(protocol_).find("r", "match")->steps[start]);
    EXPECT_DOUBLE_EQ(*t.start_value, series_value(start));
    answer(page, adjust_body(page, json::array()));  // Enter only: no change
    t = stored(third);
    ASSERT_TRUE(t.final_value);
    EXPECT_EQ(*t.final_value, *t.start_value);
    EXPECT_EQ(count("SELECT count(*) FROM adjustments"), 4 + 3);
    EXPECT_EQ(responses(), 3);
}

// The events lucent.js sent in headless Chromium for: 3 x ArrowRight, Shift+ArrowLeft,
// one wheel notch up, a drag of 40 one-pixel moves right then 20 px left across a match
// 64 px wide (the moves past the top end are not sent: they change nothing), while it
// showed index 138: 100 + 30 - 1 + 10 = 139, + 20 x 3.125 -> 200 (held at the end),
// - 62.5 -> 137.5, rounded up to 138 (std::round and Math.round agree on the tie).
TEST_P(ServeMatching, TheEventsThePageSendsReplayToThePictureItShowed) {
    Page page{direct(*web_)};
    page.open({{"participant", "M2"}});
    to_trial(page);
    ASSERT_EQ(page.state["trial"]["start_index"], 100);
    const std::string uuid = page.state["trial"]["id"];
    json events = {{{"type", "key"}, {"key", "ArrowRight"}, {"shift", false}},
                   {{"type", "key"}, {"key", "ArrowRight"}, {"shift", false}},
                   {{"type", "key"}, {"key", "ArrowRight"}, {"shift", false}},
                   {{"type", "key"}, {"key", "ArrowLeft"}, {"shift", true}},
                   {{"type", "wheel"}, {"notches", 1}}};
    for (int k = 0; k < 20; ++k)
        events.push_back({{"type", "drag"}, {"dx", 1}, {"width", 64}});
    events.push_back({{"type", "drag"}, {"dx", -20}, {"width", 64}});
    answer(page, adjust_body(page, events));
    const TrialRow t = stored(uuid);
    ASSERT_TRUE(t.final_value);
    EXPECT_DOUBLE_EQ(*t.final_value, series_value(138));
    // Every event a change: 4 keys, the wheel, 20 drags to the top, 1 back.
    EXPECT_EQ(adjustments(), 26);
    EXPECT_EQ(count("SELECT count(*) FROM adjustments WHERE input = 'drag'"), 21);
}

// A reloaded page's flow moves over the series too: a drag of 1 px across 64 (1/64 of
// the range, 3.125 steps) from 100 stores the picture shown, index 103, not 10^1.03125.
TEST_P(ServeMatching, AReloadedPageStillMovesOverTheSeries) {
    Page page{direct(*web_)};
    page.open({{"participant", "M3"}});
    to_trial(page);
    answer(page, adjust_body(page, json::array()));  // (before any answer: consent again)
    const json shown = page.state["trial"];
    ASSERT_EQ(shown["task"], "adjust");
    Page reloaded{direct(*web_)};
    reloaded.token = page.token;
    reloaded.now = page.now + 1000;
    reloaded.open({{"participant", "M3"}, {"token", page.token}});
    ASSERT_EQ(reloaded.state["screen"], "trial");
    EXPECT_EQ(reloaded.state["trial"], shown);
    answer(reloaded,
           adjust_body(reloaded, {{{"type", "drag"}, {"dx", 1}, {"width", 64}}}));
    const TrialRow t = stored(shown["id"]);
    ASSERT_TRUE(t.final_value);
    EXPECT_DOUBLE_EQ(*t.final_value, series_value(103));
}

TEST_P(ServeMatching, AStaircaseComparisonIsItsLaddersNearestRungAnsweredAsAPair) {
    Page page{direct(*web_)};
    page.open({{"participant", "S1"}});
    to_trial(page);
    for (int k = 0; k < 3; ++k) answer(page, adjust_body(page, json::array()));
    ASSERT_EQ(page.state["screen"], "trial");
    json trial = page.state["trial"];
    ASSERT_EQ(trial["task"], "staircase") << trial.dump();

    // The first delta is the procedure's start, 0.65, shown as the nearest rung of
    // k * 0.5: 0.5, i.e. the standard's 10 + 0.5.
    std::string uuid = trial["id"];
    TrialRow row = stored(uuid);
    ASSERT_TRUE(row.expected == 1 || row.expected == 2) << row.expected;
    ASSERT_EQ(trial["shown"].size(), 2u);
    for (int place = 1; place <= 2; ++place)
        EXPECT_EQ(picture_id(trial["shown"][place - 1]["image"]),
                  place == row.expected ? "std@thickness_exponent=10.5" : "std")
            << place;
    expect_opaque(trial);
    EXPECT_EQ(trial["question"], "Which looks more translucent?");
    EXPECT_EQ(trial["labels"], json({"left", "right"}));
    EXPECT_EQ(trial["presentation"], "side_by_side");
    for (const char* secret : {"expected", "delta", "intensity", "comparison"})
        EXPECT_EQ(trial.dump().find(secret), std::string::npos) << secret;

    // Refused: an adjustment's events, a third alternative, Shift.
    json body = page.choice_body(0, row.expected);
    body["token"] = page.token;
    json wheel = body;
    wheel["events"] = {{{"t_ms", 1e4}, {"type", "wheel"}, {"notches", 1}}};
    refused(wheel,
            "field 'type': a 'wheel' event adjusts a match; this trial is a forced "
            "choice (staircase)");
    json three = body;
    three["events"] = {{{"t_ms", 1e4}, {"type", "choice"}, {"alternative", 3}}};
    refused(three, "field 'alternative' must be 1 or 2, not 3");
    json shifted = body;
    shifted["events"][0]["shift"] = true;
    refused(shifted, "field 'shift' is only for an adjustment's arrows");

    // Choosing the comparison: stored with the rung shown as its intensity.
    page.now = body["events"].back()["t_ms"].get<double>() + 500;
    page.state = page.call("answer", body);
    row = stored(uuid);
    ASSERT_TRUE(row.answered);
    ASSERT_TRUE(row.intensity);
    EXPECT_EQ(*row.intensity, 0.5);
    EXPECT_EQ(row.choice, row.expected);

    // On to the odd one out: the standard twice, the comparison at its place, 1..3.
    for (int guard = 0; guard < 10 && page.state["screen"] == "trial" &&
                        page.state["trial"]["question"] != "Which one differs?";
         ++guard) {
        json next = page.choice_body(1, 1);
        next["token"] = page.token;
        page.now = next["events"].back()["t_ms"].get<double>() + 500;
        page.state = page.call("answer", next);
    }
    to_trial(page);
    ASSERT_EQ(page.state["screen"], "trial");
    trial = page.state["trial"];
    ASSERT_EQ(trial["question"], "Which one differs?") << trial.dump();
    uuid = trial["id"];
    row = stored(uuid);
    ASSERT_GE(row.expected, 1);
    ASSERT_LE(row.expected, 3);
    ASSERT_EQ(trial["shown"].size(), 3u);
    for (int place = 1; place <= 3; ++place)
        EXPECT_EQ(picture_id(trial["shown"][place - 1]["image"]),
                  place == row.expected ? "std@thickness_exponent=10.5" : "std")
            << place;
    // The standard twice under two names, neither repeating a name of an earlier trial.
    expect_opaque(trial);
    EXPECT_EQ(trial["labels"], json({"left", "middle", "right"}));
    body = page.choice_body(1, 3);  // the digit 3, then Enter
    body["token"] = page.token;
    ASSERT_EQ(body["events"][0]["key"], "3");
    json four = body;
    four["events"][0]["key"] = "4";
    refused(four,
            "field 'key': '4' does not answer a forced choice (ArrowLeft, "
            "ArrowRight, 1, 2, 3, Enter)");
    json click4 = body;
    click4["events"] = {{{"t_ms", 1e4}, {"type", "choice"}, {"alternative", 4}}};
    refused(click4, "field 'alternative' must be 1, 2 or 3, not 4");
    const int64_t before = responses();
    page.state = page.call("answer", body);
    EXPECT_EQ(responses(), before + 1);
    row = stored(uuid);
    ASSERT_TRUE(row.answered && row.intensity);
    EXPECT_EQ(*row.intensity, 0.5);
    EXPECT_EQ(row.choice, 3);
}

// Without the series (or a picture of it) the protocol cannot be served.
TEST_P(ServeMatching, AProtocolWithoutItsSeriesPicturesIsRefused) {
    WebStudyOptions o = options_for(protocol_);
    o.series = {};
    EXPECT_THROW((WebStudy{protocol_, *store_, o}), std::invalid_argument);
    o = options_for(protocol_);
    o.images.erase("match@thickness_exponent=10");
    EXPECT_THROW((WebStudy{protocol_, *store_, o}), std::invalid_argument);
    o = options_for(protocol_);
    o.images["match@thickness_exponent=10"] = {65, 48};
    EXPECT_THROW((WebStudy{protocol_, *store_, o}), std::invalid_argument);
}

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    return info.param;
}

INSTANTIATE_TEST_SUITE_P(Stores, ServeMatching, ::testing::Values("sqlite", "postgresql"),
                         param_name);

}  // namespace
}  // namespace lucent::study
