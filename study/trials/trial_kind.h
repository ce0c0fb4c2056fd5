#pragma once
// What one block's trials ask, as one family listed once (trials/registry.cpp), in the
// way techniques are one folder and one registry line: a kind's folder holds how its
// block is read from a protocol and how its trials are planned; the rest of the study
// asks the kind instead of naming it. A test may register a kind of its own
// (TrialKindRegistration). README.md in this folder says what is still dispatched by
// name, and why.
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace lucent::common {
struct Observation;
}

namespace lucent::study {

struct Block;
struct PlannedTrial;
struct Protocol;
struct Question;
class TableReader;
class TrialKind;
struct TrialAnswerFacts;
struct TrialOutcome;

// A trial's own stored columns beside its responses (schema 7), as an observation reads
// them.
struct StoredTrialMeasures {
    std::optional<double> start_value, final_value, intensity;
    std::int64_t adjustments = 0;  // rows in `adjustments`
    std::string staircase;         // trials.staircase ("" when NULL)
};

// A handle on one registered kind: a small value, cheap to copy and compare, that names
// one entry of the registry (the idea of pbrt's TaggedPointer: a closed family listed
// once). The built-in kinds have constants, in the registry's order; a kind registered
// later gets the next index.
class Task {
public:
    static const Task rating, pair, triad, quadruple, adjust, staircase;
    constexpr Task() = default;  // rating
    constexpr explicit Task(std::uint8_t index) : index_(index) {}
    const TrialKind& kind() const;
    const TrialKind* operator->() const { return &kind(); }
    constexpr std::uint8_t index() const { return index_; }
    friend constexpr bool operator==(Task a, Task b) { return a.index_ == b.index_; }
    friend constexpr bool operator<(Task a, Task b) { return a.index_ < b.index_; }

private:
    std::uint8_t index_ = 0;
};
inline constexpr Task Task::rating{0};
inline constexpr Task Task::pair{1};
inline constexpr Task Task::triad{2};
inline constexpr Task Task::quadruple{3};
inline constexpr Task Task::adjust{4};
inline constexpr Task Task::staircase{5};

// How a trial is answered on screen. The lab (session/) and the page (serve/) each draw
// every screen once; a kind picks the one its trials use, so a kind that asks a question
// of its own on a scale, or a choice among its pictures, needs no screen of its own.
enum class TrialScreen {
    scales,     // one picture and rating scales (TrialKind::questions): a digit each
    choice,     // its pictures, side by side or in sequence; one of answers() chosen
    adjust,     // a target beside a live match whose knob the participant turns
    staircase,  // a choice whose comparison is rendered at the procedure's delta
};
// "scales", "choice", "adjust" or "staircase": the page's name for the screen.
const char* screen_name(TrialScreen screen);

class TrialKind {
public:
    virtual ~TrialKind() = default;
    // The name a protocol's `task` and the database's trials.kind hold.
    virtual const char* name() const = 0;
    // Answered by choosing among its pictures (responses.rating holds 1..answers()).
    virtual bool is_choice() const = 0;
    // A forced choice the scaling reads (paired comparisons, MLDS).
    virtual bool is_scaling() const = 0;
    // Rated on the protocol's [[questions]] (the kind that catch trials and practice
    // stimuli belong to); every other kind asks its block's own question.
    virtual bool rated_on_questions() const { return false; }
    // The pictures of one trial: the kind's usual count, and a block's (a block's keys
    // may change it, as an odd-one-out staircase's 3).
    virtual int pictures_per_trial() const = 0;
    virtual int pictures(const Block&) const { return pictures_per_trial(); }
    // The answers of one trial: 0 (the [[questions]]), 1 (a confirmation), 2 or more.
    virtual int answers(const Block& block) const = 0;
    // The screen its trials are answered on.
    virtual TrialScreen screen() const = 0;
    // What each answer of a `choice` or `staircase` screen names, in answer order: the
    // indices of its pictures (into the trial's shown pictures, left to right). By
    // default each picture is its own answer; a triad's two pairs share their middle
    // picture ({0, 1}, {1, 2}), a quadruple's pairs are {0, 1} and {2, 3}. In sequence
    // the first answer's pictures are shown, then the second's. Both screens lay these
    // out the same way (session/layout.h, serve/web/lucent.js), so a new kind chooses
    // among its pictures with no screen code.
    virtual std::vector<std::vector<int>> answer_groups(const Block& block) const;
    // The scales of a `scales` trial, each answered 1..points (`block`: null for a
    // practice rating): a rating's are the protocol's [[questions]]; a kind asking its
    // block's own question gives that, its labels the points. None for other screens.
    virtual std::vector<Question> questions(const Protocol& protocol,
                                            const Block* block) const;

    // The block's own keys, read after its id, stimuli and repeats; the reader refuses
    // any key nobody asked for once the block is read.
    virtual void read_block(const Protocol& protocol, TableReader& keys,
                            Block& block) const = 0;
    // The block's trials in its design's order, drawn from the block's own stream.
    virtual std::vector<PlannedTrial> plan_block(const Protocol& protocol,
                                                 const Block& block,
                                                 std::mt19937_64& rng) const = 0;
    // False: the protocol's shuffle keeps the planned order (a staircase's rounds).
    virtual bool shuffled() const { return true; }
    // A trial's level for the shuffle's constraints (max_repeat, min_distance): by
    // default the level of its stimulus under the randomisation's factor.
    virtual std::string sequence_level(
        const PlannedTrial& trial,
        const std::map<std::string, std::string>& level_of_stimulus) const;

    // What an answer of this kind carries beside its responses (a final value and
    // adjustments, an intensity), checked before any store writes it; throws
    // StoreError naming `where`. By default it carries none of them
    // (refuse_outcome_columns in store_rules.h).
    virtual void check_outcome(const std::string& where, const TrialAnswerFacts& facts,
                               const TrialOutcome& outcome) const;
    // What the analysis reads its observations as (Observation::analysed_as):
    // "ratings", "choices", "matches", "thresholds", or "" (exported, not analysed).
    virtual const char* analysed_as() const = 0;
    // The observation's part that only this kind's trials have, from their stored
    // columns (an adjustment's final value as its response; a staircase's procedure).
    virtual void observe(const StoredTrialMeasures&, common::Observation&) const {}
};

// Every registered kind, built-ins first in the order of the Task constants.
std::vector<Task> all_tasks();
// Registers a kind (a test's own): its Task is the next index. Kept for the program's
// life; a second kind of the same name is refused (std::logic_error).
class TrialKindRegistration {
public:
    explicit TrialKindRegistration(const TrialKind& kind);
    Task task() const { return task_; }

private:
    Task task_;
};

}  // namespace lucent::study
