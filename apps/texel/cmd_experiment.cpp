// placeholder: being written
#include "commands.hpp"
namespace texel::cli {
void register_experiment(CLI::App&) {}
}  // namespace texel::cli
