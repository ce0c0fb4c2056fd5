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
#include <random>
#include <stdexcept>

#include "common/srgb.h"
#include "study/serve/answer_events.h"
#include "study/serve/request_fields.h"
#include "study/session/adjust_input.h"
#include "study/session/session_flow.h"
#include "study/sha256.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

using nlohmann::json;

namespace {

// ---- [SECTION] tokens and names -------------------------------------------------------
std::string bytes_of_hex(const std::string& hex) {
    std::string out;
    for (size_t i = 0; i + 1 < hex.size(); i += 2)
        out += static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16));
    return out;
}

// Compares without an early exit, so the time taken tells nothing about the token.
bool same_secret_text(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
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

int64_t random_seed() {
    std::random_device device;
    return static_cast<int64_t>((uint64_t(device()) << 32 | device()) &
                                0x7FFFFFFFFFFFFFFFull);
}

std::string css_colour(const float rgb[3]) {
    // The protocol's background is linear; the page takes sRGB.
    // In double (as the page always had it), rounded to 8 bits.
    auto encode = [](float c) {
        return static_cast<int>(std::lround(common::srgb_encode(double(c)) * 255));
    };
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

std::string hmac_sha256_hex(std::string_view key, std::string_view message) {
    constexpr size_t kBlock = 64;
    std::string k =
        key.size() > kBlock ? bytes_of_hex(sha256_hex(key)) : std::string(key);
    k.resize(kBlock, '\0');
    std::string inner(kBlock, '\0'), outer(kBlock, '\0');
    for (size_t i = 0; i < kBlock; ++i) {
        inner[i] = static_cast<char>(k[i] ^ 0x36);
        outer[i] = static_cast<char>(k[i] ^ 0x5c);
    }
    return sha256_hex(outer + bytes_of_hex(sha256_hex(inner + std::string(message))));
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
    return std::string(code) + "." + hmac_sha256_hex(secret, session_uuid);
}

std::optional<std::string> image_of_target(
    std::string_view target, const std::map<std::string, WebImage>& images) {
    target = target.substr(0, target.find('?'));
    std::string path;
    for (size_t i = 0; i < target.size(); ++i) {
        if (target[i] != '%') {
            path += target[i];
            continue;
        }
        if (i + 2 >= target.size() || hex_digit(target[i + 1]) < 0 ||
            hex_digit(target[i + 2]) < 0)
            return std::nullopt;
        path +=
            static_cast<char>(hex_digit(target[i + 1]) * 16 + hex_digit(target[i + 2]));
        i += 2;
    }
    const std::string_view prefix = "/images/", suffix = ".png";
    if (path.size() <= prefix.size() + suffix.size() ||
        path.compare(0, prefix.size(), prefix) != 0 ||
        path.compare(path.size() - suffix.size(), suffix.size(), suffix) != 0)
        return std::nullopt;
    const std::string id =
        path.substr(prefix.size(), path.size() - prefix.size() - suffix.size());
    // A name, never a path: no separator, no parent, nothing a file system would resolve.
    if (id.find_first_of("/\\%") != std::string::npos ||
        id.find("..") != std::string::npos || id.find('\0') != std::string::npos ||
        !images.count(id))
        return std::nullopt;
    return id;
}

// ---- [SECTION] sessions ---------------------------------------------------------------
// A page is `pending` from its first request until the participant agrees on the consent
// screen: held in memory only (the session UUID and so its token, the seed, what the
// browser said), nothing stored. Agreeing enrols it (StudyStore::enrol_online), and from
// then on it is a session like a lab station's.
struct WebStudy::Live {
    std::string code;
    bool pending = false;
    uint64_t seed = 0;   // pending: the seed its plan will have
    SessionRow session;  // pending: only the UUID
    std::string token;
    std::vector<TrialRow> trials;  // as stored when loaded; `answered` kept up to date
    std::optional<SessionFlow> flow;
    std::chrono::system_clock::time_point seen;  // the page's last request
    // What the browser said about itself (the segment's environment).
    std::string user_agent;
    int window_width = 0, window_height = 0, screen_width = 0, screen_height = 0;
    double device_pixel_ratio = 0;
    std::optional<double> refresh_hz;
    std::string prolific_study, prolific_session;
};

namespace {

// The view a pending page's consent screen has: a new SessionFlow's first screen.
constexpr int kConsentView = 1;

const char* const kWithdrawn =
    "this session was withdrawn: nothing more of it is recorded. You may close this "
    "window.";

}  // namespace

WebStudy::WebStudy(const Protocol& protocol, StudyStore& store, WebStudyOptions options)
    : protocol_(protocol), store_(store), options_(std::move(options)) {
    for (const StimulusSpec& s : protocol_.stimuli)
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
    study_id_ = store_.ensure_study(protocol_);
    store_.check_stimulus_values(options_.environment.stimuli);
}

WebStudy::~WebStudy() = default;

std::chrono::system_clock::time_point WebStudy::now() const { return options_.clock(); }

std::string WebStudy::active_since_utc() const {
    return utc_iso8601(now() -
                       std::chrono::duration_cast<std::chrono::system_clock::duration>(
                           options_.idle_timeout));
}

size_t WebStudy::live_sessions() const {
    std::lock_guard lock(mutex_);
    size_t n = 0;
    for (const auto& [code, live] : live_) n += live->pending ? 0 : 1;
    return n;
}

size_t WebStudy::pending_sessions() const {
    std::lock_guard lock(mutex_);
    size_t n = 0;
    for (const auto& [code, live] : live_) n += live->pending ? 1 : 0;
    return n;
}

size_t WebStudy::release_idle() {
    std::lock_guard lock(mutex_);
    return release_idle_locked();
}

size_t WebStudy::release_idle_locked() {
    const auto cutoff =
        now() - std::chrono::duration_cast<std::chrono::system_clock::duration>(
                    options_.idle_timeout);
    std::vector<std::string> idle;
    for (const auto& [code, live] : live_)
        if (live->seen < cutoff) idle.push_back(code);
    for (const std::string& code : idle) {
        Live& live = *live_.at(code);
        if (!live.pending && live.flow &&
            live.flow->answered_trials() < live.flow->total_trials()) {
            try {
                store_.set_status(live.session.id, "paused",
                                  false);  // as a lab quit leaves it
            } catch (const std::exception&) {
                // Withdrawn, completed meanwhile, or the server away: the claim ends
                // anyway.
            }
        }
        drop(code);
    }
    return idle.size();
}

void WebStudy::drop(const std::string& code) {
    const auto it = live_.find(code);
    if (it == live_.end()) return;
    const bool loaded = !it->second->pending;
    live_.erase(it);
    if (!loaded) return;
    try {
        store_.release_participant(code);
    } catch (const std::exception&) {
        // A release that fails leaves the lock to the connection's end (its next loss).
    }
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
    std::lock_guard lock(mutex_);
    try {
        release_idle_locked();
        if (endpoint == "session") return start(request);
        if (endpoint == "state" || endpoint == "continue" || endpoint == "decline" ||
            endpoint == "answer" || endpoint == "environment")
            return act(endpoint, request);
        return error_reply(404, "no API endpoint '" + std::string(endpoint) + "'");
    } catch (const RequestError& e) {
        return error_reply(e.status, e.what());
    } catch (const json::exception& e) {
        return error_reply(400, std::string("bad request: ") + e.what());
    } catch (const StoreError& e) {
        // Refused by the store (a participant run on a lab station now, a rating it
        // does not accept): nothing was written.
        return error_reply(409, e.what());
    } catch (const std::exception& e) {
        return error_reply(500, e.what());
    }
}

SessionEnvironment WebStudy::environment_for(const Live& live) const {
    SessionEnvironment env = options_.environment;
    env.gl_vendor = "web browser";
    env.gl_renderer = live.user_agent;  // the browser draws: its user agent
    std::string mode = "browser window " + std::to_string(live.window_width) + "x" +
                       std::to_string(live.window_height) + " CSS px, devicePixelRatio ";
    char dpr[32];
    std::snprintf(dpr, sizeof dpr, "%g", live.device_pixel_ratio);
    mode += dpr;
    if (live.screen_width > 0)
        mode += ", screen " + std::to_string(live.screen_width) + "x" +
                std::to_string(live.screen_height);
    if (!live.prolific_study.empty() || !live.prolific_session.empty())
        mode += "; Prolific STUDY_ID=" + live.prolific_study +
                " SESSION_ID=" + live.prolific_session;
    env.display_mode = mode;
    env.display_refresh_hz.reset();
    env.measured_refresh_hz = live.refresh_hz;
    env.refresh_note = live.refresh_hz
                           ? "browser estimate: median requestAnimationFrame interval"
                           : "refresh not measured by the browser (yet)";
    return env;
}

WebStudy::Live& WebStudy::load(const std::string& code, const SessionRow& session,
                               const std::string& token) {
    auto live = std::make_unique<Live>();
    live->code = code;
    live->session = session;
    live->token = token;
    live->seen = now();
    Live& out = *live;
    live_[code] = std::move(live);
    return out;
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

// What this page says about itself: the request's `client` fields (Prolific's ids are
// the caller's to add).
WebStudy::Live WebStudy::browser_of(const json& body) {
    Live browser;
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
    return browser;
}

void WebStudy::take_browser(Live& live, const Live& browser) {
    live.user_agent = browser.user_agent;
    live.window_width = browser.window_width;
    live.window_height = browser.window_height;
    live.screen_width = browser.screen_width;
    live.screen_height = browser.screen_height;
    live.device_pixel_ratio = browser.device_pixel_ratio;
    live.refresh_hz = browser.refresh_hz;
    live.prolific_study = browser.prolific_study;
    live.prolific_session = browser.prolific_session;
}

// The participant's session in progress in the store, if any; a loaded page whose
// session ended is forgotten first, and a session whose every trial is answered is
// completed instead.
std::optional<SessionRow> WebStudy::unfinished_session_of(const std::string& code,
                                                          const std::string& token) {
    std::optional<SessionRow> unfinished = store_.unfinished_session(code);
    if (const auto it = live_.find(code);
        it != live_.end() && !it->second->pending &&
        (!unfinished || unfinished->id != it->second->session.id)) {
        // The loaded session is no longer an unfinished one of the store: completed, or
        // withdrawn (`participants withdraw`) while its page was open.
        const bool same_page = same_secret_text(token, it->second->token);
        drop(code);
        if (same_page && !store_.has_completed_session(code) &&
            !store_.participant_counts(code))
            throw RequestError(410, kWithdrawn);
    }
    if (unfinished && store_.complete_session_if_answered(unfinished->id)) {
        drop(code);
        unfinished.reset();
    }
    return unfinished;
}

// A page (re)loaded for a session in progress: from the first unanswered trial, as
// `lucent run --resume` does; a new segment only once the last one has an answer.
WebReply WebStudy::resume(const std::string& code, const std::string& token,
                          const SessionRow& unfinished, const Live& browser,
                          double t_ms) {
    const std::string in_progress =
        "participant '" + code +
        "' has a session in progress in another browser; continue "
        "it there (the study link in that browser holds its key)";
    const std::string expected = session_token(options_.secret, code, unfinished.uuid);
    if (!same_secret_text(token, expected)) throw RequestError(403, in_progress);
    store_.claim_participant(code);
    Live probe;
    take_browser(probe, browser);
    const SessionEnvironment env = environment_for(probe);
    store_.set_status(unfinished.id, "running", false);
    store_.resume_segment(unfinished.id, env);
    Live& live = load(code, unfinished, expected);
    take_browser(live, browser);
    live.trials = store_.trials(unfinished.id);
    live.flow.emplace(protocol_, store_, unfinished.id, live.trials,
                      store_.has_consent(unfinished.id), ms_to_ns(t_ms));
    live.flow->show_series(&options_.series);
    json reply = state(live);
    reply["token"] = live.token;
    return {200, to_text(reply)};
}

// A new participant: the consent screen, nothing stored (the same page reloaded
// keeps its pending session; another page without its token starts a new one).
WebReply WebStudy::show_consent(const std::string& code, const std::string& token,
                                const Live& browser, double t_ms) {
    const auto it = live_.find(code);
    if (it == live_.end() || !it->second->pending ||
        !same_secret_text(token, it->second->token)) {
        drop(code);
        if (live_.size() >= options_.max_pending) {
            // Forget the pending page idle longest (it holds nothing but memory).
            auto oldest = live_.end();
            for (auto i = live_.begin(); i != live_.end(); ++i)
                if (i->second->pending &&
                    (oldest == live_.end() || i->second->seen < oldest->second->seen))
                    oldest = i;
            if (oldest != live_.end()) live_.erase(oldest);
        }
        SessionRow planned;
        planned.uuid = new_uuid_v4();
        Live& live =
            load(code, planned, session_token(options_.secret, code, planned.uuid));
        live.pending = true;
        live.seed = static_cast<uint64_t>(random_seed());
    }
    Live& live = *live_.at(code);
    take_browser(live, browser);
    live.seen = now();
    if (protocol_.screens.consent.empty()) {
        // No consent screen in the protocol: the session starts at once.
        WebReply reply = consent(live, false, t_ms, t_ms);
        if (reply.status == 200) {
            json out = json::parse(reply.body);
            out["token"] = live_.at(code)->token;
            reply.body = to_text(out);
        }
        return reply;
    }
    json reply = pending_state(live);
    reply["token"] = live.token;
    return {200, to_text(reply)};
}

WebReply WebStudy::start(const json& body) {
    const Participant who = participant_of(body);
    const std::string& code = who.code;
    const std::string token = text_field(body, "token", kMaxTokenLength, false);
    const double t_ms = *number_field(body, "t_ms", 0, kMaxPageMs, true);

    Live browser = browser_of(body);  // what this page says about itself
    browser.prolific_study = who.prolific_study;
    browser.prolific_session = who.prolific_session;

    if (const std::optional<SessionRow> unfinished = unfinished_session_of(code, token))
        return resume(code, token, *unfinished, browser, t_ms);
    if (store_.has_completed_session(code)) {
        drop(code);
        json reply = done_state();
        reply["already_completed"] = true;
        return {200, to_text(reply)};
    }
    return show_consent(code, token, browser, t_ms);
}

// The answer on a pending page's consent screen. Declined: one more in the study's count,
// the page forgotten. Agreed: enrolled (number, cell, session, plan) and consent recorded
// through the same SessionFlow as in the lab.
WebReply WebStudy::consent(Live& live, bool decline, double shown_ms, double t_ms) {
    const std::string code = live.code;
    if (decline) {
        store_.count_declined_consent(study_id_);
        drop(code);
        return {200,
                to_text(json{{"screen", "declined"},
                             {"text",
                              "You did not agree to take part. Nothing of yours was "
                              "stored; the study counts only that one person declined. "
                              "You may close this window."}})};
    }
    store_.claim_participant(code);
    OnlineSession enrolled;
    try {
        OnlineEnrolment how;
        how.session_uuid = live.session.uuid;
        how.seed = live.seed;
        how.cells = protocol_.randomisation.counterbalance_blocks
                        ? latin_square_rows(static_cast<int>(protocol_.blocks.size()))
                        : 1;
        how.active_since_utc = active_since_utc();
        how.plan = [&](int cell) { return plan_trials(protocol_, live.seed, cell); };
        enrolled = store_.enrol_online(study_id_, code, how, environment_for(live));
    } catch (...) {
        store_.release_participant(code);
        throw;
    }
    live.pending = false;
    live.session = enrolled.session;
    live.trials = store_.trials(enrolled.session.id);
    SessionFlow flow(protocol_, store_, enrolled.session.id, live.trials, false,
                     ms_to_ns(shown_ms));
    flow.show_series(&options_.series);  // copies keep it; options_ outlives them
    if (flow.screen() == Screen::Consent) {
        flow.presented(flow.serial(), ms_to_ns(shown_ms));
        flow.key({Key::Enter, 0, ms_to_ns(t_ms)});  // records consent
    }
    live.flow.emplace(flow);
    return {200, to_text(state(live))};
}

json WebStudy::pending_state(const Live& live) const {
    (void)live;
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
// The page a token names: loaded here, and the token its own.
WebStudy::Live& WebStudy::page_of_token(const std::string& code,
                                        const std::string& token) {
    const auto it = live_.find(code);
    if (participant_code_problem(code).empty() && it == live_.end()) {
        // Not loaded here (the server restarted, the page was idle, or the session
        // ended): the page starts again through /api/session, which checks the token
        // against the store.
        throw RequestError(409, "session of '" + code +
                                    "' is not loaded; start it again "
                                    "(POST /api/session with its token)");
    }
    if (it == live_.end() || !same_secret_text(token, it->second->token))
        throw RequestError(403, "unknown session token");
    return *it->second;
}

// An action of a pending page: only its consent screen is shown (the answer agrees or
// declines).
WebReply WebStudy::act_pending(std::string_view endpoint, Live& live, const json& body) {
    if (endpoint == "state") return {200, to_text(pending_state(live))};
    if (endpoint == "environment") {
        live.refresh_hz =
            number_field(body, "refresh_hz", 1, 1000, true);  // kept in memory
        return {200, to_text(pending_state(live))};
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
    return consent(live, endpoint == "decline", shown_ms, t_ms);
}

// continue / decline: Enter (or N on the consent screen) on the view shown.
WebReply WebStudy::continue_or_decline(std::string_view endpoint, Live& live,
                                       const std::string& code, const json& body) {
    SessionFlow& flow = *live.flow;
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
        drop(code);
        return {200, to_text(json{{"screen", "declined"},
                                  {"text",
                                   "You did not agree to take part. You may close this "
                                   "window."}})};
    }
    live.flow.emplace(next);
    if (next.screen() == Screen::Done) {
        drop(code);
        return {200, to_text(done_state())};
    }
    return {200, to_text(state(live))};
}

WebReply WebStudy::act(std::string_view endpoint, const json& body) {
    const std::string token = text_field(body, "token", kMaxTokenLength, true);
    const size_t dot = token.rfind('.');
    const std::string code = token.substr(0, dot == std::string::npos ? 0 : dot);
    Live& live = page_of_token(code, token);
    live.seen = now();

    if (live.pending) return act_pending(endpoint, live, body);

    try {
        if (endpoint == "state") return {200, to_text(state(live))};
        if (endpoint == "environment") {
            live.refresh_hz = number_field(body, "refresh_hz", 1, 1000, true);
            store_.update_environment(live.session.id, environment_for(live));
            return {200, to_text(state(live))};
        }
        if (endpoint == "answer") {
            WebReply reply = answer(live, body);
            if (live.flow->answered_trials() == live.flow->total_trials())
                store_.release_participant(
                    code);  // completed: the debrief writes nothing
            return reply;
        }
        return continue_or_decline(endpoint, live, code, body);
    } catch (const StoreError&) {
        // Refused by the store: when because the participant was withdrawn while the page
        // was open, the page is told so (and forgotten) instead of the store's words.
        if (!store_.participant_counts(code)) {
            drop(code);
            throw RequestError(410, kWithdrawn);
        }
        throw;
    }
}

WebReply WebStudy::answer(Live& live, const json& body) {
    SessionFlow& flow = *live.flow;
    const std::string trial_uuid = text_field(body, "trial", 64, true);
    check_trial_on_screen(flow, live.trials, trial_uuid);
    const double view = *number_field(body, "view", 0, 1e9, true);
    if (static_cast<int>(view) != flow.serial())
        throw RequestError(409, "view " + std::to_string(static_cast<int>(view)) +
                                    " is no longer shown (now view " +
                                    std::to_string(flow.serial()) + ")");
    const double onset_ms = *number_field(body, "onset_ms", 0, kMaxPageMs, true);
    const TrialRow& trial = *flow.trial();
    const Block* block = protocol_.find_block(trial.block);
    const bool sequential = trial.task != Task::rating && trial.task != Task::adjust &&
                            block && block->presentation == Presentation::sequential;
    const std::optional<SequenceOnsets> sequence = sequence_onsets_of(body, sequential);
    const std::vector<AnswerEvent> replay =
        events_of(body, protocol_.questions, trial.task, block ? block->answers() : 2);

    SessionFlow next =
        replayed(flow, onset_ms, sequence, replay, protocol_.inter_trial_ms);
    for (TrialRow& t : live.trials)
        if (t.uuid == trial_uuid) t.answered = true;
    live.flow.emplace(next);
    return {200, to_text(state(live))};
}

// ---- [SECTION] the state a page shows -------------------------------------------------
json WebStudy::rating_trial(const TrialRow& t) const {
    const WebImage& image = options_.images.at(t.stimulus);
    return {{"id", t.uuid},
            {"task", task_name(t.task)},
            {"image", "/images/" + t.stimulus + ".png"},
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
    for (const std::string& id : pictures) {
        const WebImage& image = options_.images.at(id);
        shown.push_back({{"image", "/images/" + id + ".png"},
                         {"width", image.width},
                         {"height", image.height}});
    }
    json out = {
        {"id", t.uuid},
        {"task", task_name(t.task)},
        {"shown", shown},
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
    json urls = json::array();
    for (const std::string& id : series.pictures)
        urls.push_back("/images/" + id + ".png");
    const WebImage& target = options_.images.at(t.stimulus);
    const WebImage& match = options_.images.at(series.pictures.front());
    return {{"id", t.uuid},
            {"task", "adjust"},
            {"target",
             {{"image", "/images/" + t.stimulus + ".png"},
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

json WebStudy::state(const Live& live) const {
    const SessionFlow& flow = *live.flow;
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
        out["trial"] = t->task == Task::rating      ? rating_trial(*t)
                       : t->task == Task::adjust    ? adjust_trial(*t)
                       : t->task == Task::staircase ? staircase_trial(*t, flow)
                                                    : choice_trial(*t, t->shown);
    } else {
        const std::string& text = flow.text();
        out["text"] = text.empty() ? std::string("Press Enter.") : text;
    }
    return out;
}

}  // namespace lucent::study
