// libFuzzer target: one Service, one client, each input one text message.
// Every reply must be one valid JSON object with a type (an error reply with
// a code and a one-line message); anything else aborts. The service's
// workers run concurrently, so crashes in the slow lanes surface too (ASan).
// Build with clang: -fsanitize=fuzzer,address,undefined (tests/studio/CMakeLists.txt).
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "texel/studio/service.hpp"

namespace {

void check_reply(const std::string& text) {
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("type") || !j["type"].is_string()) std::abort();
  if (j["type"] == "error") {
    if (!j.contains("code") || !j["code"].is_string() || !j.contains("message") || !j["message"].is_string()) std::abort();
    if (j["message"].get<std::string>().find('\n') != std::string::npos) std::abort();
  }
}

struct Fixture {
  std::unique_ptr<texel::studio::Service> service;
  std::uint64_t client = 0;
  Fixture() {
    const auto dir = std::filesystem::temp_directory_path() / ("texel-fuzz-studio-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    texel::studio::ServiceOptions o;
    o.db_path = (dir / "fuzz.db").string();
    o.protocols_dir = std::string(TEXEL_FUZZ_PROTOCOLS_DIR);
    o.max_messages_per_s = 1e6;  // reach the parsers, not the rate limiter
    o.max_map_samples = 1u << 16;
    service = std::make_unique<texel::studio::Service>(o);
    client = service->connect(check_reply);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Fixture f;
  f.service->handle(f.client, std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
