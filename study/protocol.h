#pragma once
// A study protocol: what participants see and rate, in what order, and how trials are
// randomised. Parsed from TOML (parse_protocol) or the built-in `thesis` preset. GL-free.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/core/stimulus.h"
#include "study/trials/trial_kind.h"

namespace lucent::study {

// Bad protocol text. what() is one line: "FILE:LINE:COL: key 'a.b': reason".
class ProtocolError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct Question {
    std::string id;    // short key stored in responses.question, e.g. "translucent"
    std::string text;  // the statement shown, e.g. "The object looks translucent."
    std::vector<std::string> labels;  // one per scale point (ends may be the only text)
    int points() const { return static_cast<int>(labels.size()); }
};

// A catch trial: a stimulus shown with a prompt that fixes the right answer.
struct CatchTrial {
    std::string id;
    std::string stimulus;  // stimulus id
    std::string block;     // block it is shuffled into
    std::string prompt;    // shown above the scale, e.g. "Attention check: choose 7"
    int expected = 7;      // the expected rating on every question
    int tolerance = 0;     // |rating - expected| <= tolerance passes
};

// What a block's trials ask. `rating`: one picture rated on every [[questions]] entry.
// The forced choices (issue 30): `pair`, which of two pictures is more X (paired
// comparisons: Bradley-Terry, Thurstone); `triad` and `quadruple`, which of two pairs of
// an ordered series differs more (Maximum Likelihood Difference Scaling). Matching and
// thresholds (issue 31): `adjust`, a live match object whose knob the participant turns
// until it looks like a target picture; `staircase`, a forced choice between a standard
// and the standard with a knob changed by a delta that an adaptive procedure chooses.
// Each is one folder and one line of trials/registry.cpp (trial_kind.h: the Task
// handle and what a kind answers for itself).
// "\"rating\", \"pair\", ... or \"staircase\"": every kind's name, for messages.
std::string task_names_text();
const char* task_name(Task task);
std::optional<Task> parse_task(std::string_view text);
// A forced choice the scaling reads (paired comparisons, MLDS): pair, triad, quadruple.
bool is_scaling_task(Task task);
// A trial answered by choosing among its pictures: the scaling's kinds and staircase.
bool is_choice_task(Task task);
// The pictures one trial of the task shows: 1, 2, 3 or 4 (adjust: the target and the
// match; staircase: 2, see Block::pictures() for an odd-one-out staircase's 3).
int pictures_per_trial(Task task);

// How a choice block's pictures are shown: all at once, side by side (a triad in a row,
// a quadruple's pairs as two groups), or one after another (a pair's pictures, an MLDS
// trial's pairs) with a blank between.
enum class Presentation { side_by_side, sequential };

struct Block {
    std::string id;
    // Rating: stimulus ids, each shown `repeats` times. Choice blocks: the series, in
    // its physical order for triads and quadruples.
    std::vector<std::string> stimuli;
    int repeats = 1;
    Task task = Task::rating;
    // Choice blocks only.
    std::string question;     // the text shown, e.g. "Which looks more translucent?"
    std::string question_id;  // stored in responses.question (default: the block id)
    std::vector<std::string> labels;  // the two answers' names (left/right, pairs)
    // Which pairs or groups: "all" (every unordered pair; every triad a<b<c; every
    // quadruple a<b<c<d, MLDS's non-overlapping ones) or, for pairs, "cyclic" (a
    // balanced incomplete design: (i, i+d mod n) for d = 1..neighbours, every stimulus
    // in 2 * neighbours pairs, the comparison graph connected).
    std::string design = "all";
    int neighbours = 0;
    Presentation presentation = Presentation::side_by_side;
    int duration_ms = 1000;   // sequential: each picture (pair) or pair (MLDS) on screen
    int blank_ms = 500;       // sequential: the blank between them
    int identical_catch = 0;  // pair blocks: trials showing one stimulus twice
    // Catch trials with a right answer: {low, high}. A pair block shows them and the
    // answer is `high`; an MLDS block shows (low, low) against (low, high) and the
    // answer is the differing pair.
    std::vector<std::string> obvious_catch;
    int obvious_catch_repeats = 0;
    // The stimulus parameter whose value places each stimulus on the series (the
    // report's axis; MLDS blocks: numeric and increasing along `stimuli`); "" = none.
    std::string series;
    int practice = 0;  // practice trials of this task (from its design) before block 1

