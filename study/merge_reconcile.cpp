// Reconciling copies of one session in a merge (merge_reconcile.h).
#include "study/merge_reconcile.h"

#include <algorithm>
#include <tuple>

#include "common/number_text.h"
#include "study/sqlite/sqlite_store.h"

namespace lucent::study {
namespace {

// How far a session got with the same answers: each resume adds a segment; within a
// segment running -> paused -> aborted or completed.
std::tuple<int, int> progress(const SessionCopy& c) {
    const int rank = c.status == "running" ? 0 : c.status == "paused" ? 1 : 2;
    return {c.segments, rank};
}

std::string rating_text(const std::map<std::string, int64_t>& answers,
                        const std::string& q) {
    const auto it = answers.find(q);
    return it == answers.end() ? "(none)" : std::to_string(it->second);
}

std::string number_text(const std::optional<double>& v) {
    return v ? common::shortest_text(*v) : std::string("(none)");
}

std::string adjustment_text(const std::vector<SessionCopy::Adjusted>& adjustments,
                            size_t k) {
    if (k >= adjustments.size()) return "(none)";
    const SessionCopy::Adjusted& a = adjustments[k];
    return common::shortest_text(a.value) + " (" + a.input + " at " +
           std::to_string(a.t_ns) + " ns)";
}

// The first difference between what two copies hold of one trial besides its ratings
// ("final_value 1.5 in A but 1.25 in B"), or "".
std::string outcome_difference(const SessionCopy::Outcome& x, const std::string& an,
                               const SessionCopy::Outcome& y, const std::string& bn) {
    auto differs = [&](const std::string& what, const std::string& a,
                       const std::string& b) {
        return what + " " + a + " in " + an + " but " + b + " in " + bn;
    };
    if (x.skipped != y.skipped)
        return x.skipped ? "skipped in " + an + " but answered in " + bn
                         : "answered in " + an + " but skipped in " + bn;
    if (x.final_value != y.final_value)
        return differs("final_value", number_text(x.final_value),
                       number_text(y.final_value));
    if (x.intensity != y.intensity)
        return differs("intensity", number_text(x.intensity), number_text(y.intensity));
    const size_t n = std::max(x.adjustments.size(), y.adjustments.size());
    for (size_t k = 0; k < n; ++k)
        if (k >= x.adjustments.size() || k >= y.adjustments.size() ||
            !(x.adjustments[k] == y.adjustments[k]))
            return differs("adjustment " + std::to_string(k + 1),
                           adjustment_text(x.adjustments, k),
                           adjustment_text(y.adjustments, k));
    return "";
}

// Whether `c` holds the trial at `position`: answered, or skipped.
bool holds(const SessionCopy& c, int64_t position) {
    if (c.answers.count(position)) return true;
    const auto it = c.outcomes.find(position);
    return it != c.outcomes.end() && it->second.skipped;
}

// The positions `c` holds, in order.
std::set<int64_t> held_positions(const SessionCopy& c) {
    std::set<int64_t> out;
    for (const auto& [position, ratings] : c.answers) out.insert(position);
    for (const auto& [position, outcome] : c.outcomes)
        if (outcome.skipped) out.insert(position);
    return out;
}

// > 0 when `a` extends `b`, < 0 when `b` extends `a`, 0 when they are equal; throws
// when they disagree or neither extends the other.
int compare(const std::string& uuid, const SessionCopy& a, const SessionCopy& b,
            const std::vector<std::string>& names) {
    const std::string& an = names[a.input];
    const std::string& bn = names[b.input];
    const std::string who = "refusing to merge: session " + uuid + " (" + a.code + ")";
    if (a.code != b.code || a.machine_id != b.machine_id)
        throw StoreError(who + ": participant " + a.code + " on machine '" +
                         a.machine_id + "' in " + an + " but " + b.code +
                         " on machine '" + b.machine_id + "' in " + bn +
                         " (one session UUID, two people?)");
    if (a.seed != b.seed || a.cell != b.cell || a.block_order != b.block_order ||
        a.plan.size() != b.plan.size())
        throw StoreError(who + ": " + an + " and " + bn +
                         " hold different trial plans (seed " + a.seed + ", " +
                         std::to_string(a.plan.size()) + " trials vs seed " + b.seed +
                         ", " + std::to_string(b.plan.size()) + " trials)");
    for (const auto& [position, planned] : a.plan) {
        const auto other = b.plan.find(position);
        SessionCopy::Planned x = planned;
        if (other != b.plan.end() && (x.uuid.empty() || other->second.uuid.empty()))
            x.uuid = other->second.uuid;  // a trial planned before schema 4 has none
        if (other == b.plan.end() || !(x == other->second))
            throw StoreError(
                who + " trial " + std::to_string(position) + ": " + an + " and " + bn +
                " hold different trial plans (stimulus '" + planned.stimulus + "' vs '" +
                (other == b.plan.end() ? std::string("(none)") : other->second.stimulus) +
                "')");
    }
    int64_t only_a = -1, only_b = -1;
    static const std::map<std::string, int64_t> kNone;
    static const SessionCopy::Outcome kNothing;
    for (const int64_t position : held_positions(a)) {
        if (!holds(b, position)) {
            if (only_a < 0) only_a = position;
            continue;
        }
        const auto ra = a.answers.find(position), rb = b.answers.find(position);
        const auto& ratings = ra == a.answers.end() ? kNone : ra->second;
        const auto& other = rb == b.answers.end() ? kNone : rb->second;
        std::set<std::string> questions;
        for (const auto& [q, r] : ratings) questions.insert(q);
        for (const auto& [q, r] : other) questions.insert(q);
        const auto oa = a.outcomes.find(position), ob = b.outcomes.find(position);
        const std::string outcome =
            outcome_difference(oa == a.outcomes.end() ? kNothing : oa->second, an,
                               ob == b.outcomes.end() ? kNothing : ob->second, bn);
        if (!outcome.empty())
            throw StoreError(who + " trial " + std::to_string(position) + ": " + outcome);
        for (const std::string& q : questions)
            if (rating_text(ratings, q) != rating_text(other, q))
                throw StoreError(who + " trial " + std::to_string(position) +
                                 ": rating '" + q + "'=" + rating_text(ratings, q) +
                                 " in " + an + " but " + rating_text(other, q) + " in " +
                                 bn);
    }
    for (const int64_t position : held_positions(b))
        if (!holds(a, position)) {
            only_b = position;
            break;
        }
    if (only_a >= 0 && only_b >= 0)
        throw StoreError(who + ": trial " + std::to_string(only_a) +
                         " is answered only in " + an + " and trial " +
                         std::to_string(only_b) + " only in " + bn +
                         "; neither copy extends the other");
    if (only_a >= 0) return 1;
    if (only_b >= 0) return -1;
    const auto pa = progress(a), pb = progress(b);
    return pa > pb ? 1 : pa < pb ? -1 : 0;
}

}  // namespace

std::map<std::string, SessionCopy> read_session_copies(Database& db, int input) {
    std::map<std::string, SessionCopy> out;
    Statement s = db.prepare(
        "SELECT se.uuid, p.code, se.machine_id, se.started_utc, se.status, se.seed, "
        "se.cell, "
        "se.block_order, (SELECT count(*) FROM session_segments g WHERE g.session_id = "
        "se.id) "
        "FROM sessions se JOIN participants p ON p.id = se.participant_id ORDER BY "
        "se.id");
    while (s.step()) {
        SessionCopy& c = out[s.text(0)];
        c.input = input;
        c.code = s.text(1);
        c.machine_id = s.text(2);
        c.started_utc = s.text(3);
        c.status = s.text(4);
        c.seed = s.text(5);
        c.cell = s.integer(6);
        c.block_order = s.text(7);
        c.segments = static_cast<int>(s.integer(8));
    }
    return out;
}

void read_session_details(Database& db, std::map<std::string, SessionCopy*>& wanted) {
    if (wanted.empty()) return;
    Statement t = db.prepare(
        "SELECT se.uuid, t.position, coalesce(t.uuid, ''), st.stimulus_key, t.block, "
        "t.practice, t.catch FROM trials t JOIN sessions se ON se.id = t.session_id "
        "JOIN stimuli st ON st.id = t.stimulus_id");
    while (t.step()) {
        const auto it = wanted.find(t.text(0));
        if (it == wanted.end()) continue;
        it->second->plan[t.integer(1)] = {t.text(2), t.text(3), t.text(4), t.integer(5),
                                          t.integer(6)};
    }
    Statement r = db.prepare(
        "SELECT se.uuid, t.position, r.question, r.rating FROM responses r "
        "JOIN trials t ON t.id = r.trial_id JOIN sessions se ON se.id = t.session_id");
    while (r.step()) {
        const auto it = wanted.find(r.text(0));
        if (it == wanted.end()) continue;
        it->second->answers[r.integer(1)][r.text(2)] = r.integer(3);
    }
    // Schema 7 (inputs are read at the current schema): final values, intensities,
    // skipped slots and adjustments.
    Statement o = db.prepare(
        "SELECT se.uuid, t.position, t.final_value, t.intensity, t.skipped FROM trials t "
        "JOIN sessions se ON se.id = t.session_id WHERE t.final_value IS NOT NULL OR "
        "t.intensity IS NOT NULL OR t.skipped <> 0");
    while (o.step()) {
        const auto it = wanted.find(o.text(0));
        if (it == wanted.end()) continue;
        SessionCopy::Outcome& outcome = it->second->outcomes[o.integer(1)];
        outcome.final_value = o.optional_real(2);
        outcome.intensity = o.optional_real(3);
        outcome.skipped = o.integer(4) != 0;
    }
    Statement a = db.prepare(
        "SELECT se.uuid, t.position, a.value, a.t_ns, a.input FROM adjustments a "
        "JOIN trials t ON t.id = a.trial_id JOIN sessions se ON se.id = t.session_id "
        "ORDER BY a.trial_id, a.step");
    while (a.step()) {
        const auto it = wanted.find(a.text(0));
        if (it == wanted.end()) continue;
        it->second->outcomes[a.integer(1)].adjustments.push_back(
            {a.real(2), a.integer(3), a.text(4)});
    }
}

Reconciled reconcile_copies(const std::string& uuid,
                            const std::vector<SessionCopy>& copies,
                            const std::vector<std::string>& names) {
    Reconciled out;
    // The copies only grow along the way, so a copy extending every other is reached
    // whatever the order; then every copy must be within it.
    for (size_t i = 1; i < copies.size(); ++i) {
        try {
            if (compare(uuid, copies[i], copies[out.kept], names) > 0) out.kept = i;
        } catch (const StoreError&) {
            // Neither extends the other: a later copy may still extend both (checked
            // below); a disagreement on a rating throws again there.
        }
    }
    for (size_t i = 0; i < copies.size(); ++i) {
        if (i == out.kept) continue;
        const int c = compare(uuid, copies[out.kept], copies[i], names);
        if (c < 0)
            throw StoreError("refusing to merge: session " + uuid + " (" +
                             copies[i].code + "): no copy extends every other (" +
                             names[copies[i].input] + " got further than " +
                             names[copies[out.kept].input] + ")");
        (c == 0 ? out.identical : out.extended)++;
    }
    return out;
}

}  // namespace lucent::study
