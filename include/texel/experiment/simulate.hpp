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
//   p=0.85          working memory: P(correct) for every condition; digit=0.8
//   rating-noise=0.5, speed=100 (mm/s swipe speed), seed=7
//   spread=0.25     between-participant variability (participant_sd): each
//                   participant's threshold, matcher target and memory
//                   accuracy deviate from the group by a draw from the seed
//
// Trade-off: the observers are stand-ins with textbook shapes (observer.hpp),
// good for testing procedures and planning sample sizes, not a model of a
// particular person.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "texel/experiment/session.hpp"

namespace texel::experiment {

/// Validates an "observer" object (its sections, keys, types and ranges);
/// throws FormatError naming the field ("observer.psychometric.slope …").
void validate_observer(const nlohmann::json& observer);

/// The observer description a SPEC produces over the protocol's observer
/// (throws InvalidArgument naming the key, the value and what is allowed).
nlohmann::json simulation_observer(const nlohmann::json& protocol_observer, const std::string& spec);

class SimulatedParticipant {
 public:
  /// `observer` as returned by simulation_observer(). Validates it.
  SimulatedParticipant(nlohmann::json observer, const Session& session);
  /// The answer to the session's current question, with a simulated finger
  /// trace's swipe measures, exploration events and reaction time.
  [[nodiscard]] Response respond(const Session& session) const;
  [[nodiscard]] const nlohmann::json& observer() const { return observer_; }

 private:
  nlohmann::json observer_;
  std::uint64_t seed_ = 1;
  double threshold_scale_ = 1.0;  // this participant's deviations from the group
  double bias_pitch_db_ = 0.0, bias_irregularity_db_ = 0.0;
  double memory_shift_ = 0.0;
};

}  // namespace texel::experiment
