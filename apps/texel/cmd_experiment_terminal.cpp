// The terminal runner of `texel experiment run` (docs/experiments.md): one
// question at a time on stdout, answers typed on stdin, the stimuli fed to
// the Presenter meanwhile. It only presents and collects; the engine
// (libtexel_experiment's Session) validates and scores.
#include "experiment_terminal.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>
#include <thread>

#include "texel/detail/format.hpp"
#include "texel/experiment/records.hpp"

namespace texel::cli {

namespace ex = texel::experiment;
using Clock = std::chrono::steady_clock;

std::atomic<bool> experiment_interrupted{false};
extern "C" void on_experiment_signal(int) { experiment_interrupted = true; }

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Reads one line from stdin, pumping the presenter meanwhile. nullopt on
// end of input, Ctrl-C or timeout (timeout_s <= 0: none).
std::optional<std::string> read_line(ex::Presenter* presenter, double timeout_s, bool* timed_out = nullptr) {
  static std::string buffer;
  const auto t0 = Clock::now();
  if (timed_out) *timed_out = false;
  for (;;) {
    if (const auto nl = buffer.find('\n'); nl != std::string::npos) {
      std::string line = buffer.substr(0, nl);
      buffer.erase(0, nl + 1);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return line;
    }
    if (experiment_interrupted) return std::nullopt;
    if (timeout_s > 0 && seconds_since(t0) >= timeout_s) {
      if (timed_out) *timed_out = true;
      return std::nullopt;
    }
    if (presenter) presenter->pump();
    pollfd p{STDIN_FILENO, POLLIN, 0};
    const int r = ::poll(&p, 1, 20);
    if (r > 0) {
      char chunk[512];
      const ssize_t n = ::read(STDIN_FILENO, chunk, sizeof chunk);
      if (n <= 0) {
        if (!buffer.empty()) {
          std::string line;
          line.swap(buffer);
          return line;
        }
        return std::nullopt;  // end of input
      }
      buffer.append(chunk, static_cast<std::size_t>(n));
      if (buffer.size() > 4096) buffer.clear();  // a pasted novel is not an answer
    }
  }
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

}  // namespace

// Waits `seconds` while keeping the presenter fed; returns early on Ctrl-C.
void wait_pumping(ex::Presenter* presenter, double seconds) {
  const auto t0 = Clock::now();
  while (!experiment_interrupted && seconds_since(t0) < seconds) {
    if (presenter) presenter->pump();
    std::this_thread::sleep_for(std::chrono::milliseconds(std::min(10, std::max(1, static_cast<int>(seconds * 1000)))));
  }
  if (presenter) presenter->pump();
}

// ------------------------------------------------------------- terminal UI

// Presents one question on the terminal and collects a valid answer.
// Returns nullopt when the participant quits (q, end of input, Ctrl-C).
std::optional<ex::Response> ask_terminal(const ex::Session& session, ex::Presenter* presenter) {
  const ex::Question& q = session.question();
  ex::Response r;
  r.shown_at = ex::utc_timestamp();
  const auto t0 = Clock::now();
  auto event = [&](const std::string& kind, const std::string& detail) {
    r.events.push_back({seconds_since(t0), kind, detail, ex::utc_timestamp()});
  };
  auto feel = [&](int i) {
    if (presenter) presenter->show(q.stimuli[static_cast<std::size_t>(i)].document_json);
    event("select", q.stimuli[static_cast<std::size_t>(i)].label);
  };
  std::cout << "\n── trial " << q.trial + 1 << (q.practice ? " (practice)" : "") << " · " << q.block << " "
            << q.trial_in_block + 1
            << (q.block_trials && *q.block_trials > 0 ? " of " + std::to_string(*q.block_trials) : std::string()) << " ──\n"
            << q.prompt << "\n";
  event("show", "trial " + std::to_string(q.trial));

  // Working memory: the timed sequence first.
  for (const auto& ph : q.phases) {
    if (ph.kind == ex::PhaseKind::stimulus && ph.stimulus) {
      feel(*ph.stimulus);
      std::cout << "  feeling " << q.stimuli[static_cast<std::size_t>(*ph.stimulus)].label << " for "
                << detail::num(ph.duration_s) << " s ...\n";
      std::cout.flush();
    } else {
      if (presenter) presenter->blank();
      event("matrix", "");
      std::cout << "  remember this matrix (" << detail::num(ph.duration_s) << " s):\n";
      for (int row = 0; row < 4; ++row) {
        std::cout << "      ";
        for (int col = 0; col < 4; ++col) {
          const int d = (*q.matrix)[static_cast<std::size_t>(row * 4 + col)];
          std::cout << (d ? std::to_string(d) : std::string(".")) << "  ";
        }
        std::cout << "\n";
      }
      std::cout.flush();
    }
    wait_pumping(presenter, ph.duration_s);
    if (ph.kind == ex::PhaseKind::matrix && ::isatty(STDOUT_FILENO)) std::cout << "\033[6A\033[J";  // hide the matrix again
    if (experiment_interrupted) return std::nullopt;
  }
  if (!q.phases.empty() && presenter) presenter->blank();

  std::string labels;
  for (std::size_t i = 0; i < q.stimuli.size(); ++i) labels += "  [f " + std::to_string(i + 1) + "] " + q.stimuli[i].label;
  if (q.phases.empty() && !q.stimuli.empty()) {
    std::cout << "  feel:" << labels << "\n";
    feel(0);
  }
  double slider_p = q.sliders.empty() ? 0 : q.sliders[0].start, slider_i = q.sliders.empty() ? 0 : q.sliders[1].start;
  if (!q.sliders.empty())
    std::cout << "  sliders: 'p VALUE' (" << q.sliders[0].label << ", " << detail::num(q.sliders[0].min) << " … "
              << detail::num(q.sliders[0].max) << "), 'i VALUE' (" << q.sliders[1].label << ", " << detail::num(q.sliders[1].min)
              << " … " << detail::num(q.sliders[1].max) << "), 'a' to accept\n";
  if (!q.choices.empty()) {
    std::string c;
    for (const auto& x : q.choices) c += (c.empty() ? "" : " | ") + x;
    std::cout << "  answer: 'a CHOICE' with CHOICE one of " << c << "\n";
  }
  if (q.rating_scale)
    std::cout << "  answer: 'a N' with N from " << (*q.rating_scale)[0] << " to " << (*q.rating_scale)[1] << "\n";
  if (q.time_limit_s > 0) std::cout << "  (" << detail::num(q.time_limit_s) << " s to explore)\n";
  std::cout << "  ('q' saves and quits; the session resumes with --resume)\n";

  bool time_up = false;
  for (;;) {
    std::cout << "> " << std::flush;
    const double remaining = q.time_limit_s > 0 && !time_up ? q.time_limit_s - seconds_since(t0) : 0.0;
    bool timed_out = false;
    const auto line = read_line(presenter, remaining > 0 ? remaining : (q.time_limit_s > 0 && !time_up ? 1e-3 : 0.0), &timed_out);
    if (timed_out) {
      time_up = true;
      if (presenter) presenter->blank();
      event("timeout", "");
      std::cout << "\n  time is up: answer now\n";
      continue;
    }
    if (!line) return std::nullopt;
    const std::string cmd = trim(*line);
    if (cmd == "q" || cmd == "quit") return std::nullopt;
    std::istringstream in(cmd);
    std::string verb, arg;
    in >> verb >> arg;
    if (verb == "f" && !time_up) {
      int i = 0;
      try {
        i = std::stoi(arg);
      } catch (...) {
        i = 0;
      }
      if (i >= 1 && i <= static_cast<int>(q.stimuli.size()) && q.phases.empty())
        feel(i - 1);
      else
        std::cout << "  feel which? 1 … " << q.stimuli.size() << "\n";
    } else if ((verb == "p" || verb == "i") && !q.sliders.empty()) {
      try {
        (verb == "p" ? slider_p : slider_i) = std::stod(arg);
      } catch (...) {
        std::cout << "  '" << verb << "' needs a number\n";
        continue;
      }
      event("slider", verb + "=" + arg);
      if (presenter) presenter->show(session.preview_document(slider_p, slider_i));
    } else if (verb == "a") {
      r.choice.clear();
      if (!q.choices.empty()) r.choice = arg;
      if (q.rating_scale) {
        try {
          r.rating = std::stod(arg);
        } catch (...) {
          r.rating.reset();
        }
      }
      if (!q.sliders.empty()) {
        r.slider_p = slider_p;
        r.slider_i = slider_i;
      }
      const double rt = seconds_since(t0) * 1000.0;
      if (q.confidence) {
        std::cout << "  how confident are you in this match? 1 (not at all) … 5 (very)\n> " << std::flush;
        const auto c = read_line(presenter, 0);
        if (!c) return std::nullopt;
        try {
          r.confidence = std::stod(trim(*c));
        } catch (...) {
          r.confidence.reset();
        }
      }
      if (q.recall) {
        if (q.recall->cell)
          std::cout << "  which digit was in row " << *q.recall->cell / 4 + 1 << ", column " << *q.recall->cell % 4 + 1
                    << "? (1 … 9)\n> ";
        else
          std::cout << "  which digit was in the cells? (1 … 9)\n> ";
        std::cout << std::flush;
        const auto d = read_line(presenter, 0);
        if (!d) return std::nullopt;
        try {
          r.digit = std::stoi(trim(*d));
        } catch (...) {
          r.digit.reset();
        }
      }
      r.rt_ms = std::round(rt);
      r.answered_at = ex::utc_timestamp();
      event("answer", arg);
      return r;
    } else if (!cmd.empty()) {
      std::cout << "  commands: 'f N' feel stimulus N, 'a ANSWER', " << (q.sliders.empty() ? "" : "'p V', 'i V', ")
                << "'q' quit\n";
    }
  }
}

}  // namespace texel::cli
