// The terminal runner of `texel experiment run` (docs/experiments.md "The
// terminal runner"): one question at a time on stdout in plain words, answers
// typed on stdin, the stimuli fed to the Presenter meanwhile. The participant
// sees nothing that depends on correctness or on the procedure's state; what
// the experimenter needs goes to the Monitor stream (--monitor). It only
// presents and collects; the engine (libtexel_experiment's Session)
// validates and scores.
#include "experiment_terminal.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/records.hpp"

namespace texel::cli {

namespace ex = texel::experiment;
using Clock = std::chrono::steady_clock;

std::atomic<bool> experiment_interrupted{false};
extern "C" void on_experiment_signal(int) { experiment_interrupted = true; }

std::string_view to_string(StopReason r) {
  switch (r) {
    case StopReason::quit: return "quit";
    case StopReason::end_of_input: return "end-of-input";
    case StopReason::interrupt: return "interrupt";
    case StopReason::none: break;
  }
  return "none";
}

// ------------------------------------------------------------------ monitor

Monitor::~Monitor() { close(); }

bool Monitor::open(const std::string& path) {
  close();
  if (path == "-") {
    fd_ = STDERR_FILENO;
    owned_ = false;
    return false;
  }
  struct stat st {};
  const bool existed = ::stat(path.c_str(), &st) == 0;
  if (existed && S_ISFIFO(st.st_mode)) {
    // A FIFO: wait for its reader (the experimenter's `cat PATH`), then
    // write without ever blocking the participant's run.
    int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0 && errno == ENXIO) {
      std::cerr << "waiting for a reader on the monitor FIFO " << path << " (e.g. 'cat " << path << "' in another pane)\n";
      fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
      if (fd >= 0) ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    }
    if (fd < 0) throw IoError("--monitor " + path + ": cannot open the FIFO (" + std::strerror(errno) + ")");
    fd_ = fd;
  } else {
    const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) throw IoError("--monitor " + path + ": cannot open for appending (" + std::strerror(errno) + ")");
    fd_ = fd;
  }
  owned_ = true;
  return !existed;
}

void Monitor::close() {
  if (owned_ && fd_ >= 0) ::close(fd_);
  fd_ = -1;
  owned_ = false;
}

void Monitor::event(std::string_view name, std::initializer_list<Field> fields) {
  if (fd_ < 0) return;
  std::string line = ex::utc_timestamp();
  line += ' ';
  line += name;
  for (const auto& [key, value] : fields) {
    if (value.empty()) continue;  // a field the event does not have
    const bool plain = !value.empty() && std::none_of(value.begin(), value.end(), [](char c) {
      return std::isspace(static_cast<unsigned char>(c)) || c == '"' || c == '=' || c == '\\' ||
             static_cast<unsigned char>(c) < 0x20;
    });
    line += ' ';
    line += key;
    line += '=';
    line += plain ? value : nlohmann::json(value).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  line += '\n';
  const ssize_t n = ::write(fd_, line.data(), line.size());
  if (n < 0 && errno != EAGAIN && errno != EINTR) close();  // the reader went away (EPIPE): the run goes on
}

// ------------------------------------------------------------------ helpers

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string num(double v) { return std::isfinite(v) ? detail::num(v) : std::string(); }
std::string fixed1(double v) { return std::isfinite(v) ? detail::fixed(v, 1) : std::string(); }

// Whether the participant types on the terminal that shows the questions, so
// lines can be redrawn in place (the countdown).
bool interactive() {
  static const bool on = ::isatty(STDOUT_FILENO) == 1 && ::isatty(STDIN_FILENO) == 1;
  return on;
}

int terminal_columns() {
  winsize w{};
  if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0) return w.ws_col;
  return 80;
}

// Reads one line from stdin, pumping the presenter and calling `tick`
// meanwhile. nullopt on end of input, Ctrl-C or timeout (timeout_s <= 0: none).
// What was read from stdin but not yet taken as a line.
std::string input_buffer;

