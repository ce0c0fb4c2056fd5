// `lucent serve`'s core (web_study.h). [SECTIONS] tokens and names | request fields |
// sessions (pending until consent, enrol, resume, reload, idle) | actions (continue,
// decline, answer, environment) | the state a page shows. Reading a request's fields is
// request_fields.h; checking and replaying an answer's events answer_events.h.
#include "study/serve/web_study.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "renderer/core/display_transform.h"
#include "study/serve/answer_events.h"
#include "study/serve/request_fields.h"
#include "study/session/adjust_input.h"
#include "study/session/session_flow.h"
#include "study/sha256.h"
#include "study/sqlite/sqlite_store.h"
#include "study/store_pool.h"

namespace lucent::study {

using nlohmann::json;

namespace {

// ---- [SECTION] tokens and names -------------------------------------------------------
// Compares without an early exit, so the time taken tells nothing about the token.
bool same_secret_text(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

// ---- [SECTION] request fields (request_fields.h)
// ---------------------------------------
WebReply error_reply(int status, const std::string& why) {
    return {status, to_text(json{{"error", one_line(why)}})};
}

void check_code(const std::string& code, const char* what) {
    if (const std::string why = participant_code_problem(code); !why.empty())
        throw RequestError(400, std::string(what) + " " + why);
}

std::string css_colour(const float rgb[3]) {
    // The protocol's background is linear; the page takes the codes a PNG stores.
    auto encode = [](float c) { return int(display_code(c)); };
    char out[8];
    std::snprintf(out, sizeof out, "#%02x%02x%02x", encode(rgb[0]), encode(rgb[1]),
                  encode(rgb[2]));
    return out;
}

const char* screen_name(Screen screen) {
    switch (screen) {
        case Screen::Consent:
            return "consent";
        case Screen::Instructions:
            return "instructions";
        case Screen::PracticeDone:
            return "practice_done";
        case Screen::Blank:
        case Screen::Trial:
            return "trial";
        case Screen::Break:
            return "break";
        case Screen::Debrief:
            return "debrief";
        case Screen::Done:
            return "done";
    }
    return "done";
}

}  // namespace

std::string key_fingerprint(std::string_view secret) {
    return hmac_sha256_hex(secret, "lucent serve key fingerprint").substr(0, 16);
}

std::string participant_code_problem(std::string_view code) {
    if (code.empty()) return "is empty";
    if (code.size() > kMaxCodeLength)
        return "is longer than " + std::to_string(kMaxCodeLength) + " characters";
    for (char c : code)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-')
            return "may hold only letters, digits, '_' and '-'";
    return "";
}

std::string session_token(std::string_view secret, std::string_view code,
                          std::string_view session_uuid) {
    return std::string(code) + "." + std::string(session_uuid) + "." +
           hmac_sha256_hex(secret, std::string(code) + " " + std::string(session_uuid));
}

std::string legacy_session_token(std::string_view secret, std::string_view code,
                                 std::string_view session_uuid) {
    return std::string(code) + "." + hmac_sha256_hex(secret, session_uuid);
}

// ---- [SECTION] sessions ---------------------------------------------------------------
// A page is `pending` from its first request until the participant agrees on the consent
// screen: nothing of it is stored and nothing kept in memory. Its token names the session
// UUID it will have (and with it the seed of its plan), and the page sends what the
// browser says about itself with its answer. Agreeing enrols it
// (StudyStore::enrol_online), and from then on it is a session like a lab station's, its
// flow rebuilt from the store for every request at the position the last one stored
// (schema 8: web_position).

// What the browser says about itself (the segment's environment).
struct WebStudy::Browser {
    std::string user_agent;
    int window_width = 0, window_height = 0, screen_width = 0, screen_height = 0;
    double device_pixel_ratio = 0;
    std::optional<double> refresh_hz;
    std::string prolific_study, prolific_session;
};

// One request's view of a participant's session: as stored, and its flow.
struct WebStudy::Page {
    std::string code;
    SessionRow session;
    std::vector<TrialRow> trials;
    std::optional<SessionFlow> flow;
    bool done = false;  // the debrief was continued: only the completion screen is left
};

namespace {

// The view a pending page's consent screen has: a new SessionFlow's first screen.
constexpr int kConsentView = 1;

const char* const kWithdrawn =
    "this session was withdrawn: nothing more of it is recorded. You may close this "
    "window.";

// A token's parts: "<code>.<uuid>.<mac>" (or an earlier serve's "<code>.<mac>").
struct TokenParts {
    std::string code, uuid;
    bool legacy = false;
};

std::optional<TokenParts> token_parts(const std::string& token) {
    const size_t first = token.find('.');
    if (first == std::string::npos) return std::nullopt;
    TokenParts parts;
    parts.code = token.substr(0, first);
    const size_t second = token.find('.', first + 1);
    parts.legacy = second == std::string::npos;
    if (!parts.legacy) parts.uuid = token.substr(first + 1, second - first - 1);
    if (!participant_code_problem(parts.code).empty() ||
        (!parts.legacy && (parts.uuid.empty() || parts.uuid.size() > 64)))
        return std::nullopt;
    return parts;
}

// The page's position as stored (sessions.web_position): "<screen> <view> <entered_ns>
// <first open trial id>", or "done <view>" once the debrief was continued.
std::string position_text(const FlowPosition& p) {
    return std::string(screen_name(p.screen)) + " " + std::to_string(p.serial) + " " +
           std::to_string(p.entered_ns) + " " + std::to_string(p.trial_id);
}

std::optional<FlowPosition> position_of_text(const std::string& text) {
    char name[32] = {};
    FlowPosition p;
    long long entered = 0, trial = 0;
    if (std::sscanf(text.c_str(), "%31s %d %lld %lld", name, &p.serial, &entered,
                    &trial) != 4)
        return std::nullopt;
    p.entered_ns = entered;
    p.trial_id = trial;
    const std::string n = name;
    if (n == "instructions")
        p.screen = Screen::Instructions;
    else if (n == "practice_done")
        p.screen = Screen::PracticeDone;
    else if (n == "trial")
        p.screen = Screen::Blank;
    else if (n == "break")
        p.screen = Screen::Break;
    else if (n == "debrief")
        p.screen = Screen::Debrief;
    else if (n == "consent")
        p.screen = Screen::Consent;
    else
        return std::nullopt;
    return p;
}

// The view number stored with a position (also "done N"); 0 when none.
int stored_view(const std::optional<std::string>& text) {
    int view = 0;
    char name[32] = {};
    if (text && std::sscanf(text->c_str(), "%31s %d", name, &view) == 2) return view;
    return 0;
}

bool stored_done(const std::optional<std::string>& text) {
    return text && text->rfind("done ", 0) == 0;
}

WebReply declined_reply() {
    return {200,
            to_text(json{{"screen", "declined"},
                         {"text",
                          "You did not agree to take part. Nothing of yours was stored "
                          "but a salted hash of your participant code, so that you are "
                          "counted once among those who declined. You may close this "
                          "window."}})};
}

// Holds the participant for one request: requests of one participant (on any serve
// process, through any store of a pool) take turns, as lab stations do for a whole
// session. Waits up to `wait` for another request to end; a lab station that runs the
// participant keeps it past that (409). The wait holds no store connection: the claim
// is tried on a leased store, which goes back to the pool between tries, so requests for
// a held code never starve other participants of connections (issue 44). At most one
// request per code waits in a process; another arriving meanwhile is told to come back
// (503, Retry-After), holding nothing.
class ParticipantTurn {
public:
    ParticipantTurn(StorePool& pool, const std::string& code,
                    std::chrono::milliseconds wait, WaitingCodes& waiting)
        : code_(code) {
        if (try_claim(pool)) return;
        {
            std::lock_guard lock(waiting.mutex);
            if (!waiting.codes.insert(code_).second)
                throw StoreUnavailable("participant '" + code_ +
                                       "' has another request waiting for its turn");
        }
        struct Unlist {
            WaitingCodes& waiting;
            const std::string& code;
            ~Unlist() {
                std::lock_guard lock(waiting.mutex);
                waiting.codes.erase(code);
            }
        } unlist{waiting, code_};
        const auto deadline = std::chrono::steady_clock::now() + wait;
        for (;;) {
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
            const bool last = std::chrono::steady_clock::now() >= deadline;
            if (try_claim(pool, last)) return;
        }
    }
    ~ParticipantTurn() {
        try {
            (*lease_)->release_participant(code_);
        } catch (const std::exception&) {
            // A connection in doubt releases its locks as it closes.
        }
    }
    ParticipantTurn(const ParticipantTurn&) = delete;
    ParticipantTurn& operator=(const ParticipantTurn&) = delete;
    // The store holding the claim, for the rest of the request.
    StudyStore& store() const { return **lease_; }

private:
    // True when claimed (the lease kept); false after giving the store back; `last`:
    // the store's refusal is thrown instead.
    bool try_claim(StorePool& pool, bool last = false) {
        lease_.emplace(pool.lease());
        try {
            (*lease_)->claim_participant(code_);
            return true;
        } catch (const StoreUnavailable&) {
            throw;
        } catch (const StoreError&) {
            lease_.reset();
            if (last) throw;
        }
        return false;
    }

