// The one WAV writer of the tests: a little-endian PCM16 file built by hand,
// so a test can declare any channel count and any data size (including a
// wrong one) without an audio library.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace texel::test_support {

/// A PCM16 WAV of interleaved frames. `declared_data_bytes` (0 = the true
/// size) lets a test write a header that lies about the data chunk.
inline std::string wav_bytes(unsigned channels, unsigned rate, const std::vector<std::int16_t>& interleaved,
                             std::uint32_t declared_data_bytes = 0) {
  std::string out;
  auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  auto u16 = [&](std::uint16_t v) {
    out.push_back(static_cast<char>(v & 0xFF));
    out.push_back(static_cast<char>(v >> 8));
  };
  const auto data = static_cast<std::uint32_t>(interleaved.size() * 2);
  out += "RIFF";
  u32(36 + data);
  out += "WAVEfmt ";
  u32(16);
  u16(1);
  u16(static_cast<std::uint16_t>(channels));
  u32(rate);
  u32(rate * channels * 2);
  u16(static_cast<std::uint16_t>(channels * 2));
  u16(16);
  out += "data";
  u32(declared_data_bytes ? declared_data_bytes : data);
  for (std::int16_t s : interleaved) u16(static_cast<std::uint16_t>(s));
  return out;
}

}  // namespace texel::test_support
