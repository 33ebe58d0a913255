// placeholder: being written
#include "commands.hpp"
namespace texel::cli {
void register_staircase(CLI::App&) {}
}  // namespace texel::cli
