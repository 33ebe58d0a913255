// Runs the built `texel` command for CLI tests: exit status and output
// (stdout, with stderr merged unless asked otherwise), like a user's shell.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace texel::test_support {

struct CliRun {
  int status = -1;  ///< exit status; -1 if it did not exit normally
  std::string out;  ///< what it printed
};

/// `cli args` through /bin/sh; `env` (e.g. "VAR=value") is prefixed to the
/// command; standard input is /dev/null.
inline CliRun run_cli(const std::string& cli, const std::string& args, bool merge_stderr = true, const std::string& env = "") {
  const std::string cmd =
      env + (env.empty() ? "" : " ") + cli + " " + args + (merge_stderr ? " 2>&1" : " 2>/dev/null") + " </dev/null";
  CliRun r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), p)) r.out += buf.data();
  const int s = ::pclose(p);
  r.status = WIFEXITED(s) ? WEXITSTATUS(s) : -1;
  return r;
}

}  // namespace texel::test_support
