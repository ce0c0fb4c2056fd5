#pragma once
// Each question's scale length (2 to 7 points, per question), from a protocol or from
// the protocol text a study database stores, so that the store and the analysis refuse a
// rating outside 1..points of *its* question (the schema's CHECK only knows 1..7).
#include <cstdint>
#include <map>
#include <string>
#include <utility>

#include "study/protocol.h"
#include "study/sqlite/database.h"

namespace lucent::study {

using QuestionPoints = std::map<std::string, int>;  // question id -> points

// Every question a study asks: its [[questions]] and each other block's own question
// (Block::answers() points: a forced choice's alternatives, an odd-one-out staircase's
// three places, an adjustment's one "confirmed").
QuestionPoints question_points(const Protocol& protocol);

// Which questions one trial answers: a rating every [[questions]] entry, any other
// trial its block's own question.
struct StudyQuestions {
    QuestionPoints rating;
    // Block id -> (its question id, its points), for every block but rating blocks.
    std::map<std::string, std::pair<std::string, int>> block_question;
    QuestionPoints of_block(const std::string& block) const;
};
StudyQuestions study_questions(const Protocol& protocol);

// The scales of study `study_id`, parsed from its stored protocol text. Throws
// StoreError (one line, naming the database) when that text no longer parses.
QuestionPoints stored_question_points(Database& db, int64_t study_id);
StudyQuestions stored_study_questions(Database& db, int64_t study_id);
// Throws StoreError naming the question when `rating` is not within its scale.
void check_rating_on_scale(const QuestionPoints& points, const std::string& question,
                           int rating, const std::string& where);
// Checks every stored rating against its question's scale; throws StoreError naming the
// first impossible one (participant, session, trial position, question, rating, scale).
// Returns the scale of each rated question (the longest, where studies differ).
QuestionPoints check_stored_ratings(Database& db);
// The same for the database file at `path`, opened read-only (check_database_file
// first); a database without ratings passes (and returns no scale).
QuestionPoints check_stored_ratings(const std::string& path);

}  // namespace lucent::study
