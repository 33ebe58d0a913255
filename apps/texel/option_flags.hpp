// CLI flags made from a library options struct's own description
// (texel/option_spec.hpp): one flag per described option, bound to the
// struct's member, its help the description with the library's default
// appended ("[6]", "[png]"). The values are checked with the library's rule
// in the command's callback (apply()), so a default, a range or an allowed
// spelling changes only in the library.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "texel/option_spec.hpp"

namespace texel::cli {

class DescribedFlags {
 public:
  /// Adds the flags of every option `visit_options(options, …)` describes to
  /// `cmd`. `options` must outlive the command's callback.
  template <class Options>
  DescribedFlags(CLI::App* cmd, Options& options) {
    const Options defaults{};
    std::vector<std::string> shown;
    visit_options(defaults, [&](const auto& v, const OptionSpec& spec) { shown.push_back(option_default_text(v, spec)); });
    std::size_t i = 0;
    visit_options(options, [&](auto& member, const OptionSpec& spec) {
      using T = std::remove_cvref_t<decltype(member)>;
      const std::string flag = "--" + std::string(spec.flag);
      if constexpr (std::is_same_v<T, bool>) {
        cmd->add_flag(flag, member, std::string(spec.help));
      } else if constexpr (std::is_enum_v<T>) {
        auto& text = *texts_.emplace_back(std::make_unique<std::string>(shown[i]));
        cmd->add_option(flag, text, std::string(spec.help) + " [" + shown[i] + "]");
        checks_.push_back([&member, &text, spec, flag] { member = static_cast<T>(parse_option_choice(spec, text, flag)); });
      } else {
        cmd->add_option(flag, member, std::string(spec.help) + " [" + shown[i] + "]");
        checks_.push_back([&member, spec, flag] { check_option_value(spec, static_cast<double>(member), flag); });
      }
      ++i;
    });
  }
  /// Checks every value given against the library's rule (InvalidArgument
  /// naming the flag) and sets the enumerations: call first in the callback.
  void apply() const {
    for (const auto& check : checks_) check();
  }

 private:
  std::vector<std::unique_ptr<std::string>> texts_;
  std::vector<std::function<void()>> checks_;
};

}  // namespace texel::cli
