// Simulated participants: answer any Session question from a seeded
// observer model, so every shipped protocol runs end to end without people
// (tests, demos, planning). A simulated answer depends only on (observer
// seed, trial index) and the trial's stimuli, so a resumed simulated session
// answers exactly as an uninterrupted one.
//
// The observer comes from the protocol's "observer" object, overridden by a
// SPEC string of comma-separated key=value pairs (`texel experiment run
// --simulate SPEC`); "default" uses the protocol's observer as it is.
//
//   threshold=6mm   psychometric threshold (the block variable's unit; mm, dB, % accepted)
//   slope=3.5       psychometric slope; shape=weibull|logistic; guess=; lapse=
//   target=4sin     matcher target: a reference (through the encoder's perceptual
//                   model), or target=8dB/-3dB (Central Pitch/Irregularity);
//                   default: each trial's own reference
//   noise=1.5dB     matcher noise; unsure=0.5dB (unsure band)
//   p=0.85          working memory: P(correct) for every condition; digit=0.8;
//                   hit=0.85, false-alarm=0.05 (2-back: P(respond) to a target, a non-target)
//   rating-noise=0.5, speed=100 (mm/s swipe speed), seed=7
//   integration=1   distributed irregularity: how much touch pools simultaneous
//                   texels' frequencies (0 … 1; "playback" section, with
//                   threshold_db and slope of the felt difference)
//   spread=0.25     between-participant variability (participant_sd): each
//                   participant's threshold, matcher target and memory
//                   accuracy deviate from the group by a draw from the seed
//
// Trade-off: the observers are stand-ins with textbook shapes (observer.hpp),
// good for testing procedures and planning sample sizes, not a model of a
// particular person.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "texel/experiment/observer.hpp"
#include "texel/experiment/session.hpp"
#include "texel/random.hpp"

namespace texel::experiment {

/// Validates an "observer" object (JSON object text: its sections, keys,
/// types and ranges); throws FormatError naming the field
/// ("observer.psychometric.slope …").
void validate_observer(std::string_view observer_json);

/// The observer description (JSON object text) a SPEC produces over the
/// protocol's observer (throws InvalidArgument naming the key, the value and
/// what is allowed).
std::string simulation_observer(std::string_view protocol_observer_json, const std::string& spec);

class SimulatedParticipant {
 public:
  /// `observer` as returned by simulation_observer(). Validates it.
  SimulatedParticipant(std::string observer, const Session& session);
  /// The answer to the session's current question (its task kind answers,
  /// see TaskType::simulate), with a simulated finger trace's swipe
  /// measures, exploration events and reaction time.
  [[nodiscard]] Response respond(const Session& session) const;
  [[nodiscard]] const std::string& observer() const { return observer_; }

  // The observer's parts, for the task kinds' simulated answers.
  /// The behaviour stream (seeded by the observer seed).
  [[nodiscard]] const CounterRng& behaviour() const { return rng_; }
  /// The psychometric observer's answer to a threshold trial (true = correct);
  /// `default_guess` is the task's chance rate.
  [[nodiscard]] bool psychometric_correct(const TrialTruth& t, double default_guess, std::uint64_t trial) const;
  /// The matcher, aiming at the observer's target or else `fallback`
  /// (each trial's own reference), shifted by this participant's bias.
  [[nodiscard]] Matcher matcher(const MatchResult& fallback, const Session& session) const;
  /// The similarity rater on a scale.
  [[nodiscard]] Rater rater(double scale_min, double scale_max) const;
  /// Working memory: P(correct) in a condition (this participant's shift applied).
  [[nodiscard]] double memory_p_correct(const std::string& condition) const;
  /// Working memory: P(digit recalled).
  [[nodiscard]] double memory_p_digit() const;
  /// Working memory's executive distractor: P(respond) to a target, and to a non-target.
  [[nodiscard]] double memory_p_hit() const;
  [[nodiscard]] double memory_p_false_alarm() const;
  /// Distributed irregularity (the observer's "playback" section): the
  /// shift (dB) of a simultaneous texture's felt Irregularity on `channels`
  /// actuators, 5·log10((1 − w) + w/K) for pooling w = `integration` (the
  /// spread of K log-frequencies averaged with weight w: 1 pools fully,
  /// −3 dB on four actuators; 0 feels each texel apart, no shift).
  [[nodiscard]] double playback_shift_db(std::size_t channels) const;
  /// Whether the odd one of a playback oddity is found when the felt
  /// Irregularities differ by `felt_difference_db`: a Weibull with the
  /// section's threshold_db (scaled by this participant's threshold) and
  /// slope, chance 1/3, the psychometric section's lapse.
  [[nodiscard]] bool playback_correct(double felt_difference_db, std::uint64_t trial) const;
  /// A wrong choice (never "unsure"), drawn from the behaviour stream.
  [[nodiscard]] std::string wrong_choice(const Question& q, const std::string& correct) const;

 private:
  struct Model;
  std::shared_ptr<const Model> model_;  // the parsed observer
  std::string observer_;
  std::uint64_t seed_ = 1;
  CounterRng rng_{1, 0};
  double threshold_scale_ = 1.0;  // this participant's deviations from the group
  double bias_pitch_db_ = 0.0, bias_irregularity_db_ = 0.0;
  double memory_shift_ = 0.0;
};

}  // namespace texel::experiment
