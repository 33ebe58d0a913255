// libFuzzer target for the experiment engine's parsers of outside input: the
// first byte picks the parser, the rest is its input.
//   0: protocol files (parse_protocol); an accepted protocol must also start
//      a Session and describe its first question;
//   1: the long-format trial CSV (parse_trials_csv); what parses must write
//      and read back to the same rows;
//   2: a front end's response message (Response::from_json).
// Every input is accepted or rejected with a texel::Error; anything else (a
// crash, another exception, a sanitizer report) is a bug.
//
// Built with clang as `fuzz_experiment` (-fsanitize=fuzzer,address,undefined):
//   build-clang/tests/experiment/fuzz_experiment -max_total_time=600 examples/protocols
// Under GCC the same function runs over mutated shipped protocols and random
// inputs in test_fuzz_experiment.cpp (part of the normal test suite).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "texel/error.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/session.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  namespace ex = texel::experiment;
  try {
    switch (data[0] % 3) {
      case 0: {
        ex::Protocol p = ex::parse_protocol(text, "fuzz");
        (void)p.planned_trials();
        ex::SessionContext c;
        c.participant = "F01";
        c.seed = 1;
        ex::Session s(std::move(p), std::move(c));
        if (!s.finished()) (void)s.question().to_json();
        break;
      }
      case 1: {
        const auto rows = ex::parse_trials_csv(text, "fuzz");
        const auto again = ex::parse_trials_csv(ex::trials_csv(rows), "again");
        if (ex::trials_csv(again) != ex::trials_csv(rows)) std::abort();
        break;
      }
      default: {
        (void)ex::Response::from_json(text).to_json();  // not JSON: a FormatError like any other
        break;
      }
    }
  } catch (const texel::Error&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