std::optional<std::string> read_line(ex::Presenter* presenter, double timeout_s, bool* timed_out = nullptr,
                                     const std::function<void()>& tick = {}) {
  std::string& buffer = input_buffer;
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
    if (tick) tick();
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

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// "1, 2 or 3"
std::string spoken_list(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + items[i];
  return out;
}

std::optional<int> whole_number(const std::string& s) {
  if (s.empty() || s.size() > 9 ||
      !std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
    return std::nullopt;
  return std::stoi(s);
}

std::optional<double> number(const std::string& s) {
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (...) {
  }
  return std::nullopt;
}

// The time left to answer, on the line above the prompt: redrawn in place
// on an interactive terminal, a line every 10 s (and at 5 s) otherwise.
class Countdown {
 public:
  Countdown(double limit_s, Clock::time_point t0) : limit_s_(limit_s), t0_(t0) {}
  [[nodiscard]] bool active() const { return limit_s_ > 0; }
  [[nodiscard]] double left_s() const { return limit_s_ - seconds_since(t0_); }
  void time_up() {
    up_ = true;
    redraw();
  }
  // The countdown line, then the prompt (the participant types after "> ").
  void prompt() {
    if (active() && (interactive() || seconds() != shown_ || up_)) {
      shown_ = seconds();
      std::cout << "  " << text() << "\n";
    }
    std::cout << "> " << std::flush;
  }
  void tick() {
    if (!active() || up_ || seconds() == shown_) return;
    shown_ = seconds();
    if (interactive())
      redraw();
    else if (shown_ > 0 && (shown_ % 10 == 0 || shown_ == 5))
      std::cout << "\n  " << text() << "\n> " << std::flush;
  }
  // After the participant pressed Enter: on an interactive terminal the
  // countdown line and the echoed input are replaced by the input alone, so
  // one countdown stays on screen; elsewhere the input is echoed.
  void entered(const std::string& raw) const {
    if (!interactive()) {
      std::cout << raw << "\n";  // no terminal echo: keep the transcript readable
      return;
    }
    if (!active()) return;
    const int rows = 1 + static_cast<int>(2 + raw.size()) / terminal_columns();
    std::cout << "\033[" << rows + 1 << "A\r\033[J> " << raw << "\n";
  }

 private:
  [[nodiscard]] int seconds() const { return std::max(0, static_cast<int>(std::ceil(left_s()))); }
  [[nodiscard]] std::string text() const {
    return up_ ? "Time is up: please answer now." : "Time left: " + std::to_string(shown_) + " s";
  }
  void redraw() {
    if (interactive())
      std::cout << "\0337\033[1A\r\033[2K  " << text() << "\0338" << std::flush;  // save, up, rewrite, restore
    else
      std::cout << "\n  " << text() << "\n> " << std::flush;
  }
  double limit_s_;
  Clock::time_point t0_;
  int shown_ = -1;
  bool up_ = false;
};

// A timed phase (working memory): a countdown redrawn in place, no input.
void countdown_phase(ex::Presenter* presenter, double seconds) {
  const auto t0 = Clock::now();
  int shown = -1;
  while (!experiment_interrupted && seconds_since(t0) < seconds) {
    if (presenter) presenter->pump();
    const int left = std::max(0, static_cast<int>(std::ceil(seconds - seconds_since(t0))));
    if (left != shown && interactive()) {
      std::cout << "\r\033[2K  Time left: " << left << " s" << std::flush;
      shown = left;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (presenter) presenter->pump();
  if (interactive()) std::cout << "\r\033[2K";
}

// Working memory's digit sequence (verbal, executive): each digit in turn on
// one line redrawn in place, for 80 % of its slot then a blank (so a repeated
// digit is seen twice). Executive (q.nback): every Enter is a response to the
// digit on screen (or just gone); only empty lines count, so an answer typed
// ahead stays for the question. Returns the items responded to, increasing.
std::vector<int> sequence_phase(ex::Presenter* presenter, const ex::Question& q, double seconds,
                                const std::function<void(const std::string&, const std::string&)>& event) {
  std::vector<int> presses;
  const auto n = static_cast<int>(q.sequence.size());
  const double slot = seconds / std::max(1, n);
  const auto t0 = Clock::now();
  int shown = -2;  // item drawn (-1: the blank)
  for (;;) {
    const double t = seconds_since(t0);
    if (experiment_interrupted || t >= seconds) break;
    if (presenter) presenter->pump();
    const int item = std::min(n - 1, static_cast<int>(t / slot));
    const bool blank = t - item * slot >= 0.8 * slot;
    const int draw = blank ? -1 : item;
    if (draw != shown) {
      if (interactive())
        std::cout << "\r\033[2K"
                  << (blank ? std::string() : "        " + std::to_string(q.sequence[static_cast<std::size_t>(item)]))
                  << std::flush;
      else if (!blank)
        std::cout << "        " << q.sequence[static_cast<std::size_t>(item)] << "\n" << std::flush;
      if (!blank) event("digit", std::to_string(item));
      shown = draw;
    }
    if (q.nback) {
      pollfd p{STDIN_FILENO, POLLIN, 0};
      if (::poll(&p, 1, 0) > 0) {
        char chunk[512];
        const ssize_t got = ::read(STDIN_FILENO, chunk, sizeof chunk);
        if (got > 0) input_buffer.append(chunk, static_cast<std::size_t>(got));
      }
      for (auto nl = input_buffer.find('\n'); nl != std::string::npos; nl = input_buffer.find('\n')) {
        const std::string line = input_buffer.substr(0, nl);
        if (!std::all_of(line.begin(), line.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)); })) break;
        input_buffer.erase(0, nl + 1);
        if (presses.empty() || presses.back() != item) presses.push_back(item);  // one response per digit
        event("respond", std::to_string(item));
        if (interactive()) std::cout << "\033[1A" << std::flush;  // the echoed Enter moved the line down
        shown = -2;                                               // redraw it there
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (presenter) presenter->pump();
  if (interactive()) std::cout << "\r\033[2K" << std::flush;
  return presses;
}

// A scale's ends as the studio's page shows them: "1 (not at all) to 5 (very)".
std::string scale_words(const ex::Scale& s) {
  const auto end = [](int v, const std::string& label) { return std::to_string(v) + (label.empty() ? "" : " (" + label + ")"); };
  return end(s.min, s.min_label) + " to " + end(s.max, s.max_label);
}

std::string how_to_answer(const ex::Question& q, bool two_d) {
  std::string out;
  const std::size_t n = q.stimuli.size();
  if (q.phases.empty() && n > 1) {
    std::vector<std::string> numbers;
    for (std::size_t i = 1; i <= n; ++i) numbers.push_back(std::to_string(i));
    out += "  Feel a texture: type its number (" + spoken_list(numbers) + ") and press Enter.\n";
    if (two_d)
      out += "  Then stroke the display with your finger along the line shown for that texture (back and forth is fine).\n";
    bool numbered = true;
    for (std::size_t i = 0; i < n; ++i) numbered = numbered && q.stimuli[i].label == std::to_string(i + 1);
    if (!numbered) {
      std::string legend;
      for (std::size_t i = 0; i < n; ++i)
        legend += (i ? ", " : "") + std::to_string(i + 1) + " = " + stimulus_name(q.stimuli[i].label);
      out += "    (" + legend + ")\n";
    }
  } else if (q.phases.empty() && n == 1) {
    out += "  Feel the display; type 1 to play it again.\n";
  }
  if (q.sliders.size() >= 2) {
    const auto& p = q.sliders[0];
    const auto& i = q.sliders[1];
    out += "  Adjust: 'p NUMBER' sets " + p.label + " (" + detail::num(p.min) + " to " + detail::num(p.max) +
           "), 'i NUMBER' sets " + i.label + " (" + detail::num(i.min) + " to " + detail::num(i.max) + ").\n";
    out += "  When it feels the same: type 'a' to accept.\n";
  }
  if (!q.choices.empty()) {
    // The library's words for each choice (Question::wording), and what to type for it.
    std::vector<std::string> examples;
    for (std::size_t k = 0; k < q.choices.size(); ++k)
      examples.push_back("'a " + q.choices[k] + "'" +
                         (k < q.wording.choice_labels.size() && q.wording.choice_labels[k] != q.choices[k]
                              ? " (" + q.wording.choice_labels[k] + ")"
                              : std::string()));
    out += "  " + q.wording.choice_question + ": type 'a' and your answer: " + spoken_list(examples) + ".\n";
  }
  if (const auto& s = q.wording.rating)
    out += "  " + s->question + " Type 'a' and a whole number from " + scale_words(*s) + ", e.g. 'a " +
           std::to_string((s->min + s->max + 1) / 2) + "'.\n";
  out += "  Help: 'h'.  Pause and quit (your answers are kept): 'q'.\n";
  return out;
}

// Asks a follow-up number (confidence, digit) until it is a whole number in
// [lo, hi]; nullopt when the participant quits.
std::optional<int> ask_number(ex::Presenter* presenter, const std::string& question, int lo, int hi, StopReason& stop) {
  std::cout << "  " << question << "\n> " << std::flush;
  for (;;) {
    const auto line = read_line(presenter, 0);
    if (!line) {
      stop = experiment_interrupted ? StopReason::interrupt : StopReason::end_of_input;
      return std::nullopt;
    }
    if (!interactive()) std::cout << *line << "\n";
    const std::string s = trim(*line);
    if (s == "q" || s == "quit") {
      stop = StopReason::quit;
      return std::nullopt;
    }
    if (const auto v = whole_number(s); v && *v >= lo && *v <= hi) return *v;
    std::cout << "  Please type a whole number from " << lo << " to " << hi << ".\n> " << std::flush;
  }
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

void tell_participant(const std::string& text) { std::cout << text << "\n" << std::flush; }

// The library's words (Question::wording), as the studio's page shows them.
std::string stimulus_name(const std::string& label) { return ex::stimulus_name(label); }

// ------------------------------------------------------------- terminal UI

void report_question(Monitor& monitor, const ex::Session& session) {
  const ex::Question& q = session.question();
  const ex::TrialTruth& truth = session.truth();
  const ex::Block* block = session.protocol().block(q.block);
  const std::string trial_number = std::to_string(q.trial + 1);
  monitor.event("question", {{"trial_number", trial_number},
                             {"trial", std::to_string(q.trial)},
                             {"block", q.block},
                             {"practice", q.practice ? "1" : "0"},
                             {"task", q.task},
                             {"trial_in_block", std::to_string(q.trial_in_block + 1)},
                             {"block_trials", q.block_trials ? std::to_string(*q.block_trials) : "adaptive"},
                             {"variable", block ? block->variable : std::string()},
                             {"value", num(truth.intensity)},
                             {"reference", truth.reference},
                             {"condition", truth.condition},
                             {"correct_answer", truth.correct_answer},
                             {"time_limit_s", num(q.time_limit_s)}});
}

std::optional<ex::Response> ask_terminal(const ex::Session& session, ex::Presenter* presenter, Monitor& monitor,
                                         StopReason& stop) {
  const ex::Question& q = session.question();
  const std::string trial_number = std::to_string(q.trial + 1);  // the export's trial_number
  stop = StopReason::none;
  // The stimuli into a map-storing display's slots before onset; the trial's finger trace starts.
  if (presenter && !presenter->two_d()) presenter->prepare(q);
  if (presenter && presenter->two_d()) {
    // The display's maps, before the trial's clock starts (a friction
    // bitmap takes about a second to render).
    // Usually ready: the presenter's preload renders the session's friction
    // bitmaps in the background from the start. The monitor gets the wait.
    if (interactive()) std::cout << "  Please wait: preparing the textures…" << std::flush;
    const auto prepared_from = Clock::now();
    presenter->prepare(q);
    monitor.event("maps_ready", {{"trial_number", trial_number}, {"wait_s", detail::fixed(seconds_since(prepared_from), 3)}});
    if (interactive()) std::cout << "\r\033[2K" << std::flush;
    // Keys typed on a terminal while the maps rendered were meant for no
    // trial on screen (and their echo would upset the countdown's redraw).
    if (interactive()) {
      ::tcflush(STDIN_FILENO, TCIFLUSH);
      input_buffer.clear();
    }
  }
  ex::Response r;
  r.shown_at = ex::utc_timestamp();
  const auto t0 = Clock::now();
  auto event = [&](const std::string& kind, const std::string& detail) {
    r.events.push_back({seconds_since(t0), kind, detail, ex::utc_timestamp()});
  };
  auto ended = [&](StopReason why) {
    stop = why;
    monitor.event(
        "quit",
        {{"trial_number", trial_number}, {"reason", std::string(to_string(why))}, {"t_s", detail::fixed(seconds_since(t0), 3)}});
    return std::nullopt;
  };
  // A 2-D display: the participant strokes each texture along its own
  // line. Leaving a texture whose strokes went another way brings one plain
  // reminder (about the stroke, nothing of the trial); the trial goes on.
  const bool two_d = presenter && presenter->two_d();
  int felt = -1;
  auto remind = [&](int next) {
    if (!two_d || felt < 0 || felt == next) return;
    const auto strokes = presenter->strokes(q);
    const ex::IntervalStrokes& last = strokes[static_cast<std::size_t>(felt)];
    if (last.strokes == 0 || last.compliant) return;
    const auto& label = q.stimuli[static_cast<std::size_t>(felt)].label;
    event("stroke_reminder", label);
    monitor.event("stroke_reminder", {{"trial_number", trial_number},
                                      {"stimulus", std::to_string(felt + 1)},
                                      {"direction_deg", fixed1(last.direction_deg)},
                                      {"deviation_deg", fixed1(last.deviation_deg)},
                                      {"straightness", detail::fixed(last.straightness, 2)}});
    std::cout << "  (You stroked " << stimulus_name(label) << " along another line than its own: "
              << ex::direction_words(q.surfaces[static_cast<std::size_t>(felt)].direction_deg) << ".)\n";
  };
  auto feel = [&](int i) {
    const auto& s = q.stimuli[static_cast<std::size_t>(i)];
    remind(i);
    felt = i;
    if (presenter) presenter->show(q, static_cast<std::size_t>(i));
    event("select", s.label);
    monitor.event("play", {{"trial_number", trial_number},
                           {"stimulus", std::to_string(i + 1)},
                           {"label", s.label},
                           {"t_s", detail::fixed(seconds_since(t0), 3)}});
    std::cout << "  Now playing: " << stimulus_name(s.label) << "\n";
    if (two_d)
      std::cout << "  Stroke along: " << ex::direction_words(q.surfaces[static_cast<std::size_t>(i)].direction_deg) << "\n";
  };
  report_question(monitor, session);

  const int planned = session.trials_planned();
  std::cout << "\n────────────────────────────────────────\n"
            << "Trial " << trial_number << (planned > 0 ? " of " + std::to_string(planned) : std::string())
            << (q.practice ? " (practice)" : "") << "\n"
            << q.prompt << "\n";
  event("show", "trial " + std::to_string(q.trial));

  // Working memory: the timed sequence first.
  for (const auto& ph : q.phases) {
    if (ph.kind == ex::PhaseKind::stimulus && ph.stimulus) {
      feel(*ph.stimulus);
      std::cout << "  Feel it for " << detail::num(ph.duration_s) << " s.\n" << std::flush;
      countdown_phase(presenter, ph.duration_s);
    } else if (ph.kind == ex::PhaseKind::sequence) {
      if (presenter) presenter->blank();
      event("sequence", "");
      monitor.event("sequence", {{"trial_number", trial_number}, {"t_s", detail::fixed(seconds_since(t0), 3)}});
      std::cout << "  " << q.wording.sequence_instruction << (q.nback ? " Press Enter to respond." : "") << " ("
                << detail::num(ph.duration_s) << " s)\n"
                << std::flush;
      r.presses = sequence_phase(presenter, q, ph.duration_s, event);
      if (q.nback)
        monitor.event("responses", {{"trial_number", trial_number}, {"items", [&] {
                                                                       std::string items;
                                                                       for (int i : r.presses)
                                                                         items += (items.empty() ? "" : ",") + std::to_string(i);
                                                                       return items.empty() ? std::string("none") : items;
                                                                     }()}});
      if (interactive()) std::cout << "\033[1A\r\033[J" << std::flush;  // hide the instruction again
    } else {
      if (presenter) presenter->blank();
      event("matrix", "");
      monitor.event("matrix", {{"trial_number", trial_number}, {"t_s", detail::fixed(seconds_since(t0), 3)}});
      std::cout << "  Remember this matrix (" << detail::num(ph.duration_s) << " s):\n";
      for (int row = 0; row < 4; ++row) {
        std::cout << "      ";
        for (int col = 0; col < 4; ++col) {
          const int d = (*q.matrix)[static_cast<std::size_t>(row * 4 + col)];
          std::cout << (d ? std::to_string(d) : std::string(".")) << "  ";
        }
        std::cout << "\n";
      }
      std::cout.flush();
      countdown_phase(presenter, ph.duration_s);
      if (interactive()) std::cout << "\033[5A\033[J" << std::flush;  // hide the matrix again
    }
    if (experiment_interrupted) return ended(StopReason::interrupt);
  }
  if (!q.phases.empty() && presenter) presenter->blank();

  std::cout << how_to_answer(q, two_d);
  if (q.phases.empty() && !q.stimuli.empty()) feel(0);

  double slider_p = q.sliders.empty() ? 0 : q.sliders[0].start, slider_i = q.sliders.size() < 2 ? 0 : q.sliders[1].start;
  Countdown countdown(q.time_limit_s, t0);
  bool time_up = false, need_prompt = true;
  for (;;) {
    if (need_prompt) countdown.prompt();
    need_prompt = true;
    bool timed_out = false;
    const double remaining = countdown.active() && !time_up ? std::max(1e-3, countdown.left_s()) : 0.0;
    const auto line = read_line(presenter, remaining, &timed_out, [&] { countdown.tick(); });
    if (timed_out) {
      time_up = true;
      need_prompt = false;  // the participant may be typing on this prompt
      if (presenter) presenter->blank();
      event("timeout", "");
      monitor.event("timeout", {{"trial_number", trial_number}, {"t_s", detail::fixed(seconds_since(t0), 3)}});
      countdown.time_up();
      continue;
    }
    if (!line) return ended(experiment_interrupted ? StopReason::interrupt : StopReason::end_of_input);
    countdown.entered(*line);
    const std::string cmd = trim(*line);
    if (cmd.empty()) continue;
    if (cmd == "q" || cmd == "quit") return ended(StopReason::quit);
    if (cmd == "h" || cmd == "help" || cmd == "?") {
      std::cout << how_to_answer(q, two_d);
      continue;
    }
    std::istringstream in(cmd);
    std::string verb, arg, extra;
    in >> verb >> arg >> extra;
    auto refuse = [&](const std::string& reason, const std::string& tell) {
      monitor.event("refused", {{"trial_number", trial_number}, {"input", cmd}, {"reason", reason}});
      std::cout << "  " << tell << "\n";
    };
    // Feel: a bare number, or 'f N' / 'feel N' (N a number or a label).
    std::optional<int> pick;
    if (whole_number(verb)) {
      pick = *whole_number(verb);
      arg = verb;
    } else if (verb == "f" || verb == "feel") {
      pick = whole_number(arg).value_or(0);
      for (std::size_t i = 0; i < q.stimuli.size() && !whole_number(arg); ++i)
        if (lower(q.stimuli[i].label) == lower(arg)) pick = static_cast<int>(i + 1);
    }
    if (pick) {
      if (!q.phases.empty())
        refuse("feel during recall", "The textures of this trial have been played; please answer.");
      else if (time_up)
        refuse("feel after time-out", "Time is up: please answer now.");
      else if (*pick >= 1 && *pick <= static_cast<int>(q.stimuli.size()) && extra.empty())
        feel(*pick - 1);
      else
        refuse("no such stimulus", "There is no texture '" + arg + "'. Type 'h' for help.");
      continue;
    }
    if ((verb == "p" || verb == "i") && q.sliders.size() >= 2) {
      const auto& spec = q.sliders[verb == "p" ? 0 : 1];
      const auto v = number(arg);
      if (!v || *v < spec.min || *v > spec.max) {
        refuse("slider out of range",
               "'" + verb + "' needs a number from " + detail::num(spec.min) + " to " + detail::num(spec.max) + ".");
        continue;
      }
      (verb == "p" ? slider_p : slider_i) = *v;
      event("slider", verb + "=" + arg);
      monitor.event("slider", {{"trial_number", trial_number}, {"name", spec.name}, {"value", detail::num(*v)}});
      if (presenter && !time_up) presenter->show(session.preview_document(slider_p, slider_i));
      std::cout << "  " << spec.label << " set to " << detail::num(*v) << (time_up ? "." : "; now playing your rendering.")
                << "\n";
      continue;
    }
    if (verb != "a" && verb != "answer") {
      refuse("unknown command", "Sorry, '" + cmd + "' is not a command. Type 'h' for help.");
      continue;
    }
    // An answer: checked against the question here, so a typo costs nothing.
    r.choice.clear();
    r.rating.reset();
    if (!q.choices.empty()) {
      std::string found;
      for (const auto& c : q.choices)
        if (lower(c) == lower(arg)) found = c;
      std::vector<std::string> examples;
      for (const auto& c : q.choices) examples.push_back("'a " + c + "'");
      if (found.empty() || !extra.empty()) {
        refuse("not a choice", "That is not a valid answer: answer with " + spoken_list(examples) + ".");
        continue;
      }
      r.choice = found;
    }
    if (q.rating_scale) {
      const auto v = whole_number(arg);
      if (!v || *v < (*q.rating_scale)[0] || *v > (*q.rating_scale)[1] || !extra.empty()) {
        refuse("not on the scale", "That is not a valid answer: type 'a' and a whole number from " +
                                       detail::num((*q.rating_scale)[0]) + " to " + detail::num((*q.rating_scale)[1]) + ".");
        continue;
      }
      r.rating = *v;
    }
    if (!q.sliders.empty()) {
      r.slider_p = slider_p;
      r.slider_i = slider_i;
    }
    const double rt = seconds_since(t0) * 1000.0;  // from the first stimulus onset (shown with the question)
    if (presenter) {
      presenter->blank();
      r.trace = presenter->take_trace();  // the finger that explored, stored with the trial
    }
    if (two_d) {
      r.strokes = presenter->strokes(q);  // stored with the trial; the experimenter's monitor gets each interval
      for (std::size_t k = 0; k < r.strokes.size(); ++k) {
        const ex::IntervalStrokes& st = r.strokes[k];
        monitor.event("strokes", {{"trial_number", trial_number},
                                  {"stimulus", std::to_string(k + 1)},
                                  {"instructed_deg", fixed1(st.instructed_deg)},
                                  {"strokes", std::to_string(st.strokes)},
                                  {"direction_deg", fixed1(st.direction_deg)},
                                  {"deviation_deg", fixed1(st.deviation_deg)},
                                  {"straightness", std::isfinite(st.straightness) ? detail::fixed(st.straightness, 2) : ""},
                                  {"mean_speed_mm_s", fixed1(st.mean_speed_mm_s)},
                                  {"path_mm", fixed1(st.path_mm)},
                                  {"compliant", st.compliant ? "1" : "0"}});
      }
    }
    if (q.confidence) {
      const ex::Scale& s = *q.wording.confidence;
      const auto c = ask_number(presenter, s.question + " " + scale_words(s), s.min, s.max, stop);
      if (!c) return ended(stop);
      r.confidence = *c;
    }
    if (q.recall) {
      const ex::Scale& s = *q.wording.recall;
      const auto d = ask_number(presenter, s.question + " (" + scale_words(s) + ")", s.min, s.max, stop);
      if (!d) return ended(stop);
      r.digit = *d;
    }
    r.rt_ms = std::round(rt);
    r.answered_at = ex::utc_timestamp();
    event("answer", arg);
    monitor.event("answer", {{"trial_number", trial_number},
                             {"response", !q.choices.empty() ? r.choice
                                          : r.rating         ? detail::num(*r.rating)
                                                             : std::string()},
                             {"slider_p", r.slider_p ? detail::num(*r.slider_p) : std::string()},
                             {"slider_i", r.slider_i ? detail::num(*r.slider_i) : std::string()},
                             {"confidence", r.confidence ? detail::num(*r.confidence) : std::string()},
                             {"digit", r.digit ? std::to_string(*r.digit) : std::string()},
                             {"rt_ms", detail::num(r.rt_ms)},
                             {"after_time_limit", time_up ? "1" : "0"}});
    return r;
  }
}

}  // namespace texel::cli
