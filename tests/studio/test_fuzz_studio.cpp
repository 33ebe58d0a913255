// Replays the studio fuzz target under any compiler over a deterministic
// corpus: one valid message of every type and mutations of each (bit flips,
// JSON punctuation, truncations, deleted and duplicated spans, extreme
// numbers, strings swapped for numbers or objects). The target aborts on any
// reply that is not a well-formed JSON object (error replies included).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "../support/json_mutation.hpp"
#include "texel/random.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

void feed(const std::string& text) { LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()); }

const std::string doc =
    R"({"format":"texel-document","version":2,"device":"tpad","regions":[{"start_mm":0,"length_mm":50.88,"texture":{"kind":"reference","name":"4sin","seed":1}},{"start_mm":50.88,"texture":{"kind":"texel","central_pitch_db":8,"irregularity_db":-3,"texel_length_mm":0.25,"seed":1,"coarse":{"kind":"sine","period_mm":5,"phase_deg":0},"coarse_strength":0.5}}]})";

const std::vector<std::string> seeds = {
    R"({"type":"hello","id":1})",
    R"({"type":"design","id":"d","document":)" + doc + R"(,"region":1,"bins":20})",
    R"({"type":"feel.select","document":)" + doc + "}",
    R"({"type":"feel.move","id":2,"seq":5,"t_ms":16.5,"x_mm":12.5,"touch":true,"coalesced":[[8.2,12.1],[12.4,12.3]]})",
    R"({"type":"feel.state"})",
    R"({"type":"export","document":)" + doc + R"(,"as":"bitstream"})",
    R"({"type":"import","name":"a.texel.json","data_base64":"eyJmb3JtYXQiOiJ0ZXhlbC1kb2N1bWVudCJ9"})",
    R"({"type":"import","name":"a.texel","data_base64":"VAEAA+j+DPoAvAcBAQ=="})",
    R"({"type":"experiment.list"})",
    R"({"type":"experiment.start","protocol":"texel-length","participant":"F1","resume":false,"simulate":"default"})",
    R"({"type":"experiment.current"})",
    R"({"type":"experiment.select","trial":0,"stimulus":1})",
    R"({"type":"experiment.preview","trial":0,"slider_p":50,"slider_i":50})",
    R"({"type":"experiment.answer","trial":0,"response":{"choice":"1","rt_ms":800,"confidence":3}})",
    R"({"type":"experiment.answer","trial":0,"simulated":true})",
    R"({"type":"experiment.stroke","trial":0,"token":"t","stimulus":0,"samples":[[1.5,10,20,true],[2.5,11,20,false]]})",
    R"({"type":"experiment.stop"})",
};

}  // namespace

TEST(StudioFuzzReplay, ValidMessagesAndTheirMutations) {
  const texel::CounterRng rng(2026, 9);
  std::uint64_t k = 0;
  for (const auto& s : seeds) feed(s);
  for (int round = 0; round < 40; ++round)
    for (const auto& s : seeds) {
      std::string m = s;
      const auto n = rng.below(k * 8 + 5, 4) + 1;
      for (std::uint64_t i = 0; i < n; ++i) m = texel::test_support::mutate_json(m, rng, ++k);
      feed(m);
    }
  // Let the lanes drain while the fixture lives (replies are checked as they come).
  std::this_thread::sleep_for(std::chrono::seconds(2));
  SUCCEED() << k << " mutations";
}
