#pragma once
// A simulated browser page for lucent serve's tests: it speaks the API as lucent.js does
// (JSON bodies, performance.now() times, the input events of each answer) over any
// transport: WebStudy::handle directly, or HTTP to a running `lucent serve`.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "study/serve/web_study.h"

namespace lucent::test {

using nlohmann::json;
using Transport =
    std::function<study::WebReply(const std::string& endpoint, const std::string& body)>;

inline Transport direct(study::WebStudy& web) {
    return [&web](const std::string& endpoint, const std::string& body) {
        return web.handle(endpoint, body);
    };
}

// lucent.js's retry (api() in study/serve/web/lucent.js): a network error (status 0),
// 502, 503 or 504 is sent again after each of these waits in turn (Retry-After when
// longer), about a minute in all; then the page shows the error. A test that checks
// what a server under load loses retries as the page does: a busy server's 503 is an
// answer the page waits out, not a lost participant.
inline constexpr std::array<int, 10> kRetryDelaysMs = {250,  500,  1000, 2000, 4000,
                                                       8000, 8000, 8000, 8000, 8000};
inline bool transient_status(int status) {
    return status == 0 || status == 502 || status == 503 || status == 504;
}

// What a retrying transport waited through: how many requests were sent again (the
// page's data-retries) and how long it slept in all. Reported, never asserted on: how
// often a loaded machine answers 503 is the machine's business.
struct Retries {
    std::atomic<int> sent_again{0};
    std::atomic<long long> waited_ms{0};
};

using Sleep = std::function<void(std::chrono::milliseconds)>;

// `send` retried as lucent.js retries: the same body again after kRetryDelaysMs[attempt]
// (or the reply's Retry-After, when longer) while the status is transient, the last
// reply returned once the waits are spent. `sleep` waits (a test of the policy itself
// records the waits instead).
inline Transport retrying(Transport send, Retries* retries = nullptr, Sleep sleep = {}) {
    if (!sleep)
        sleep = [](std::chrono::milliseconds ms) { std::this_thread::sleep_for(ms); };
    return [send = std::move(send), retries, sleep = std::move(sleep)](
               const std::string& endpoint, const std::string& body) {
        for (std::size_t attempt = 0;; ++attempt) {
            study::WebReply reply = send(endpoint, body);
            if (!transient_status(reply.status) || attempt >= kRetryDelaysMs.size())
                return reply;
            const int wait_ms =
                std::max(kRetryDelaysMs[attempt], 1000 * reply.retry_after_s);
            if (retries) {
                ++retries->sent_again;
                retries->waited_ms += wait_ms;
            }
            sleep(std::chrono::milliseconds(wait_ms));
        }
    };
}

// The rating a test page gives question q of the k-th trial it was shown.
inline int page_rating(int k, int q, bool is_catch, int catch_rating = 7) {
    return is_catch ? catch_rating : 1 + (k * 3 + q * 2) % 5;
}

// One browser page: its clock (ms since load), the token and the screen it shows.
struct Page {
    Transport send;
    int catch_rating = 7;
    double now = 50;
    std::string token;
    json state;
    std::vector<std::string> shown;  // trial ids in the order the page was given them
    // Forced choices: the alternative (1 or 2) the participant picks on a trial (by
    // default the first), and what each trial shown was answered (0: a rating).
    std::function<int(const json& trial)> choose;
    std::vector<int> chosen;

    study::WebReply raw(const std::string& endpoint, const json& body) {
        return send(endpoint, body.dump());
    }
    // What the page says about itself with every request, as lucent.js does (the server
    // keeps nothing of a page before consent): the browser, its refresh once measured.
    json client = {{"user_agent", "TestBrowser/1.0"},
                   {"window_width", 1280},
                   {"window_height", 900},
                   {"device_pixel_ratio", 2},
                   {"screen_width", 2560},
                   {"screen_height", 1440}};
    json who = json::object();  // the link's participant code or Prolific ids

