// Shared helpers of the session-store tests: a fully populated trial, raw
// SQLite access, file bytes.
#pragma once

#include <sqlite3.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "texel/experiment/store.hpp"

namespace texel::test_support {

/// A trial with every TrialRow field set to a distinct, awkward value.
inline experiment::StoredTrial full_trial(int i) {
  experiment::StoredTrial t;
  t.trial = i;
  t.question_json = R"({"question":{"stimuli":[{"document":"texel 1\n","seed":)" + std::to_string(1000 + i) + "}]}}";
  t.response_json = R"({"choice":")" + std::to_string(i % 3) + R"(","note":"a, \"quoted\" one"})";
  t.state_json = R"({"intensity":)" + std::to_string(0.5 + i) + "}";
  auto& r = t.row;
  r.participant = "S01";
  r.session_id = 1;
  r.protocol = "texel-length";
  r.study = "texel-length";
  r.block = "narrow, \"fine\"";
  r.block_index = 2;
  r.trial = i;
  r.trial_in_block = i + 3;
  r.practice = (i % 2) == 1;
  r.task = "oddity";
  r.condition = "wide-distractor";
  r.reference = "line\nbreak";
  r.variable = "texel_length_mm";
  r.intensity = 0.1 + i;
  r.reversal = true;
  r.next_intensity = 1.0 / 3.0;
  r.procedure_finished = (i % 2) == 0;
  r.response = "2";
  r.correct_answer = "3";
  r.correct = 0;
  r.rating = 4.5;
  r.confidence = 3;
  r.rt_ms = 1234.5678;
  r.slider_p = -0.25;
  r.slider_i = 1e-300;
  r.pitch_db = 12.345678901234567;
  r.irregularity_db = -3;
  r.pitch_a_db = 1;
  r.irregularity_a_db = 2;
  r.pitch_b_db = 3;
  r.irregularity_b_db = 4;
  r.iteration = 7;
  r.reference_pitch_db = 5.5;
  r.reference_irregularity_db = 6.5;
  r.texel_length_mm = 0.25;
  r.coarse_strength = 0.7;
  r.fine_strength = 0.3;
  r.quantization_db = 6;
  r.digit_cell = 15;
  r.digit_response = 9;
  r.digit_correct = 1;
  r.nback_targets = 3;
  r.nback_hits = 2;
  r.nback_false_alarms = i;
  r.swipe_mean_speed_mm_s = 101.5;
  r.swipe_sd_speed_mm_s = 20.25;
  r.directional_proportion = 0.875;
  r.presentation_mode = "display-plays";
  r.finger_source = "display";
  r.swipe_flag = i == 1 ? "implausible_speed" : "";
  r.shown_at = "2026-11-23T10:00:00.000Z";
  r.answered_at = "2026-11-23T10:00:01.234Z";
  t.events = {{0.0, "show", "stimulus 1", "2026-11-23T10:00:00.000Z"},
              {0.5, "select", "stimulus 2, \"B\"", "2026-11-23T10:00:00.500Z"},
              {1.2345, "answer", "", ""}};
  // Odd trials have no finger trace; even ones one from a display (µs and nm resolution).
  if (i % 2 == 0) {
    t.trace.source = experiment::TraceSource::display;
    t.trace.mode = experiment::PresentationMode::display_plays;
    t.trace.samples = {{0.0, 10.0, true}, {0.001, 10.1, true}, {4294.967296, -0.000001, false}, {4294.968, 12.345678, true}};
  }
  return t;
}

