// Replays the experiment fuzz target over a deterministic corpus under any
// compiler: every shipped protocol, and mutations of it (bit flips, byte
// substitutions, truncations, deleted and duplicated spans, swapped JSON
// values), trial CSVs and response messages, random and mutated. Every input
// must be accepted or rejected with texel::Error (the target aborts otherwise).
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "../support/json_mutation.hpp"
#include "texel/io.hpp"
#include "texel/random.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

void feed(std::uint8_t which, const std::string& text) {
  std::vector<std::uint8_t> in(text.size() + 1);
  in[0] = which;
  std::copy(text.begin(), text.end(), in.begin() + 1);
  LLVMFuzzerTestOneInput(in.data(), in.size());
}

}  // namespace

TEST(ExperimentFuzzReplay, ShippedProtocolsAndTheirMutations) {
  const texel::CounterRng rng(2026, 77);
  std::uint64_t k = 0;
  int files = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols")) {
    const std::string text = texel::read_file(f.path().string());
    feed(0, text);
    ++files;
    for (int i = 0; i < 150; ++i, ++k) {
      std::string m = texel::test_support::mutate_json(text, rng, k);
      if (i % 3 == 0) m = texel::test_support::mutate_json(m, rng, k + 1000000);
      feed(0, m);
    }
  }
  EXPECT_GE(files, 9);
}

TEST(ExperimentFuzzReplay, TrialCsvAndResponses) {
  const texel::CounterRng rng(2026, 78);
  const std::string csv =
      "participant,session_id,trial,practice,iteration,rating,response,shown_at\n"
      "S01,1,0,0,,4,\"a, \"\"quoted\"\" answer\",2026-11-23T14:02:08.123Z\r\n"
      "S02,2,1,1,3,nan,B,\n";
  const std::string response = R"({"choice": "A", "rating": 3, "confidence": 5, "slider_p": 1.5, "digit": 7, "rt_ms": 1200,
    "shown_at": "x", "events": []})";
  feed(1, csv);
  feed(2, response);
  for (std::uint64_t k = 0; k < 3000; ++k) {
    feed(1, texel::test_support::mutate_json(csv, rng, k));
    feed(2, texel::test_support::mutate_json(response, rng, k));
  }
  std::string noise;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    noise.assign(static_cast<std::size_t>(rng.below(k * 3, 200)), ' ');
    for (std::size_t i = 0; i < noise.size(); ++i) noise[i] = static_cast<char>(rng.below(k * 3 + 1 + i * 7919, 256));
    feed(static_cast<std::uint8_t>(k % 3), noise);
  }
}
