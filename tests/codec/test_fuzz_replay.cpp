// Replays the fuzz target over a deterministic corpus under any compiler:
// random byte strings of every length up to 64, and valid bitstreams (fine
// only and with coarse profiles) mutated by bit flips, byte substitutions,
// truncations, insertions and appended bytes. Every input must parse
// canonically or be rejected with FormatError (the target aborts otherwise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "texel/bitstream.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using namespace texel;
using namespace texel::codec;

// The fuzz target's input is octets; the library's byte buffers are std::byte.
std::vector<std::uint8_t> octets(const std::vector<std::byte>& bytes) {
  std::vector<std::uint8_t> out(bytes.size());
  std::transform(bytes.begin(), bytes.end(), out.begin(), [](std::byte b) { return std::to_integer<std::uint8_t>(b); });
  return out;
}

std::vector<std::vector<std::uint8_t>> seeds() {
  std::vector<std::vector<std::uint8_t>> out;
  Bitstream b;
  out.push_back(octets(write_bitstream(b)));
  b.fine.seed = 0xFFFFFFFFFFFFFFFFULL;
  b.fine.band_min_cdb = -1500;
  b.fine.phase = PhaseMode::reset;
  out.push_back(octets(write_bitstream(b)));
  CoarseFields c;
  c.coarse_strength = 153;
  c.fine_strength = 128;
  c.bits = 6;
  c.predictor = 2;
  for (int k = 0; k < 200; ++k) c.levels.push_back(static_cast<std::uint16_t>((k * 7) % 64));
  b.coarse = c;
  out.push_back(octets(write_bitstream(b)));
  c.bits = 0;
  c.levels.clear();
  b.coarse = c;
  out.push_back(octets(write_bitstream(b)));
  return out;
}

TEST(FuzzReplay, RandomByteStrings) {
  SequentialRng rng(20240501, Stream::user);
  std::size_t accepted = 0;
  for (int round = 0; round < 20000; ++round) {
    std::vector<std::uint8_t> v(rng.below(65));
    for (auto& x : v) x = static_cast<std::uint8_t>(rng.bits());
    // Half of them start like a bitstream so the parser gets past the magic.
    if (round % 2 == 0 && v.size() >= 2) v[0] = bitstream_magic, v[1] = bitstream_version;
    LLVMFuzzerTestOneInput(v.data(), v.size());
    try {
      (void)parse_bitstream(std::as_bytes(std::span(v)));
      ++accepted;
    } catch (const FormatError&) {
    }
  }
  // Magic, version, structure and CRC-8 together: a random string almost
  // never parses (bound: 1 in 256 of those reaching the CRC).
  EXPECT_LT(accepted, 60u);
}

TEST(FuzzReplay, MutatedValidStreams) {
  SequentialRng rng(7, Stream::user);
  for (const auto& seed : seeds()) {
    ASSERT_NO_THROW((void)parse_bitstream(std::as_bytes(std::span(seed))));
    for (int round = 0; round < 5000; ++round) {
      std::vector<std::uint8_t> v = seed;
      const int ops = 1 + static_cast<int>(rng.below(3));
      for (int o = 0; o < ops; ++o) {
        switch (rng.below(5)) {
          case 0:
            if (!v.empty()) v[rng.below(v.size())] ^= static_cast<std::uint8_t>(1u << rng.below(8));
            break;
          case 1:
            if (!v.empty()) v[rng.below(v.size())] = static_cast<std::uint8_t>(rng.bits());
            break;
          case 2: v.resize(rng.below(v.size() + 1)); break;
          case 3:
            v.insert(v.begin() + static_cast<std::ptrdiff_t>(rng.below(v.size() + 1)), static_cast<std::uint8_t>(rng.bits()));
            break;
          default: v.push_back(static_cast<std::uint8_t>(rng.bits())); break;
        }
      }
      LLVMFuzzerTestOneInput(v.data(), v.size());
    }
  }
}

}  // namespace
