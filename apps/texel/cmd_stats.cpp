// placeholder: being written
#include "commands.hpp"
namespace texel::cli {
void register_stats(CLI::App&) {}
}  // namespace texel::cli
