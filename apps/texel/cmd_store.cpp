// texel store init — the one-time set-up of a study's PostgreSQL server
// (docs/session-store.md "Lab set-up"): schema, migrations and roles, by the
// library's init_postgres().
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "texel/error.hpp"
#include "texel/experiment/store.hpp"

namespace texel::cli {

void register_store(CLI::App& app) {
  auto* cmd = app.add_subcommand("store", "The experiment store's server: set-up and migrations (PostgreSQL)");
  cmd->require_subcommand(1);
  struct InitArgs {
    std::string uri;
    std::vector<std::string> stations, analysts;
  };
  auto a = std::make_shared<InitArgs>();
  auto* init =
      cmd->add_subcommand("init", "As the migration owner: create or migrate the texel schema and the station and analyst roles");
  init->add_option("--postgres", a->uri, "The server (postgresql://owner@host/db or service=NAME; password from ~/.pgpass)")
      ->required();
  init->add_option("--station", a->stations, "A station's login role to create (repeatable)");
  init->add_option("--analyst", a->analysts, "An analyst's login role to create (repeatable)");
  init->callback([a] {
    if (!experiment::is_postgres(a->uri))
      throw InvalidArgument("--postgres: not a PostgreSQL URI (postgresql://…) or service name (service=NAME): " + a->uri);
    for (const auto& line : experiment::init_postgres(a->uri, a->stations, a->analysts)) std::cout << line << "\n";
  });
}

}  // namespace texel::cli
