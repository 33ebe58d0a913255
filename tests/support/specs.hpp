// Texture specs the tests build over and over.
#pragma once

#include <cstdint>

#include <string>

#include "texel/reference.hpp"
#include "texel/texture.hpp"

namespace texel::test_support {

/// A fine-only TexelSpec: Central Pitch and Irregularity in dB, texel length
/// in mm, seed; every other field at its default.
inline TexelSpec fine_spec(double pitch_db, double irregularity_db, double length_mm, std::uint64_t seed) {
  TexelSpec s;
  s.central_pitch = Decibels(pitch_db);
  s.irregularity = Decibels(irregularity_db);
  s.texel_length = Millimetres(length_mm);
  s.seed = seed;
  return s;
}

/// A ReferenceSpec of the named generator with its default parameters.
inline ReferenceSpec reference_spec(const std::string& name, std::uint64_t seed = 1) {
  ReferenceSpec s;
  s.name = name;
  s.seed = seed;
  return s;
}

}  // namespace texel::test_support