    // Adjust and staircase blocks: the knob turned (adjust: of `match`; staircase: of
    // each standard, i.e. each of `stimuli`), a scalar knob of the stimulus's technique.
    std::string knob;
    // Adjust: `stimuli` are the targets; `match` is the live stimulus drawn beside each
    // with `knob` at the participant's value, within [range_min, range_max] (default:
    // the knob's range). Arrows (and the wheel) move by `step`, Shift+arrows by
    // `fine_step`, on the knob's value (`scale` "linear") or its logarithm ("log": the
    // steps are then factors 10^step); a drag across the match moves over the range.
    // Each trial starts at `start`: "random" (uniform over the range on the scale,
    // drawn when the plan is made), "min", "max" or a number.
    std::string match;
    double range_min = 0, range_max = 0;
    double step = 0, fine_step = 0;
    std::string scale = "linear";
    std::string start = "random";
    // Adjust, in the browser (`lucent serve`): the match is a pre-rendered series of
    // this many pictures, evenly spaced on the scale from range_min to range_max (both
    // included); the keys, wheel and drag move as in the lab and show the nearest one.
    // Default: the range in fine steps, plus one.
    int series_steps = 0;
    // Staircase: each standard in `stimuli` runs every [[blocks.staircases]] entry,
    // all interleaved (each round a random order of the procedures still running); a
    // trial shows the standard and the comparison (the standard with `knob` moved by
    // the delta, upwards or downwards by `direction`) as a pair ("pair": which is more
    // X, the comparison's side is right) or three pictures ("oddity": which differs,
    // the comparison's place is right). The procedure's intensity is the delta.
    std::string staircase_trial = "pair";
    std::string direction = "up";
    struct Procedure {
        std::string id;
        std::string method = "updown";  // "updown" (StairHandler) or "quest"
        double start = 0;
        // updown
        int n_up = 1, n_down = 3;
        std::vector<double> step_sizes;
        std::string step_type = "lin";
        int n_trials = 0, n_reversals = 0;
        // quest (Watson and Pelli 1983, as PsychoPy's QuestHandler)
        double start_sd = 0, p_threshold = 0.82, beta = 3.5, delta = 0.01, grain = 0.01;
        double quest_range = 0;  // 0: the whole range of the delta
        // Both: deltas are held within [min_delta, max_delta] (max_delta 0: as far as the
        // knob's range allows from the standard); the plan holds max_trials slots.
        double min_delta = 0, max_delta = 0;
        int max_trials = 50;
    };
    std::vector<Procedure> procedures;
    // Staircase, in the browser: each standard's comparisons are a pre-rendered ladder
    // of deltas k * ladder_step within the procedures' [min_delta, max_delta]; a
    // proposed delta is shown as the nearest rung and the procedure told the delta shown.
    // Default: the smallest step of a linear up/down procedure, else 1/32 of the span.
    double ladder_step = 0;
    // Picture count of one trial: pictures_per_trial, 3 for an odd-one-out staircase.
    int pictures() const;
    // Forced choices, answered 1..answers(): pair, triad, quadruple and staircase.
    bool is_choice() const { return is_choice_task(task); }
    // The number of answers of a trial: 2 (a choice), 3 (an odd-one-out staircase), 1
    // (an adjustment's confirmation), 0 (a rating: its [[questions]]).
    int answers() const;
};

// Randomisation within blocks, and block order across participants.
struct Randomisation {
    bool shuffle = true;
    std::string factor = "stimulus";  // "stimulus", "technique" or a parameter name
    int max_repeat = 0;    // at most this many consecutive trials share a level (0: off)
    int min_distance = 0;  // trials sharing a level are at least this far apart (0: off)
    bool counterbalance_blocks = true;  // Latin square of block order by participant
};

// [analysis]: how `lucent analyze` reads the study's ratings.
struct AnalysisPlan {
    // "within": every participant rates every level (the thesis's survey), so the
    // repeated-measures tests lead the report; "between": independent groups lead.
    std::string primary_design = "within";
    // The analysis that leads the report: "anova" (the thesis's one-way tests, the
    // default) or a registered rating model ("clmm", the ordinal mixed model with
    // participants and stimuli as random effects; "lmm", its linear cousin). Study code
    // cannot see the analysis's registry (analysis/models/): the protocol checks the
    // name's spelling and where it was written, and lucent run, serve and analyze check
    // that it is registered (app/analysis_plan.h).
    std::string primary_model = "anova";
    std::string primary_model_at;  // "p.toml:12:17: key 'analysis.primary_model'"; ""
    // Which sessions enter the analysis (`lucent analyze`, `export --format analysis`):
    // "completed" (the default: a participant who gave up, or quit before the catch
    // trials, is left out as incomplete) or "all" (running, paused and aborted too).
    std::string sessions = "completed";
};

// [online]: how `lucent serve` ends a participant's session in the browser.
struct OnlineSettings {
    std::string completion_code;  // shown on the completion page (e.g. Prolific's code)
    std::string completion_url;   // http(s) URL the page redirects to when the study ends
};

struct Screens {
    std::string consent;
    std::string instructions;
    std::string practice_done = "The practice trials are over. The study starts now.";
    std::string break_text = "Take a short break. Press Enter when you are ready.";
    std::string debrief;
};

struct Protocol {
    std::string name;
    std::string title;
    std::string source;  // file name or "preset:thesis", for messages
    // The TOML text itself (stored with its hash). A protocol that takes its stimuli from
    // a set ([study] stimulus_set) holds the set's text too, in a [embedded_stimulus_set]
    // table appended when it is first read, so the stored protocol needs no other file
    // and its hash changes with the set.
    std::string text;
    std::string stimulus_set;  // "preset:NAME" or a set file; "" when the entries are own
    float background[3] = {0.f, 0.f, 0.f};  // linear 0..1, behind every stimulus
    int stimulus_width = 512;               // live stimuli are rendered at this size
    int stimulus_height = 512;
    int break_every = 0;       // break screen after every N main trials (0: never)
    int inter_trial_ms = 500;  // blank screen between trials
    int max_failed_catch = 0;  // participants failing more catch trials are excluded
    Screens screens;
    std::vector<Stimulus> stimuli;
    std::vector<Question> questions;
    std::vector<std::string> practice;  // stimulus ids of the practice trials, in order
    std::vector<Block> blocks;
    std::vector<CatchTrial> catch_trials;
    Randomisation randomisation;
    AnalysisPlan analysis;
    OnlineSettings online;