/// Field-by-field equality with NaN == NaN (EXPECT_EQ on each).
#define TEXEL_EXPECT_ROW_EQ(a, b)                                                                     \
  do {                                                                                                \
    const auto& ra_ = (a);                                                                            \
    const auto& rb_ = (b);                                                                            \
    const auto same_ = [](double x, double y) { return (std::isnan(x) && std::isnan(y)) || x == y; }; \
    EXPECT_EQ(ra_.participant, rb_.participant);                                                      \
    EXPECT_EQ(ra_.session_id, rb_.session_id);                                                        \
    EXPECT_EQ(ra_.protocol, rb_.protocol);                                                            \
    EXPECT_EQ(ra_.study, rb_.study);                                                                  \
    EXPECT_EQ(ra_.block, rb_.block);                                                                  \
    EXPECT_EQ(ra_.block_index, rb_.block_index);                                                      \
    EXPECT_EQ(ra_.trial, rb_.trial);                                                                  \
    EXPECT_EQ(ra_.trial_in_block, rb_.trial_in_block);                                                \
    EXPECT_EQ(ra_.practice, rb_.practice);                                                            \
    EXPECT_EQ(ra_.task, rb_.task);                                                                    \
    EXPECT_EQ(ra_.condition, rb_.condition);                                                          \
    EXPECT_EQ(ra_.reference, rb_.reference);                                                          \
    EXPECT_EQ(ra_.variable, rb_.variable);                                                            \
    EXPECT_PRED2(same_, ra_.intensity, rb_.intensity);                                                \
    EXPECT_EQ(ra_.reversal, rb_.reversal);                                                            \
    EXPECT_PRED2(same_, ra_.next_intensity, rb_.next_intensity);                                      \
    EXPECT_EQ(ra_.procedure_finished, rb_.procedure_finished);                                        \
    EXPECT_EQ(ra_.response, rb_.response);                                                            \
    EXPECT_EQ(ra_.correct_answer, rb_.correct_answer);                                                \
    EXPECT_PRED2(same_, ra_.correct, rb_.correct);                                                    \
    EXPECT_PRED2(same_, ra_.rating, rb_.rating);                                                      \
    EXPECT_PRED2(same_, ra_.confidence, rb_.confidence);                                              \
    EXPECT_PRED2(same_, ra_.rt_ms, rb_.rt_ms);                                                        \
    EXPECT_PRED2(same_, ra_.slider_p, rb_.slider_p);                                                  \
    EXPECT_PRED2(same_, ra_.slider_i, rb_.slider_i);                                                  \
    EXPECT_PRED2(same_, ra_.pitch_db, rb_.pitch_db);                                                  \
    EXPECT_PRED2(same_, ra_.irregularity_db, rb_.irregularity_db);                                    \
    EXPECT_PRED2(same_, ra_.pitch_a_db, rb_.pitch_a_db);                                              \
    EXPECT_PRED2(same_, ra_.irregularity_a_db, rb_.irregularity_a_db);                                \
    EXPECT_PRED2(same_, ra_.pitch_b_db, rb_.pitch_b_db);                                              \
    EXPECT_PRED2(same_, ra_.irregularity_b_db, rb_.irregularity_b_db);                                \
    EXPECT_EQ(ra_.iteration, rb_.iteration);                                                          \
    EXPECT_PRED2(same_, ra_.reference_pitch_db, rb_.reference_pitch_db);                              \
    EXPECT_PRED2(same_, ra_.reference_irregularity_db, rb_.reference_irregularity_db);                \
    EXPECT_PRED2(same_, ra_.texel_length_mm, rb_.texel_length_mm);                                    \
    EXPECT_PRED2(same_, ra_.coarse_strength, rb_.coarse_strength);                                    \
    EXPECT_PRED2(same_, ra_.fine_strength, rb_.fine_strength);                                        \
    EXPECT_PRED2(same_, ra_.quantization_db, rb_.quantization_db);                                    \
    EXPECT_PRED2(same_, ra_.digit_cell, rb_.digit_cell);                                              \
    EXPECT_PRED2(same_, ra_.digit_response, rb_.digit_response);                                      \
    EXPECT_PRED2(same_, ra_.digit_correct, rb_.digit_correct);                                        \
    EXPECT_PRED2(same_, ra_.nback_targets, rb_.nback_targets);                                        \
    EXPECT_PRED2(same_, ra_.nback_hits, rb_.nback_hits);                                              \
    EXPECT_PRED2(same_, ra_.nback_false_alarms, rb_.nback_false_alarms);                              \
    EXPECT_PRED2(same_, ra_.swipe_mean_speed_mm_s, rb_.swipe_mean_speed_mm_s);                        \
    EXPECT_PRED2(same_, ra_.swipe_sd_speed_mm_s, rb_.swipe_sd_speed_mm_s);                            \
    EXPECT_PRED2(same_, ra_.directional_proportion, rb_.directional_proportion);                      \
    EXPECT_EQ(ra_.presentation_mode, rb_.presentation_mode);                                          \
    EXPECT_EQ(ra_.finger_source, rb_.finger_source);                                                  \
    EXPECT_EQ(ra_.swipe_flag, rb_.swipe_flag);                                                        \
    EXPECT_EQ(ra_.shown_at, rb_.shown_at);                                                            \
    EXPECT_EQ(ra_.answered_at, rb_.answered_at);                                                      \
  } while (0)

inline std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// A raw SQLite connection for building layouts by hand.
struct RawDb {
  sqlite3* db = nullptr;
  explicit RawDb(const std::string& path) {
    if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("raw open failed");
  }
  ~RawDb() { sqlite3_close(db); }
  RawDb(const RawDb&) = delete;
  RawDb& operator=(const RawDb&) = delete;
  void exec(const std::string& sql) const {
    char* err = nullptr;
    if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string why = err ? err : "?";
      sqlite3_free(err);
      throw std::runtime_error("raw sql failed: " + why + " in: " + sql);
    }
  }
  /// First column of the first row as text ("" if none).
  [[nodiscard]] std::string one(const std::string& sql) const {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr) != SQLITE_OK)
      throw std::runtime_error("raw prepare failed: " + sql);
    std::string out;
    if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0))
      out = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    return out;
  }
};

}  // namespace texel::test_support
