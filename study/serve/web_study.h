#pragma once
// The server side of `lucent serve`, GL-free and without HTTP: online participants run
// the same protocol as `lucent run` (consent, instructions, practice, blocks, breaks,
// catch trials, debrief) through the same SessionFlow, trial plan and StudyStore. The
// HTTP layer (app/cmd_serve.cpp) only hands each API request's name and body here and
// sends back the reply; README.md documents the endpoints.
//
// The server owns the plan and the state; the page is a view of one screen at a time.
// Every action names the view it answers (the flow's serial), so an action meant for a
// screen already left (a double Enter, a second tab) is refused, never applied twice.
// An answer carries the participant's input events (keys, clicks, performance.now()
// times), which the server replays through the session's RatingInput (an adjustment's
// through its AdjustInput, over pre-rendered pictures: web_series.h): the same rules as
// in the lab, and the trial is committed to the store before the reply names the next
// screen. A refused request (4xx, one-line reason) changes nothing: each action runs on
// a copy of the participant's flow, kept only when it succeeded.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "study/protocol.h"
#include "study/study_store.h"
#include "study/web_series.h"

namespace lucent::study {

struct WebReply {
    int status = 200;
    std::string body;  // JSON: the state, or {"error": "one line"} for a 4xx/5xx
};

// A picture the page shows, served at /images/<stimulus id>.png.
struct WebImage {
    int width = 0;
    int height = 0;
};

struct WebStudyOptions {
    std::string secret;  // HMAC key of the session tokens (kept: tokens outlive restarts)
    // What every segment records besides the browser: machine, software, stimuli.
    SessionEnvironment environment;
    // By stimulus id: every protocol stimulus and every picture of `series`.
    std::map<std::string, WebImage> images;
    // The pictures the lab renders live (issue 31): each adjust block's match series and
    // each staircase standard's ladder (web_series(protocol)); required for a protocol
    // with such blocks. Every session's flow shows them (SessionFlow::show_series).
    WebSeries series;
    size_t max_body_bytes = 64 * 1024;  // larger API bodies: 413
    // A page that sent nothing for this long is put aside (release_idle): its claim on
    // the participant ends, and its session no longer holds a cell (abandoned) once the
    // store has seen no activity of it for as long. A later request re-loads it.
    std::chrono::milliseconds idle_timeout = std::chrono::minutes(30);
    // Wall time (tests pass a fake one).
    std::function<std::chrono::system_clock::time_point()> clock;
    // Pages shown the consent screen and not yet answered (held in memory only); beyond
    // this many, the one idle longest is forgotten.
    size_t max_pending = 10000;
};

// Field limits of API requests (beyond them: 400).
inline constexpr size_t kMaxCodeLength = 64;  // participant code, Prolific ids
inline constexpr size_t kMaxUserAgentLength = 512;
inline constexpr size_t kMaxTokenLength = 160;
inline constexpr size_t kMaxEventsPerAnswer = 500;

// A participant code or Prolific id: 1..64 of [A-Za-z0-9_-]. "" when valid, else why.
std::string participant_code_problem(std::string_view code);
// The token of a session: "<code>.<hex HMAC-SHA256(secret, session uuid)>".
std::string session_token(std::string_view secret, std::string_view code,
                          std::string_view session_uuid);
// HMAC-SHA256 (RFC 2104) in lower-case hex.
std::string hmac_sha256_hex(std::string_view key, std::string_view message);
// The stimulus id an /images/ request names, from the raw request target (percent-
// encoded or not): exactly "/images/<id>.png" for a stimulus in `images`, else nullopt
// (traversal, other folders, encoded separators, unknown names).
std::optional<std::string> image_of_target(std::string_view target,
                                           const std::map<std::string, WebImage>& images);

class SessionFlow;

class WebStudy {
public:
    // `protocol` and `store` must outlive this; ensure_study runs here (StoreError when
    // the store holds another protocol).
    WebStudy(const Protocol& protocol, StudyStore& store, WebStudyOptions options);
    ~WebStudy();

    // One API request: `endpoint` is the name after /api/ (session, state, continue,
    // decline, answer, environment), `body` its JSON. Thread-safe (one at a time).
    WebReply handle(std::string_view endpoint, std::string_view body);

    // Participants whose session is loaded now (consented, a page open and not yet done).
    size_t live_sessions() const;
    // Pages on the consent screen (nothing of them stored).
    size_t pending_sessions() const;
    // Puts aside every page idle for longer than idle_timeout: a loaded session's claim
    // ends (its status becomes paused), a pending one is forgotten. Also runs at the
    // start of every request. Returns how many were put aside.
    size_t release_idle();

private:
    struct Live;
    WebReply start(const nlohmann::json& body);
    // start()'s stages: what the browser says, the participant's session in progress,
    // resuming it, or a new participant's consent screen.
    static Live browser_of(const nlohmann::json& body);
    static void take_browser(Live& live, const Live& browser);
    std::optional<SessionRow> unfinished_session_of(const std::string& code,
                                                    const std::string& token);
    WebReply resume(const std::string& code, const std::string& token,
                    const SessionRow& unfinished, const Live& browser, double t_ms);
    WebReply show_consent(const std::string& code, const std::string& token,
                          const Live& browser, double t_ms);
    WebReply act(std::string_view endpoint, const nlohmann::json& body);
    // act()'s stages: the page a token names, a pending page's actions, Enter or N on a
    // loaded session's screen.
    Live& page_of_token(const std::string& code, const std::string& token);
    WebReply act_pending(std::string_view endpoint, Live& live,
                         const nlohmann::json& body);
    WebReply continue_or_decline(std::string_view endpoint, Live& live,
                                 const std::string& code, const nlohmann::json& body);
    WebReply answer(Live& live, const nlohmann::json& body);
    nlohmann::json state(const Live& live) const;
    nlohmann::json rating_trial(const TrialRow& trial) const;
    // A forced choice showing `shown` (stimulus ids in screen order).
    nlohmann::json choice_trial(const TrialRow& trial,
                                const std::vector<std::string>& shown) const;
    nlohmann::json adjust_trial(const TrialRow& trial) const;
    nlohmann::json staircase_trial(const TrialRow& trial, const SessionFlow& flow) const;
    nlohmann::json done_state() const;
    SessionEnvironment environment_for(const Live& live) const;
    Live& load(const std::string& code, const SessionRow& session,
               const std::string& token);
    // Forgets a page; ends the claim when its session was loaded.
    void drop(const std::string& code);
    size_t release_idle_locked();
    WebReply consent(Live& live, bool decline, double shown_ms, double t_ms);
    nlohmann::json pending_state(const Live& live) const;
    std::chrono::system_clock::time_point now() const;
    std::string active_since_utc() const;

    const Protocol& protocol_;
    StudyStore& store_;
    WebStudyOptions options_;
    int64_t study_id_ = 0;
    int main_trials_ = 0;       // a session's main (not practice) trials
    mutable std::mutex mutex_;  // one store connection: requests in turn
    std::map<std::string, std::unique_ptr<Live>> live_;  // by participant code
};

}  // namespace lucent::study