    const Stimulus* find_stimulus(std::string_view id) const;
    const Block* find_block(std::string_view id) const;
    // A stimulus's parameter as a finite number (e.g. its place on a block's series);
    // nullopt when it has no such parameter or it is not a number.
    std::optional<double> numeric_parameter(std::string_view stimulus,
                                            const std::string& parameter) const;
    // True when some trial rates a picture on [[questions]] (a rating block or
    // [practice] stimuli); a study of forced choices only needs no [[questions]].
    bool has_rating_trials() const;
    // Level of `factor` for a stimulus ("stimulus", "technique" or a parameter); empty
    // when the stimulus has no such parameter. The level of "stimulus" is the picture:
    // the id of the first stimulus with the same picture_key, so ids that show the same
    // picture (the thesis's rows 1, 4 and 7) share a level.
    std::string level_of(const Stimulus& stimulus, std::string_view factor) const;
    // level_of for every stimulus at once (stimulus id -> level), hashing each image
    // once.
    std::map<std::string, std::string> levels_of(std::string_view factor) const;
    // What the participant sees, independent of the id: a live stimulus's technique,
    // mesh and parameters (as written; a default spelled out counts as different), or a
    // pre-rendered image's content hash (its path when the file cannot be read).
    static std::string picture_key(const Stimulus& stimulus);
};

// How a live stimulus's parameters are held to its technique's knobs.
enum class KnobCheck {
    // A protocol being set up (a file, a preset): every parameter must be a knob of the
    // technique with a value the knob accepts, else ProtocolError at its line.
    strict,
    // A protocol read back from a database: the study already ran with it, so a value
    // today's knobs refuse (a renamed knob, a moved density file) keeps its text.
    lenient,
};

// Parses and validates a protocol. `source` names the file in error messages; image
// paths are resolved relative to `base_dir` when given. Unknown keys are errors. A live
// stimulus's parameters are checked as stimulus sets read them
// (renderer/core/knob_toml.h) and kept as written, at full precision.
Protocol parse_protocol(std::string_view text, const std::string& source,
                        const std::string& base_dir = "",
                        KnobCheck check = KnobCheck::strict);
Protocol load_protocol_file(const std::string& path);
// Built-in protocols by name ("thesis"); throws ProtocolError listing valid names.
Protocol builtin_protocol(std::string_view name);
std::vector<std::string> builtin_protocol_names();

// Hex SHA-256 of the protocol text: studies with different hashes are never merged.
std::string protocol_hash(std::string_view text);

}  // namespace lucent::study
