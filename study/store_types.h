#pragma once
// The rows the study store reads and writes, shared by every backend (study_store.h).
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "study/protocol.h"

namespace lucent::study {

// Any storage failure, from every backend; what() is one line naming the store (its
// file or its server).
class StoreError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// The store cannot be reached now (a server away, every pooled connection busy past the
// wait): nothing was written, and the same call may succeed later. `lucent serve` answers
// it with 503 and Retry-After.
class StoreUnavailable : public StoreError {
public:
    using StoreError::StoreError;
};

// The resolved description of a stimulus as stored (technique, mesh, mesh hash, every
// knob value); compared between sessions and between databases being merged.
struct ResolvedStimulus {
    std::string technique;
    std::string mesh;
    std::string mesh_hash;
    std::map<std::string, std::string> values;
};

// What one stimulus is, as the renderer resolved it and as a segment shows it.
struct StimulusProvenance {
    std::string stimulus;   // protocol id
    std::string source;     // "live", "images" (a --images file checked against its
                            // manifest) or "image" (the protocol's own image file)
    std::string technique;  // "" for image stimuli
    std::string mesh;  // resolved mesh spec (the default when the protocol names none)
    std::string mesh_hash;  // content hash of that mesh
    // Every knob of the technique and the scene, defaults included, in knob order, as
    // format_knob_value() writes them; empty for image stimuli.
    std::vector<std::pair<std::string, std::string>> values;
    std::string software_version;  // the lucent that made the picture (the manifest's for
    std::string build_hash;        // --images files)
    std::string file;              // the image file shown; "" when rendered live
    std::string content_hash;  // the manifest's content hash of that file; "" when live
};

// Where a session segment ran.
struct SessionEnvironment {
    std::string machine_id;
    std::string software_version;
    std::string build_hash;
    std::string gl_vendor;
    std::string gl_renderer;
    std::string display_mode;                   // e.g. "1280x1024 fullscreen, mode 60 Hz"
    std::optional<double> display_refresh_hz;   // video mode's rate; NULL when it says 0
    std::optional<double> measured_refresh_hz;  // from swap intervals; NULL when unknown
    std::string refresh_note;                   // why a refresh is NULL, or a warning
    std::vector<StimulusProvenance> stimuli;    // what this segment shows (may be empty)
    // Pictures shown beyond the protocol's stimuli (`lucent serve`: an adjust series'
    // steps, a staircase's ladder), each with `stimulus` = the picture's id (BASE@...),
    // its file and content hash; recorded once per distinct set (series_pictures).
    std::vector<StimulusProvenance> series_pictures;
};

struct SessionRow {
    int64_t id = 0;
    std::string uuid;
    int64_t participant_id = 0;
    std::string participant;
    uint64_t seed = 0;
    int cell = 0;
    std::string status;  // running, paused, completed, aborted
};

struct TrialRow {
    int64_t id = 0;
    int position = 0;
    std::string block;
    std::string stimulus;
    bool practice = false;
    bool is_catch = false;
    std::string prompt;
    int expected = 0;
    bool break_before = false;
    bool answered = false;
    std::string uuid;  // schema 4: the trial's identity across stores (resends, merges)
    Task task = Task::rating;        // schema 6 (NULL before: rating)
    std::vector<std::string> shown;  // forced choices: stimulus ids in screen order
    // Schema 7 (issue 31). Adjust: the planned start and, once answered, the confirmed
    // value. Staircase: the slot's procedure (planned), the delta shown (answered), and
    // whether the slot was skipped because its procedure had finished.
    std::optional<double> start_value;
    std::optional<double> final_value;
    std::string staircase;
    std::optional<double> intensity;
    bool skipped = false;
    // The answer to a forced choice or a staircase trial (its block's question); nullopt
    // before it is answered and for ratings.
    std::optional<int> choice;
};

// One change of an adjust trial's knob, as the participant made it.
struct Adjustment {
    double value = 0;   // the knob's value after the change
    int64_t t_ns = 0;   // steady-clock timestamp of the change
    std::string input;  // "key", "fine_key", "wheel" or "drag"
};

// One rating as the runner collected it.
struct Response {
    std::string question;
    int rating = 0;               // 1..points
    double rt_ms = 0;             // from stimulus onset to the final choice
    int changes = 0;              // times the choice changed after the first one
    int64_t first_choice_ns = 0;  // steady-clock timestamps (raw, monotonic)
    int64_t final_choice_ns = 0;
};

struct TrialOutcome {
    int64_t onset_ns = 0;               // first swap showing the stimulus, after glFinish
    int64_t confirm_ns = 0;             // when the answer was made final
    std::optional<int> dropped_frames;  // NULL when the refresh is unknown
    std::vector<Response> responses;
    // Adjust trials: the confirmed value (the response is then the block's question
    // with rating 1, "confirmed") and every change on the way, in order.
    std::optional<double> final_value;
    std::vector<Adjustment> adjustments;
    // Staircase trials: the delta shown (the response is the place chosen), and whether
    // this answer finished the slot's procedure: the store then marks the procedure's
    // unanswered slots skipped in the same transaction.
    std::optional<double> intensity;
    bool finishes_staircase = false;
};

struct ParticipantCounts {
    int64_t sessions = 0;
    int64_t ratings = 0;
};

}  // namespace lucent::study
