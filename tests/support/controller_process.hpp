// The reference display controller (`texel controller --pty …`) as a child
// process for CLI tests: it stands in for a friction display on a
// pseudo-terminal whose path it prints first.
#pragma once

#include <csignal>
#include <cstdio>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace texel::test_support {

class ControllerProcess {
 public:
  /// Starts `cli controller --pty <args…>` and reads the pty's path (empty if
  /// it did not start).
  ControllerProcess(const std::string& cli, const std::vector<std::string>& args) {
    int out[2];
    if (::pipe(out) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      ::dup2(out[1], 2);
      ::close(out[0]);
      std::vector<std::string> all = {cli, "controller", "--pty"};
      all.insert(all.end(), args.begin(), args.end());
      std::vector<char*> argv;
      for (auto& a : all) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(cli.c_str(), argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    output_ = ::fdopen(out[0], "r");
    char line[512];
    if (output_ && std::fgets(line, sizeof line, output_)) {
      pty_ = line;
      while (!pty_.empty() && (pty_.back() == '\n' || pty_.back() == '\r')) pty_.pop_back();
    }
  }
  ~ControllerProcess() { (void)stop(); }
  ControllerProcess(const ControllerProcess&) = delete;
  ControllerProcess& operator=(const ControllerProcess&) = delete;

  [[nodiscard]] const std::string& pty() const { return pty_; }

  /// Stops it (SIGTERM: it stops cleanly and prints its counters) and
  /// returns what it printed after the pty's path.
  std::string stop() {
    if (pid_ <= 0) return rest_;
    ::kill(pid_, SIGTERM);
    char line[512];
    while (output_ && std::fgets(line, sizeof line, output_)) rest_ += line;
    if (output_) std::fclose(output_);
    output_ = nullptr;
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return rest_;
  }

 private:
  pid_t pid_ = -1;
  FILE* output_ = nullptr;
  std::string pty_;
  std::string rest_;
};

}  // namespace texel::test_support