    std::string code_;
    std::optional<StorePool::Lease> lease_;
};

}  // namespace

namespace {
std::vector<std::string> picture_ids(const std::map<std::string, WebImage>& images) {
    std::vector<std::string> ids;
    for (const auto& entry : images) ids.push_back(entry.first);
    return ids;
}
}  // namespace

WebStudy::WebStudy(const Protocol& protocol, StudyStore& store, WebStudyOptions options)
    : protocol_(protocol),
      own_pool_(std::make_unique<StorePool>(store)),
      pool_(*own_pool_),
      options_(std::move(options)),
      picture_names_(options_.secret, picture_ids(options_.images)),
      waiting_(std::make_unique<WaitingCodes>()) {
    init();
}

WebStudy::WebStudy(const Protocol& protocol, StorePool& pool, WebStudyOptions options)
    : protocol_(protocol),
      pool_(pool),
      options_(std::move(options)),
      picture_names_(options_.secret, picture_ids(options_.images)),
      waiting_(std::make_unique<WaitingCodes>()) {
    init();
}

void WebStudy::init() {
    for (const Stimulus& s : protocol_.stimuli)
        if (!options_.images.count(s.id))
            throw std::invalid_argument("lucent serve: no picture for stimulus '" + s.id +
                                        "'");
    // What the lab renders live is shown from pictures: each adjust block's match series
    // and each staircase standard's ladder, every picture of them served.
    auto series_of = [&](const Block& b, const std::string& stimulus) {
        const KnobSeries* series = options_.series.find(b.id, stimulus);
        if (!series || series->steps.size() < 2 ||
            series->pictures.size() != series->steps.size())
            throw std::invalid_argument("lucent serve: block '" + b.id +
                                        "' has no picture series for '" + stimulus + "'");
        for (const std::string& id : series->pictures)
            if (!options_.images.count(id))
                throw std::invalid_argument("lucent serve: no picture for '" + id + "'");
        return series;
    };
    for (const Block& b : protocol_.blocks) {
        if (b.task == Task::adjust) {
            // One size for the whole series: the match never jumps as it moves.
            const KnobSeries* series = series_of(b, b.match);
            const WebImage& first = options_.images.at(series->pictures.front());
            for (const std::string& id : series->pictures) {
                const WebImage& image = options_.images.at(id);
                if (image.width != first.width || image.height != first.height)
                    throw std::invalid_argument(
                        "lucent serve: block '" + b.id + "': the series picture '" + id +
                        "' differs in size from '" + series->pictures.front() + "'");
            }
        }
        if (b.task == Task::staircase)
            for (const std::string& standard : b.stimuli) series_of(b, standard);
    }
    if (!options_.clock) options_.clock = [] { return std::chrono::system_clock::now(); };
    // The main trials a session plans (the same for every seed and cell): choice
    // blocks' designs and catch trials are not one per stimulus.
    for (const PlannedTrial& t : plan_trials(protocol_, 0, 0).trials)
        main_trials_ += t.practice ? 0 : 1;
    StorePool::Lease store = pool_.lease();
    study_id_ = store->ensure_study(protocol_);
    store->check_stimulus_values(options_.environment.stimuli);
}

WebStudy::~WebStudy() = default;

std::chrono::system_clock::time_point WebStudy::now() const { return options_.clock(); }

std::string WebStudy::active_since_utc() const {
    return utc_iso8601(now() -
                       std::chrono::duration_cast<std::chrono::system_clock::duration>(
                           options_.idle_timeout));
}

uint64_t WebStudy::seed_of(const std::string& uuid) const {
    const std::string mac = hmac_sha256_hex(options_.secret, "seed " + uuid);
    return std::stoull(mac.substr(0, 16), nullptr, 16) & 0x7FFFFFFFFFFFFFFFull;
}

WebReply WebStudy::handle(std::string_view endpoint, std::string_view body) {
    if (body.size() > options_.max_body_bytes)
        return error_reply(413, "request body of " + std::to_string(body.size()) +
                                    " bytes is over the limit of " +
                                    std::to_string(options_.max_body_bytes));
    json request;
    std::string last_key;  // the field being parsed, for a number the parser cannot hold
    try {
        request = json::parse(body, [&](int, json::parse_event_t event, json& parsed) {
            if (event == json::parse_event_t::key && parsed.is_string())
                last_key = parsed.get<std::string>();
            return true;
        });
    } catch (const json::out_of_range&) {
        // A number beyond a double (e.g. 1e999): the parser stops at it.
        return error_reply(
            400, last_key.empty()
                     ? std::string("a number in the request is beyond a double's range")
                     : "field '" + last_key + "' holds a number beyond a double's range");
    } catch (const json::exception& e) {
        return error_reply(400, std::string("malformed JSON: ") + e.what());
    }
    if (!request.is_object())
        return error_reply(400, "the request body must be a JSON object");
    const bool action = endpoint == "state" || endpoint == "continue" ||
                        endpoint == "decline" || endpoint == "answer" ||
                        endpoint == "environment";
    if (endpoint != "session" && !action)
        return error_reply(404, "no API endpoint '" + std::string(endpoint) + "'");
    try {
        return endpoint == "session" ? start(request) : act(endpoint, request);
    } catch (const RequestError& e) {
        return error_reply(e.status, e.what());
    } catch (const json::exception& e) {
        return error_reply(400, std::string("bad request: ") + e.what());
    } catch (const StoreUnavailable& e) {
        // The store cannot be reached, or every connection stayed busy: nothing was
        // written or acknowledged; the page tries again.
        WebReply reply = error_reply(503, e.what());
        reply.retry_after_s = 1;
        return reply;
    } catch (const StoreError& e) {
        // Refused by the store (a participant run on a lab station now, a rating it
        // does not accept): nothing was written.
        return error_reply(409, e.what());
    } catch (const std::exception& e) {
        return error_reply(500, e.what());
    }
}

std::optional<NamedPicture> WebStudy::picture(std::string_view target) const {
    return picture_names_.picture(target);
}

WebReply WebStudy::health() {
    try {
        StorePool::Lease store = pool_.lease();
        store->query_int("SELECT 1");
        return {200, to_text(json{{"store", "ok"},
                                  {"connections", pool_.size()},
                                  {"key", key_fingerprint(options_.secret)}})};
    } catch (const std::exception& e) {
        WebReply reply{
            503, to_text(json{{"error", one_line(std::string("store: ") + e.what())},
                              {"key", key_fingerprint(options_.secret)}})};
        reply.retry_after_s = 1;
        return reply;
    }
}

SessionEnvironment WebStudy::environment_for(const Browser& browser) const {
    SessionEnvironment env = options_.environment;
    env.gl_vendor = "web browser";
    env.gl_renderer = browser.user_agent;  // the browser draws: its user agent
    std::string mode = "browser window " + std::to_string(browser.window_width) + "x" +
                       std::to_string(browser.window_height) +
                       " CSS px, devicePixelRatio ";
    char dpr[32];
    std::snprintf(dpr, sizeof dpr, "%g", browser.device_pixel_ratio);
    mode += dpr;
    if (browser.screen_width > 0)
        mode += ", screen " + std::to_string(browser.screen_width) + "x" +
                std::to_string(browser.screen_height);
    if (!browser.prolific_study.empty() || !browser.prolific_session.empty())
        mode += "; Prolific STUDY_ID=" + browser.prolific_study +
                " SESSION_ID=" + browser.prolific_session;
    env.display_mode = mode;
    env.display_refresh_hz.reset();
    env.measured_refresh_hz = browser.refresh_hz;
    env.refresh_note = browser.refresh_hz
                           ? "browser estimate: median requestAnimationFrame interval"
                           : "refresh not measured by the browser (yet)";
    return env;
}

namespace {

// Who a page is: its participant code and, from Prolific, the study and session.
struct Participant {
    std::string code;
    std::string prolific_study, prolific_session;
};

// Who: ?participant=ID, or Prolific's PROLIFIC_PID (with STUDY_ID and SESSION_ID).
Participant participant_of(const json& body) {
    Participant who;
    std::string& code = who.code;
    code = text_field(body, "participant", kMaxCodeLength + 1, false);
    if (const json* prolific = field(body, "prolific")) {
        if (!prolific->is_object())
            throw RequestError(400, "field 'prolific' must be an object");
        const std::string pid =
            text_field(*prolific, "PROLIFIC_PID", kMaxCodeLength + 1, true);
        check_code(pid, "PROLIFIC_PID");
        if (!code.empty() && code != pid)
            throw RequestError(
                400, "participant '" + code + "' and PROLIFIC_PID '" + pid + "' differ");
        code = pid;
        who.prolific_study = text_field(*prolific, "STUDY_ID", kMaxCodeLength + 1, false);
        who.prolific_session =
            text_field(*prolific, "SESSION_ID", kMaxCodeLength + 1, false);
        if (!who.prolific_study.empty()) check_code(who.prolific_study, "STUDY_ID");
        if (!who.prolific_session.empty()) check_code(who.prolific_session, "SESSION_ID");
    }
    if (code.empty())
        throw RequestError(400,
                           "no participant code (the link needs ?participant=ID or "
                           "Prolific's PROLIFIC_PID)");
    check_code(code, "participant code");
    return who;
}

}  // namespace

// What this page says about itself: the request's `client` fields, with Prolific's ids
// when it names them (`prolific`, as on the start request).
WebStudy::Browser WebStudy::browser_of(const json& body) {
    Browser browser;
    if (const json* client = field(body, "client")) {
        if (!client->is_object())
            throw RequestError(400, "field 'client' must be an object");
        browser.user_agent =
            text_field(*client, "user_agent", kMaxUserAgentLength, false);
        browser.window_width = static_cast<int>(
            number_field(*client, "window_width", 0, 1e5, false).value_or(0));
        browser.window_height = static_cast<int>(
            number_field(*client, "window_height", 0, 1e5, false).value_or(0));
        browser.screen_width = static_cast<int>(
            number_field(*client, "screen_width", 0, 1e5, false).value_or(0));
        browser.screen_height = static_cast<int>(
            number_field(*client, "screen_height", 0, 1e5, false).value_or(0));
        browser.device_pixel_ratio =
            number_field(*client, "device_pixel_ratio", 0.05, 16, false).value_or(0);
        browser.refresh_hz = number_field(*client, "refresh_hz", 1, 1000, false);
    }
    if (field(body, "prolific")) {
        const Participant who = participant_of(body);
        browser.prolific_study = who.prolific_study;
        browser.prolific_session = who.prolific_session;
    }
    return browser;
}

void WebStudy::load_flow(StudyStore& store, Page& page, double now_ms,
                         bool reload) const {
    const int64_t id = page.session.id;
    page.trials = store.trials(id);
    page.flow.emplace(protocol_, store, id, page.trials, store.has_consent(id),
                      ms_to_ns(now_ms));
    page.flow->show_series(&options_.series);
    const std::optional<std::string> text = store.web_position(id);
    const int view = stored_view(text);
    page.done = stored_done(text);
    std::optional<FlowPosition> at = text ? position_of_text(*text) : std::nullopt;
    if (at && reload) {
        // A new page: its clock starts anew, and views of the page before are stale.
        at->serial = view + 1;
        at->entered_ns = ms_to_ns(now_ms);
    }
    if (at && page.flow->restore(*at)) return;
    // The position no longer fits (an answer committed whose position was not stored,
    // a lab station ran the participant meanwhile) or was never stored: from the first
    // open trial, as a resume, with a view past any the page may still show.
    FlowPosition fresh = page.flow->position();
    fresh.serial = std::max(fresh.serial, view + 1);
    page.flow->restore(fresh);
}

void WebStudy::save_position(StudyStore& store, const Page& page) const {
    const SessionFlow& flow = *page.flow;
    store.set_web_position(page.session.id, flow.finished()
                                                ? "done " + std::to_string(flow.serial())
                                                : position_text(flow.position()));
}

// A page (re)loaded for a session in progress: where its page stood (a reload renumbers
// the views), or from the first unanswered trial; a new segment only once the last one
// has an answer.
WebReply WebStudy::resume(StudyStore& store, const std::string& code,
                          const SessionRow& unfinished, const Browser& browser,
                          double t_ms) {
    store.set_status(unfinished.id, "running", false);
    store.resume_segment(unfinished.id, environment_for(browser));
    Page page{code, unfinished, {}, std::nullopt, false};
    load_flow(store, page, t_ms, true);
    save_position(store, page);
    json reply = state(page);
    reply["token"] = session_token(options_.secret, code, unfinished.uuid);
    return {200, to_text(reply)};
}

// A new participant: the consent screen, nothing stored (the same page reloaded keeps
// its pending session's UUID; another page without its token starts a new one).
WebReply WebStudy::show_consent(StudyStore& store, const std::string& code,
                                const std::string& uuid, const Browser& browser,
                                double t_ms) {
    const std::string token = session_token(options_.secret, code, uuid);
    if (protocol_.screens.consent.empty()) {
        // No consent screen in the protocol: the session starts at once.
        WebReply reply = consent(store, code, uuid, browser, false, t_ms, t_ms);
        if (reply.status == 200) {
            json out = json::parse(reply.body);
            out["token"] = token;
            reply.body = to_text(out);
        }
        return reply;
    }
    json reply = pending_state();
    reply["token"] = token;
    return {200, to_text(reply)};
}

WebReply WebStudy::start(const json& body) {
    const Participant who = participant_of(body);
    const std::string& code = who.code;
    const std::string token = text_field(body, "token", kMaxTokenLength, false);
    const double t_ms = *number_field(body, "t_ms", 0, kMaxPageMs, true);
    Browser browser = browser_of(body);  // what this page says about itself

    const ParticipantTurn turn(pool_, code, options_.participant_wait, *waiting_);
    StudyStore& store = turn.store();
    std::optional<SessionRow> unfinished = store.unfinished_session(code);
    if (unfinished && store.complete_session_if_answered(unfinished->id))
        unfinished.reset();  // every trial answered: completed now
    const std::optional<TokenParts> parts = token_parts(token);
    const bool ours = parts && parts->code == code;
    if (unfinished) {
        const bool names_it =
            ours && (same_secret_text(
                         token, session_token(options_.secret, code, unfinished->uuid)) ||
                     same_secret_text(token, legacy_session_token(options_.secret, code,
                                                                  unfinished->uuid)));
        if (!names_it)
            throw RequestError(403, "participant '" + code +
                                        "' has a session in progress in another browser; "
                                        "continue it there (the study link in that "
                                        "browser holds its key)");
        return resume(store, code, *unfinished, browser, t_ms);
    }
    if (store.has_completed_session(code)) {
        json reply = done_state();
        reply["already_completed"] = true;
        return {200, to_text(reply)};
    }
    const bool valid =
        ours && !parts->legacy &&
        same_secret_text(token, session_token(options_.secret, code, parts->uuid));
    // A page whose session was withdrawn is told so once (it then forgets its token).
    if (valid && store.session_withdrawn(parts->uuid))
        throw RequestError(410, kWithdrawn);
    const bool keeps_uuid = valid && !store.session_by_uuid(parts->uuid) &&
                            !store.consent_declined(parts->uuid);
    return show_consent(store, code, keeps_uuid ? parts->uuid : new_uuid_v4(), browser,
                        t_ms);
}

// The answer on a pending page's consent screen. Declined: the code counted among those
// that declined. Agreed: enrolled (number, cell, session, plan) with its consent in one
// transaction, then the same SessionFlow as in the lab takes it past the consent screen.
WebReply WebStudy::consent(StudyStore& store, const std::string& code,
                           const std::string& uuid, const Browser& browser, bool decline,
                           double shown_ms, double t_ms) {
    if (decline) {
        // Counted once per code (a decline sent again, a reload or a second page is not
        // a second person); this page stays declined.
        store.decline_consent(study_id_, code, uuid);
        return declined_reply();
    }
    // One session in progress per participant: another browser's is theirs to go on.
    if (store.unfinished_session(code))
        throw RequestError(403, "participant '" + code +
                                    "' has a session in progress in another browser; "
                                    "continue it there");
    if (store.has_completed_session(code)) return {200, to_text(done_state())};
    OnlineEnrolment how;
    how.session_uuid = uuid;
    how.seed = seed_of(uuid);
    how.cells = protocol_.randomisation.counterbalance_blocks
                    ? latin_square_rows(static_cast<int>(protocol_.blocks.size()))
                    : 1;
    how.active_since_utc = active_since_utc();
    how.plan = [&](int cell) { return plan_trials(protocol_, how.seed, cell); };
    // Consent goes with the enrolment: a fault after it cannot leave a stored session,
    // with its user agent and Prolific ids, that has no consent.
    how.consented = !protocol_.screens.consent.empty();
    const OnlineSession enrolled =
        store.enrol_online(study_id_, code, how, environment_for(browser));
    Page page{code, enrolled.session, store.trials(enrolled.session.id), std::nullopt,
              false};
    SessionFlow flow(protocol_, store, enrolled.session.id, page.trials, how.consented,
                     ms_to_ns(shown_ms));
    flow.show_series(&options_.series);  // copies keep it; options_ outlives them
    if (flow.screen() == Screen::Consent) {
        flow.presented(flow.serial(), ms_to_ns(shown_ms));
        flow.key({Key::Enter, 0, ms_to_ns(t_ms)});  // consent is on record already
    }
    page.flow.emplace(flow);
    save_position(store, page);
    return {200, to_text(state(page))};
}

json WebStudy::pending_state() const {
    json out;
    out["screen"] = "consent";
    out["view"] = kConsentView;
    out["title"] = protocol_.title;
    out["background"] = css_colour(protocol_.background);
    out["progress"] = {{"done", 0}, {"total", main_trials_}};
    json questions = json::array();
    for (const Question& q : protocol_.questions)
        questions.push_back({{"id", q.id}, {"text", q.text}, {"labels", q.labels}});
    out["questions"] = questions;
    out["text"] = protocol_.screens.consent;
    return out;
}

// ---- [SECTION] actions ----------------------------------------------------------------
// The session a token names, checked against the secret: pending (no session of its UUID
// yet), withdrawn (410), or the participant's session in the store.
WebReply WebStudy::act(std::string_view endpoint, const json& body) {
    const std::string token = text_field(body, "token", kMaxTokenLength, true);
    const std::optional<TokenParts> parts = token_parts(token);
    if (!parts) throw RequestError(403, "unknown session token");
    const std::string& code = parts->code;
    if (parts->legacy) {
        // An earlier serve's token: /api/session takes it (for the session in progress)
        // and gives the page a new one.
        StorePool::Lease lease = pool_.lease();
        const std::optional<SessionRow> unfinished = lease->unfinished_session(code);
        if (!unfinished ||
            !same_secret_text(
                token, legacy_session_token(options_.secret, code, unfinished->uuid)))
            throw RequestError(403, "unknown session token");
        throw RequestError(409, "session of '" + code +
                                    "' is not loaded; start it again (POST /api/session "
                                    "with its token)");
    }
    if (!same_secret_text(token, session_token(options_.secret, code, parts->uuid)))
        throw RequestError(403, "unknown session token");

    const ParticipantTurn turn(pool_, code, options_.participant_wait, *waiting_);
    StudyStore& store = turn.store();
    const std::optional<SessionRow> session = store.session_by_uuid(parts->uuid);
    if (!session) {
        if (store.session_withdrawn(parts->uuid)) throw RequestError(410, kWithdrawn);
        if (store.consent_declined(parts->uuid)) {
            if (endpoint == "decline") return declined_reply();  // sent again
            throw RequestError(409,
                               "this page declined; start again to see the consent "
                               "screen anew");
        }
        return act_pending(store, endpoint, code, parts->uuid, body);
    }
    if (session->participant != code) throw RequestError(403, "unknown session token");
    if (session->status == "aborted")
        throw RequestError(410, "this session has ended; you may close this window");
    Page page{code, *session, {}, std::nullopt, false};
    try {
        return act_enrolled(store, endpoint, page, body);
    } catch (const StoreUnavailable&) {
        throw;
    } catch (const StoreError&) {
        // Refused by the store: when because the participant was withdrawn while the page
        // was open, the page is told so instead of the store's words.
        if (!store.participant_counts(code)) throw RequestError(410, kWithdrawn);
        throw;
    }
}

// An action of a pending page: only its consent screen is shown (the answer agrees or
// declines, with what the browser says about itself).
WebReply WebStudy::act_pending(StudyStore& store, std::string_view endpoint,
                               const std::string& code, const std::string& uuid,
                               const json& body) {
    if (endpoint == "state") return {200, to_text(pending_state())};
    if (endpoint == "environment") {
        // Nothing is kept before consent: the page sends its estimate with its answer.
        number_field(body, "refresh_hz", 1, 1000, true);
        return {200, to_text(pending_state())};
    }
    if (endpoint == "answer")
        throw RequestError(409, "the consent screen is shown; no trial yet");
    const double view = *number_field(body, "view", 0, 1e9, true);
    const double shown_ms = *number_field(body, "shown_ms", 0, kMaxPageMs, true);
    const double t_ms = *number_field(body, "t_ms", 0, kMaxPageMs, true);
    if (static_cast<int>(view) != kConsentView)
        throw RequestError(409, "view " + std::to_string(static_cast<int>(view)) +
                                    " is no longer shown (now view " +
                                    std::to_string(kConsentView) + ")");
    if (t_ms < shown_ms)
        throw RequestError(400,
                           "the key came before the screen was shown (t_ms < shown_ms)");
    if (field(body, "prolific") && participant_of(body).code != code)
        throw RequestError(400, "PROLIFIC_PID differs from the token's participant");
    return consent(store, code, uuid, browser_of(body), endpoint == "decline", shown_ms,
                   t_ms);
}

WebReply WebStudy::act_enrolled(StudyStore& store, std::string_view endpoint, Page& page,
                                const json& body) {
    // The page's clock: the request's t_ms when it has one (a new screen's blank begins
    // then), else the stored position's.
    const double t_ms = number_field(body, "t_ms", 0, kMaxPageMs, false).value_or(0.0);
    load_flow(store, page, t_ms, false);
    if (page.done) return {200, to_text(done_state())};
    if (endpoint == "state") return {200, to_text(state(page))};
    if (endpoint == "environment") {
        Browser browser = browser_of(body);
        browser.refresh_hz = number_field(body, "refresh_hz", 1, 1000, true);
        store.update_environment(page.session.id, environment_for(browser));
        return {200, to_text(state(page))};
    }
    WebReply reply = endpoint == "answer" ? answer(page, body)
                                          : continue_or_decline(endpoint, page, body);
    if (reply.status == 200 && page.flow) save_position(store, page);
    return reply;
}

// continue / decline: Enter (or N on the consent screen) on the view shown.
WebReply WebStudy::continue_or_decline(std::string_view endpoint, Page& page,
                                       const json& body) {
    SessionFlow& flow = *page.flow;
    const double view = *number_field(body, "view", 0, 1e9, true);
    const double shown_ms = *number_field(body, "shown_ms", 0, kMaxPageMs, true);
    const double t_ms = *number_field(body, "t_ms", 0, kMaxPageMs, true);
    if (static_cast<int>(view) != flow.serial())
        throw RequestError(409, "view " + std::to_string(static_cast<int>(view)) +
                                    " is no longer shown (now view " +
                                    std::to_string(flow.serial()) + ")");
    const Screen screen = flow.screen();
    const bool decline = endpoint == "decline";
    if (decline && screen != Screen::Consent)
        throw RequestError(409, "declining is possible only on the consent screen");
    if (screen == Screen::Blank || screen == Screen::Trial || screen == Screen::Done)
        throw RequestError(409, std::string("the ") + screen_name(screen) +
                                    " screen is not continued with Enter");
    SessionFlow next = flow;  // changes kept only when the key was taken
    next.presented(next.serial(), ms_to_ns(shown_ms));
    next.key({decline ? Key::Decline : Key::Enter, 0, ms_to_ns(t_ms)});
    if (next.serial() == flow.serial() && !next.finished())
        throw RequestError(400,
                           "the key came before the screen was shown (t_ms < shown_ms)");
    if (decline) {
        // A session stored before consent (by a lab station, or an older lucent
        // serve) is left 'aborted', as a lab decline leaves it.
        page.flow.reset();
        return {200, to_text(json{{"screen", "declined"},
                                  {"text",
                                   "You did not agree to take part. You may close this "
                                   "window."}})};
    }
    page.flow.emplace(next);
    if (next.screen() == Screen::Done) return {200, to_text(done_state())};
    return {200, to_text(state(page))};
}

WebReply WebStudy::answer(Page& page, const json& body) {
    SessionFlow& flow = *page.flow;
    const std::string trial_uuid = text_field(body, "trial", 64, true);
    // The same answer sent again (its reply was lost; the proxy or the page retried it,
    // perhaps to another serve process): stored once, and the page shown where it is.
    for (const TrialRow& t : page.trials)
        if (t.uuid == trial_uuid && t.answered) {
            json reply = state(page);
            reply["already_answered"] = true;
            return {200, to_text(reply)};
        }
    check_trial_on_screen(flow, page.trials, trial_uuid);
    const double view = *number_field(body, "view", 0, 1e9, true);
    if (static_cast<int>(view) != flow.serial())
        throw RequestError(409, "view " + std::to_string(static_cast<int>(view)) +
                                    " is no longer shown (now view " +
                                    std::to_string(flow.serial()) + ")");
    const double onset_ms = *number_field(body, "onset_ms", 0, kMaxPageMs, true);
    const TrialRow& trial = *flow.trial();
    const Block* block = protocol_.find_block(trial.block);
    const bool sequential = is_choice_task(trial.task) && block &&
                            block->presentation == Presentation::sequential;
    const std::optional<SequenceOnsets> sequence = sequence_onsets_of(body, sequential);
    const std::vector<AnswerEvent> replay =
        events_of(body, trial.task->questions(protocol_, block), trial.task,
                  block ? block->answers() : 2);

    SessionFlow next =
        replayed(flow, onset_ms, sequence, replay, protocol_.inter_trial_ms);
    for (TrialRow& t : page.trials)
        if (t.uuid == trial_uuid) t.answered = true;
    page.flow.emplace(next);
    return {200, to_text(state(page))};
}

// ---- [SECTION] the state a page shows -------------------------------------------------
json WebStudy::rating_trial(const TrialRow& t) const {
    const WebImage& image = options_.images.at(t.stimulus);
    json questions = json::array();
    for (const Question& q : t.task->questions(protocol_, protocol_.find_block(t.block)))
        questions.push_back({{"id", q.id}, {"text", q.text}, {"labels", q.labels}});
    return {{"id", t.uuid},
            {"questions", questions},
            {"task", task_name(t.task)},
            {"image", picture_names_.url(t.uuid, 0, t.stimulus)},
            {"width", image.width},
            {"height", image.height},
            {"practice", t.practice},
            {"prompt", t.is_catch ? t.prompt : std::string()},
            {"blank_ms", protocol_.inter_trial_ms}};
}

// A forced choice: its pictures in screen order, the block's question and answers, and
// how they are shown. Never which answer is right, nor whether it is a catch trial (an
// attention check the page could tell would be one a script could pass).
json WebStudy::choice_trial(const TrialRow& t,
                            const std::vector<std::string>& pictures) const {
    const Block& block = *protocol_.find_block(t.block);
    json shown = json::array();
    for (size_t slot = 0; slot < pictures.size(); ++slot) {
        const std::string& id = pictures[slot];
        const WebImage& image = options_.images.at(id);
        shown.push_back({{"image", picture_names_.url(t.uuid, slot, id)},
                         {"width", image.width},
                         {"height", image.height}});
    }
    json out = {
        {"id", t.uuid},
        {"task", task_name(t.task)},
        {"shown", shown},
        {"groups", block.task->answer_groups(block)},  // what each answer names
        {"question", block.question},
        {"labels", block.labels},
        {"presentation",
         block.presentation == Presentation::sequential ? "sequential" : "side_by_side"},
        {"practice", t.practice},
        {"prompt", ""},
        {"blank_ms", protocol_.inter_trial_ms}};
    if (block.presentation == Presentation::sequential)
        out["sequence"] = {{"duration_ms", block.duration_ms},
                           {"blank_ms", block.blank_ms}};
    return out;
}

// An adjustment: the target and the match's series of pictures, and what the page needs
// to move over the series exactly as the flow's AdjustInput does (the range on the
// block's scale, its steps, the start). Never the target's value.
json WebStudy::adjust_trial(const TrialRow& t) const {
    const Block& block = *protocol_.find_block(t.block);
    const KnobSeries& series = *options_.series.find(t.block, block.match);
    // The start as the flow takes it: the series value nearest the planned start.
    const AdjustInput start(block, t.start_value.value_or(0.0), 0, series.steps);
    // The range on the scale, as AdjustInput computes it (the page cannot: its log10
    // may differ in the last bit).
    const bool log = block.scale == "log";
    // Slot 0 is the target, 1.. the series.
    json urls = json::array();
    for (size_t i = 0; i < series.pictures.size(); ++i)
        urls.push_back(picture_names_.url(t.uuid, i + 1, series.pictures[i]));
    const WebImage& target = options_.images.at(t.stimulus);
    const WebImage& match = options_.images.at(series.pictures.front());
    return {{"id", t.uuid},
            {"task", "adjust"},
            {"target",
             {{"image", picture_names_.url(t.uuid, 0, t.stimulus)},
              {"width", target.width},
              {"height", target.height}}},
            {"match", {{"width", match.width}, {"height", match.height}}},
            {"series", urls},
            {"low", log ? std::log10(block.range_min) : block.range_min},
            {"high", log ? std::log10(block.range_max) : block.range_max},
            {"coarse", block.step},
            {"fine", block.fine_step},
            {"start_index", start.series_index()},
            {"question", block.question},
            {"practice", t.practice},
            {"prompt", ""},
            {"blank_ms", protocol_.inter_trial_ms},
            {"max_events", kMaxEventsPerAnswer}};
}

// A staircase trial: a forced choice between the standard and the comparison, the
// ladder's picture of the delta the flow shows (its rung), at the comparison's place;
// an odd one out shows the standard twice. Which one is the comparison is not said.
json WebStudy::staircase_trial(const TrialRow& t, const SessionFlow& flow) const {
    const KnobSeries& ladder = *options_.series.find(t.block, t.stimulus);
    const std::optional<adaptive::Proposal> delta = flow.staircase_delta();
    if (!delta) throw std::logic_error("a staircase trial on screen without a delta");
    std::vector<std::string> shown = t.shown;
    shown.at(static_cast<size_t>(t.expected - 1)) =
        ladder.pictures[nearest_step(ladder.steps, delta->intensity)];
    return choice_trial(t, shown);
}

json WebStudy::done_state() const {
    json out{{"screen", "done"},
             {"text", "Thank you: the study is complete and your answers are saved."}};
    json completion = json::object();
    if (!protocol_.online.completion_code.empty())
        completion["code"] = protocol_.online.completion_code;
    if (!protocol_.online.completion_url.empty())
        completion["url"] = protocol_.online.completion_url;
    out["completion"] = completion;
    return out;
}

json WebStudy::state(const Page& page) const {
    const SessionFlow& flow = *page.flow;
    json out;
    out["screen"] = screen_name(flow.screen());
    out["view"] = flow.serial();
    out["title"] = protocol_.title;
    out["background"] = css_colour(protocol_.background);
    out["progress"] = {{"done", flow.main_trials_done()},
                       {"total", flow.main_trials_total()}};
    json questions = json::array();
    for (const Question& q : protocol_.questions)
        questions.push_back({{"id", q.id}, {"text", q.text}, {"labels", q.labels}});
    out["questions"] = questions;
    if (const TrialRow* t = flow.trial()) {
        const TrialScreen screen = t->task->screen();
        switch (screen) {
            case TrialScreen::scales:
                out["trial"] = rating_trial(*t);
                break;
            case TrialScreen::adjust:
                out["trial"] = adjust_trial(*t);
                break;
            case TrialScreen::staircase:
                out["trial"] = staircase_trial(*t, flow);
                break;
            case TrialScreen::choice:
                out["trial"] = choice_trial(*t, t->shown);
                break;
        }
        // The page draws the screen; `task` names the kind (its class on the page).
        out["trial"]["screen"] = screen_name(screen);
    } else {
        const std::string& text = flow.text();
        out["text"] = text.empty() ? std::string("Press Enter.") : text;
    }
    return out;
}

}  // namespace lucent::study