    // A request as lucent.js sends it (token, browser, link ids), its reply unchecked.
    study::WebReply request(const std::string& endpoint, json body) {
        if (!token.empty() && !body.contains("token")) body["token"] = token;
        if (endpoint == "environment" && body.contains("refresh_hz") &&
            body["refresh_hz"].is_number() && body["refresh_hz"].get<double>() > 0)
            client["refresh_hz"] = body["refresh_hz"];
        if (!body.contains("client")) body["client"] = client;
        for (const auto& [key, value] : who.items())
            if (!body.contains(key)) body[key] = value;
        return send(endpoint, body.dump());
    }
    json call(const std::string& endpoint, json body, int expected = 200) {
        const study::WebReply r = request(endpoint, std::move(body));
        EXPECT_EQ(r.status, expected) << endpoint << ": " << r.body;
        return json::parse(r.body);
    }
    void open(const json& link, int expected = 200) {
        json body = link;
        body["t_ms"] = now;
        who = json::object();
        for (const char* key : {"participant", "prolific"})
            if (link.contains(key)) who[key] = link[key];
        const json reply = call("session", body, expected);
        if (expected != 200 || !reply.is_object()) return;
        if (reply.contains("token")) token = reply["token"];
        state = reply;
    }
    void enter() {
        const double shown_at = now;
        now += 300;
        state = call("continue",
                     {{"view", state["view"]}, {"shown_ms", shown_at}, {"t_ms", now}});
    }
    // The page's answer to the trial on screen: each question clicked 100 ms apart after
    // the onset, then Next. Returns the onset.
    json answer_body(int k) {
        const json& trial = state["trial"];
        const double onset = now + trial["blank_ms"].get<double>() + 20;
        json events = json::array();
        // The trial's own scales (a kind's question), else the study's questions.
        const json& scales =
            trial.contains("questions") ? trial["questions"] : state["questions"];
        const int n = static_cast<int>(scales.size());
        const bool is_catch = !trial["prompt"].get<std::string>().empty();
        for (int q = 0; q < n; ++q) {
            const int points = static_cast<int>(scales[q]["labels"].size());
            events.push_back(
                {{"t_ms", onset + 100.0 * (q + 1)},
                 {"type", "point"},
                 {"question", q},
                 {"value", std::min(points, page_rating(k, q, is_catch, catch_rating))}});
        }
        events.push_back({{"t_ms", onset + 100.0 * (n + 1)}, {"type", "next"}});
        return {{"trial", trial["id"]},
                {"view", state["view"]},
                {"onset_ms", onset},
                {"events", events}};
    }
    // The page's answer to the forced choice on screen, 1 or 2 chosen 100 ms after the
    // answer screen's onset, the k-th trial shown by arrow + Enter, digit + Enter or a
    // click in turn. A sequence's parts each come 3 ms (a frame's lateness) after the
    // part before has been shown for its duration.
    json choice_body(int k, int alternative) {
        const json& trial = state["trial"];
        const double onset = now + trial["blank_ms"].get<double>() + 20;
        json body = {
            {"trial", trial["id"]}, {"view", state["view"]}, {"onset_ms", onset}};
        double answer_at = onset;
        if (trial["presentation"] == "sequential") {
            const double duration = trial["sequence"]["duration_ms"].get<double>();
            const double gap = onset + duration + 3;
            const double second = gap + trial["sequence"]["blank_ms"].get<double>() + 3;
            answer_at = second + duration + 3;
            body["phase_onsets_ms"] = {
                {"gap", gap}, {"second", second}, {"answer", answer_at}};
        }
        const double t = answer_at + 100;
        json events = json::array();
        switch (k % 3) {
            case 0:
                events.push_back(
                    {{"t_ms", t},
                     {"type", "key"},
                     {"key", alternative == 1 ? "ArrowLeft" : "ArrowRight"}});
                events.push_back({{"t_ms", t + 100}, {"type", "key"}, {"key", "Enter"}});
                break;
            case 1:
                events.push_back(
                    {{"t_ms", t}, {"type", "key"}, {"key", std::to_string(alternative)}});
                events.push_back({{"t_ms", t + 100}, {"type", "key"}, {"key", "Enter"}});
                break;
            default:
                events.push_back(
                    {{"t_ms", t}, {"type", "choice"}, {"alternative", alternative}});
                break;
        }
        body["events"] = events;
        return body;
    }
    bool on_choice() const {
        return state.contains("trial") &&
               state["trial"].value("screen", "scales") != "scales";
    }
    void answer(int k) {
        if (on_choice()) {
            const int alternative = choose ? choose(state["trial"]) : 1;
            json body = choice_body(k, alternative);
            shown.push_back(state["trial"]["id"]);
            chosen.push_back(alternative);
            now = body["events"].back()["t_ms"].get<double>() + 500;
            state = call("answer", body);
            return;
        }
        chosen.push_back(0);
        json body = answer_body(k);
        shown.push_back(state["trial"]["id"]);
        now = body["onset_ms"].get<double>() + 1000;
        state = call("answer", body);
    }
    // Continues text screens and answers trials until `stop` screens were answered or
    // the study is done.
    void run(size_t trials = 1000) {
        for (int guard = 0; guard < 200; ++guard) {
            if (!state.contains("screen") || !state["screen"].is_string()) {
                ADD_FAILURE() << "no screen in " << state.dump();
                return;
            }
            const std::string screen = state["screen"];
            if (screen == "done") return;
            if (screen == "trial") {
                if (shown.size() >= trials) return;
                answer(static_cast<int>(shown.size()));
            } else {
                enter();
            }
        }
        ADD_FAILURE() << "the session never ended";
    }
};

}  // namespace lucent::test
