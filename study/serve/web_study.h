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
//
// Nothing of a participant is held in memory between requests (issue 32): the flow is
// rebuilt from the store for each request, at the position the last request stored, and
// a page before consent is carried by its token. So several serve processes on one
// database answer any participant's request, and one dying loses nothing.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "study/protocol.h"
#include "study/serve/picture_names.h"
#include "study/sha256.h"
#include "study/study_store.h"
#include "study/web_series.h"

namespace lucent::study {

struct WebReply {
    int status = 200;
    std::string body;       // JSON: the state, or {"error": "one line"} for a 4xx/5xx
    int retry_after_s = 0;  // 503: when to try again (the Retry-After header)
};

// A picture the page shows, served under a name of each trial's (picture_names.h).
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
    // A session the store has seen no activity of (start, segment, answer) for this
    // long no longer holds its counterbalancing cell (abandoned); it still resumes.
    std::chrono::milliseconds idle_timeout = std::chrono::minutes(30);
    // A request waits this long for another request of the same participant (on this
    // process or another) to end, then is refused (409: a lab station runs them now).
    std::chrono::milliseconds participant_wait = std::chrono::seconds(3);
    // Wall time (tests pass a fake one).
    std::function<std::chrono::system_clock::time_point()> clock;
};

// Field limits of API requests (beyond them: 400).
inline constexpr size_t kMaxCodeLength = 64;  // participant code, Prolific ids
inline constexpr size_t kMaxUserAgentLength = 512;
inline constexpr size_t kMaxTokenLength = 200;
inline constexpr size_t kMaxEventsPerAnswer = 500;

// A participant code or Prolific id: 1..64 of [A-Za-z0-9_-]. "" when valid, else why.
std::string participant_code_problem(std::string_view code);
// The token of a session (or of a page before consent, whose session it names):
// "<code>.<session uuid>.<hex HMAC-SHA256(secret, code + ' ' + uuid)>". Any serve
// process holding the secret checks it without keeping anything.
std::string session_token(std::string_view secret, std::string_view code,
                          std::string_view session_uuid);
// The token an earlier lucent serve gave (before issue 32): "<code>.<hex
// HMAC-SHA256(secret, uuid)>"; still taken by /api/session for a session in progress.
std::string legacy_session_token(std::string_view secret, std::string_view code,
                                 std::string_view session_uuid);
// A short public name of a session key (16 hex digits of an HMAC under it, telling
// nothing of the key): /healthz shows it, so a monitor sees instances that disagree.
std::string key_fingerprint(std::string_view secret);

class SessionFlow;
class StorePool;
// The codes a request of this process waits for (web_study.cpp's ParticipantTurn).
struct WaitingCodes {
    std::mutex mutex;
    std::set<std::string> codes;
};

class WebStudy {
public:
    // `protocol` and the store (or pool of stores) must outlive this; ensure_study runs
    // here (StoreError when the store holds another protocol).
    WebStudy(const Protocol& protocol, StorePool& pool, WebStudyOptions options);
    // One store, one request at a time (tests; a single connection).
    WebStudy(const Protocol& protocol, StudyStore& store, WebStudyOptions options);
    ~WebStudy();

    // One API request: `endpoint` is the name after /api/ (session, state, continue,
    // decline, answer, environment), `body` its JSON. Thread-safe: requests run at once,
    // each on a store of the pool (503 with retry_after_s when none came free, or the
    // store cannot be reached); two of one participant take turns.
    WebReply handle(std::string_view endpoint, std::string_view body);
    // GET /healthz: 200 when a store of the pool answers a query now, else 503; both
    // name the key's fingerprint.
    WebReply health();
    // GET /images/<name>.png: the picture a name this study gave names, and the seed of
    // that serving's noise (picture_names.h); nullopt for any other target (404).
    std::optional<NamedPicture> picture(std::string_view target) const;

private:
    struct Browser;
    struct Page;
    void init();  // both constructors: checks the pictures, ensures the study
    WebReply start(const nlohmann::json& body);
    static Browser browser_of(const nlohmann::json& body);
    WebReply resume(StudyStore& store, const std::string& code,
                    const SessionRow& unfinished, const Browser& browser, double t_ms);
    WebReply show_consent(StudyStore& store, const std::string& code,
                          const std::string& uuid, const Browser& browser, double t_ms);
    WebReply act(std::string_view endpoint, const nlohmann::json& body);
    WebReply act_pending(StudyStore& store, std::string_view endpoint,
                         const std::string& code, const std::string& uuid,
                         const nlohmann::json& body);
    WebReply act_enrolled(StudyStore& store, std::string_view endpoint, Page& page,
                          const nlohmann::json& body);
    WebReply continue_or_decline(std::string_view endpoint, Page& page,
                                 const nlohmann::json& body);
    WebReply answer(Page& page, const nlohmann::json& body);
    // The session's flow as its page left it (the stored position), or, when that no
    // longer fits the stored trials, from its first open trial as a resume does, with a
    // view past the stored one. `reload`: a new page (its clock starts anew at `now_ms`).
    void load_flow(StudyStore& store, Page& page, double now_ms, bool reload) const;
    // Stores where the page stands now (after each action that changed it).
    void save_position(StudyStore& store, const Page& page) const;
    WebReply consent(StudyStore& store, const std::string& code, const std::string& uuid,
                     const Browser& browser, bool decline, double shown_ms, double t_ms);
    nlohmann::json state(const Page& page) const;
    nlohmann::json rating_trial(const TrialRow& trial) const;
    // A forced choice showing `shown` (stimulus ids in screen order).
    nlohmann::json choice_trial(const TrialRow& trial,
                                const std::vector<std::string>& shown) const;
    nlohmann::json adjust_trial(const TrialRow& trial) const;
    nlohmann::json staircase_trial(const TrialRow& trial, const SessionFlow& flow) const;
    nlohmann::json done_state() const;
    SessionEnvironment environment_for(const Browser& browser) const;
    nlohmann::json pending_state() const;
    std::chrono::system_clock::time_point now() const;
    std::string active_since_utc() const;
    // The seed of a pending session's plan, from its UUID (kept nowhere, unpredictable
    // without the secret).
    uint64_t seed_of(const std::string& uuid) const;

    const Protocol& protocol_;
    std::unique_ptr<StorePool> own_pool_;  // the one-store constructor's
    StorePool& pool_;
    WebStudyOptions options_;
    PictureNames picture_names_;  // of options_.images, under options_.secret
    int64_t study_id_ = 0;
    int main_trials_ = 0;  // a session's main (not practice) trials
    std::unique_ptr<WaitingCodes> waiting_;
};

}  // namespace lucent::study
