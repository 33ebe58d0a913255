// The service's message table (src/studio/messages.cpp) against the message
// schema the front end's types are generated from
// (docs/schema/studio-messages.schema.json): the same client types, each
// with the same keys and lane, every reply type a request names is a server
// message, and the replies the service really sends have the schema's keys.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "messages.hpp"
#include "texel/studio/service.hpp"

using json = nlohmann::json;
namespace st = texel::studio;

namespace {

const json& schema() {
  static const json s = [] {
    std::ifstream in(std::string(TEXEL_TEST_SOURCE_DIR) + "/docs/schema/studio-messages.schema.json");
    return json::parse(in);
  }();
  return s;
}

/// type → the $defs entry of each member of ClientMessage or ServerMessage.
std::map<std::string, json> members(const char* union_name) {
  std::map<std::string, json> out;
  for (const json& ref : schema()["$defs"][union_name]["oneOf"]) {
    const std::string name = ref["$ref"].get<std::string>().substr(std::string("#/$defs/").size());
    const json& def = schema()["$defs"][name];
    const std::string type = def["properties"]["type"]["const"];
    EXPECT_FALSE(out.count(type)) << union_name << " lists " << type << " twice";
    out[type] = def;
  }
  return out;
}

std::set<std::string> keys_of(const json& def) {
  std::set<std::string> keys;
  for (const auto& [k, v] : def["properties"].items())
    if (k != "type" && k != "id") keys.insert(k);
  return keys;
}

const char* lane_name(st::detail::Lane l) {
  switch (l) {
    case st::detail::Lane::now: return "now";
    case st::detail::Lane::design: return "design";
    case st::detail::Lane::fifo: return "fifo";
  }
  return "?";
}

}  // namespace

TEST(StudioMessages, TableAndSchemaListTheSameClientTypesKeysAndLanes) {
  auto client = members("ClientMessage");
  std::set<std::string> in_table;
  for (const auto& spec : st::detail::message_table()) {
    const std::string type(spec.type);
    in_table.insert(type);
    ASSERT_TRUE(client.count(type)) << type << " is in the message table but not in the schema's ClientMessage";
    const json& def = client[type];
    std::set<std::string> table_keys;
    for (const auto k : spec.keys) table_keys.insert(std::string(k));
    EXPECT_EQ(table_keys, keys_of(def)) << type << ": the table's keys differ from the schema's properties";
    EXPECT_EQ(def.value("x-texel-lane", ""), lane_name(spec.lane)) << type;
    EXPECT_EQ(def.value("additionalProperties", true), false) << type << ": the service refuses unknown keys";
    EXPECT_EQ(st::detail::find_message(type), &spec);
  }
  for (const auto& [type, def] : client) EXPECT_TRUE(in_table.count(type)) << type << " is in the schema but not in the table";
}

TEST(StudioMessages, EveryReplyARequestNamesIsAServerMessage) {
  const auto server = members("ServerMessage");
  ASSERT_TRUE(server.count("error"));
  std::set<std::string> named{"error"};
  for (const auto& [type, def] : members("ClientMessage")) {
    ASSERT_TRUE(def.contains("x-texel-replies")) << type;
    for (const auto& r : def["x-texel-replies"]) {
      EXPECT_TRUE(server.count(r.get<std::string>())) << type << " replies " << r;
      named.insert(r.get<std::string>());
    }
  }
  for (const auto& [type, def] : server) EXPECT_TRUE(named.count(type)) << type << " answers no request";
}

TEST(StudioMessages, RepliesHaveTheSchemasKeys) {
  std::mutex m;
  std::vector<json> replies;
  st::Service service(st::ServiceOptions{});
  const auto c = service.connect([&](std::string text) {
    std::lock_guard lock(m);
    replies.push_back(json::parse(text));
  });
  const std::string doc = R"({"format":"texel-document","version":1,"device":"tpad","texture":{"kind":"texel",
    "central_pitch_db":10,"irregularity_db":-5,"texel_length_mm":0.25,"seed":1}})";
  service.handle(c, R"({"type":"hello","id":1})");
  service.handle(c, R"({"type":"feel.move","id":2,"seq":1,"t_ms":0,"x_mm":3})");
  service.handle(c, R"({"type":"feel.state","id":3})");
  service.handle(c, R"({"type":"nonsense","id":4})");
  service.handle(c, R"({"type":"design","id":5,"document":)" + doc + "}");
  service.handle(c, R"({"type":"export","id":6,"as":"document","document":)" + doc + "}");
  for (int i = 0; i < 2000; ++i) {
    {
      std::lock_guard lock(m);
      if (replies.size() >= 6) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const auto server = members("ServerMessage");
  std::lock_guard lock(m);
  ASSERT_EQ(replies.size(), 6u);
  for (const json& r : replies) {
    const std::string type = r["type"];
    ASSERT_TRUE(server.count(type)) << type;
    const json& def = server.at(type);
    std::set<std::string> keys;
    for (const auto& [k, v] : r.items())
      if (k != "type" && k != "id") keys.insert(k);
    for (const auto& k : keys) EXPECT_TRUE(keys_of(def).count(k)) << type << " sends " << k << ", not in the schema";
    for (const auto& k : def.value("required", json::array()))
      EXPECT_TRUE(r.contains(k.get<std::string>())) << type << " lacks " << k;
  }
}
