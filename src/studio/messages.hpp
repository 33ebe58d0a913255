// The studio's message table and what its handlers share (internal to
// texel_studio; docs/studio.md "Messages", docs/schema/studio-messages.schema.json).
//
// One row per client message type: {type, lane, allowed keys, handler}. The
// service (service.cpp) routes by it, refuses unknown types and keys from it,
// and tests/studio checks it against the JSON Schema the front end's message
// types are generated from. Handlers live in files by concern:
// handlers_design.cpp (hello, design), handlers_codec.cpp (match, import,
// export), handlers_feel.cpp (feel.*), handlers_experiment.cpp (experiment.*),
// handlers_surface2d.cpp (surface2d.*, feel2d.*).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/document.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/studio/design.hpp"
#include "texel/studio/handler.hpp"
#include "texel/studio/service.hpp"

namespace texel::studio::detail {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

inline constexpr std::size_t max_queued_jobs = 64;  // per client, both lanes
inline constexpr std::size_t max_nesting = 64;      // JSON depth
inline constexpr std::size_t max_id_chars = 64;
inline constexpr std::size_t max_name_chars = 255;          // file names, participant codes, protocol names
inline constexpr std::size_t max_trace_samples = 1u << 18;  // finger samples kept per trial for swipe measures
inline constexpr double max_abs_mm = 1e6;
// feel.move's times (the page's PointerEvent.timeStamp, ms; docs/studio.md "Feel it"):
inline constexpr std::size_t max_coalesced = 64;  // earlier samples of one pointer event
inline constexpr double max_t_ms = 1e12;          // ~31 years of a page's clock
inline constexpr double max_ahead_ms = 100.0;     // how far a page's clock may run ahead of the studio's between messages

/// A refused message: the error code and one line naming field, value, allowed.
struct Reject {
  std::string code;
  std::string message;
};

/// A client-supplied text in an error message: quoted, at most 64 characters.
std::string clipped(std::string_view s);

/// Typed reads of one message's keys, each a one-line Reject naming the key
/// (unknown keys are refused from the table before a handler runs).
class Fields {
 public:
  Fields(const json& msg, std::string type) : msg_(msg), type_(std::move(type)) {}
  [[nodiscard]] bool has(const char* key) const { return msg_.contains(key) && !msg_[key].is_null(); }
  [[nodiscard]] const json& raw(const char* key) const;
  [[nodiscard]] const json& object(const char* key) const;
  [[nodiscard]] double number(const char* key, double lo, double hi) const;
  [[nodiscard]] std::int64_t integer(const char* key, std::int64_t lo, std::int64_t hi) const;
  [[nodiscard]] bool boolean(const char* key, bool fallback) const;
  [[nodiscard]] std::string string(const char* key, std::size_t max_chars) const;

 private:
  [[nodiscard]] Reject wrong(const char* key, const char* want, const json& v) const;
  const json& msg_;
  std::string type_;
};

/// One client message on its way to a handler.
struct Job {
  std::string type;
  json msg;
  json id;
  Clock::time_point received;
};

/// A connected browser: its sink, rate bucket and queued work.
struct Client {
  std::uint64_t id = 0;
  Sink sink;
  std::mutex send_mutex;  // held while the sink runs; disconnect() waits on it
  bool open = true;       // guarded by send_mutex
  // Guarded by the service's lane mutex:
  double tokens = 0.0;
  Clock::time_point refilled = Clock::now();
  std::map<std::string, std::pair<std::uint64_t, Job>> slots;  // design lane: type → (order, newest job)
  std::size_t fifo_jobs = 0;
  // Touched by the FIFO worker only:
  bool participant_screen = false;  // asked experiment.current with screen: true (its hand-outs start trial clocks)
  // The page's pointer clock (feel.move t_ms), guarded by State::feel_mutex: one
  // connection is one page, so one clock, which never goes back.
  double pointer_t_ms = -1.0;  // its newest sample's time (−1: none yet)
  // Least (arrival − t_ms) seen, ms: a sample cannot arrive before it was taken,
  // so one arriving with less lag than that (beyond max_ahead_ms) comes from a
  // clock running ahead (none yet: +inf).
  double pointer_lag_ms = std::numeric_limits<double>::infinity();
};

struct Surface2DState;  // handlers_surface2d.hpp: the prepared 2-D surface and the 2-D pad's player
std::shared_ptr<Surface2DState> make_surface2d_state();
struct Strokes2DState;  // handlers_experiment.cpp: the participant's strokes of a 2-D trial
std::shared_ptr<Strokes2DState> make_strokes2d_state();

/// What the handlers share: the options, the display (one Presenter behind
/// feel_mutex) and the experiment session (touched by the FIFO worker only).
struct State {
  ServiceOptions options;
  ojson hello;

  std::mutex feel_mutex;
  std::unique_ptr<experiment::Presenter> presenter;
  // The configured backend is one device, played by the Presenter (Feel-it
  // strip, participant screens) or by the 2-D pad's player, never both
  // (handlers_surface2d.cpp "The device"). Guarded by feel_mutex.
  experiment::PresenterOptions presenter_options;  // the configured device's
  bool device_shared = false;                      // not null: the 2-D pad borrows the device
  bool feel2d_holds_device = false;                // the Presenter runs on a null backend meanwhile
  std::string device_description;                  // the configured backend, as opened at start
  std::string device_error;                        // the device could not be re-opened at a hand-over
  std::unique_ptr<const PlayerMap> feel_map;       // the last Feel-it map, shown again when the device comes back
  std::uint64_t finger_client = 0;                 // who touched last (lifted on disconnect)
  double finger_x = 0.0;
  bool finger_down = false;
  // Finger samples of the current trial for its swipe measures, each at its
  // page's own time (feel.move t_ms, s), never its arrival; a stroke from
  // another page starts after a lift (its clock is another).
  std::vector<FingerSample> trace;
  std::uint64_t trace_client = 0;  // whose clock the trace's newest sample is on
  // Added to that page's times (ms): a page taking over the trace starts where the last one ended
  // (after a lift), so the stored trace's time never runs backwards across two pages' clocks.
  double trace_offset_ms = 0.0;

  std::shared_ptr<Surface2DState> surface2d = make_surface2d_state();  // its own mutexes
  std::shared_ptr<Strokes2DState> strokes2d = make_strokes2d_state();  // FIFO worker only

  std::optional<experiment::Store> store;
  std::optional<experiment::ActiveSession> active;
  /// Sends `make(participant_screen)` (no id) to every connected client but
  /// `except` (set by the service; runs on the FIFO worker): participant
  /// screens follow suspend, stop, switch and answers.
  std::function<void(const std::function<ojson(bool participant_screen)>& make, std::uint64_t except)> broadcast;
};

inline double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// ------------------------------------------------------------------ replies
void send(Client& c, const ojson& reply);
ojson reply(const char* type, const json& id);

// ------------------------------------------------ helpers of several handlers
/// A client's document: built-in devices only, map and texel count capped.
Document document_of(const State& s, const json& j, const std::string& where);
/// An optional region index key (0 … 1023).
std::optional<std::size_t> region_field(const Fields& f, const char* key);
/// Throws a Reject unless `name` is a built-in device.
void require_builtin_device(std::string_view name, const std::string& what);
/// {frequency_cpm, magnitude_db} of a plotted spectrum.
ojson spectrum_json(const SpectrumView& s);
/// Lower-case hex of bytes (encoded bitstreams).
std::string hex(std::span<const std::byte> bytes);
/// The hello reply without its id (built once).
ojson make_hello(const State& s);
/// Lifts the finger if `client` was the one touching.
void lift_finger(State& s, std::uint64_t client);
/// The same for the 2-D pad's player.
void lift_finger_2d(State& s, std::uint64_t client);
/// Caller holds feel_mutex: if the 2-D pad plays on the configured device,
/// ramps it out and gives the device back to the Presenter (which shows the
/// last Feel-it map again). Never throws: a device that cannot be re-opened
/// leaves the Presenter on a null backend and says why in device_error.
void device_to_presenter(State& s);
/// A participant's 2-D interval on the 2-D pad's player (the participant
/// page strokes it; handlers_experiment.cpp). Caller holds feel_mutex.
/// pad_show takes the device as the pad's touch does and plays `map`;
/// pad_push queues one finger sample at player time `t` (nothing unless a
/// participant's interval plays; returns the time queued, nothing when the
/// queue is full); pad_blank lifts the finger and fades to silence.
void pad_show(State& s, std::unique_ptr<const PlayerMap2D> map);
std::optional<double> pad_push(State& s, std::uint64_t client, double t, double x, double y, bool touch);
[[nodiscard]] double pad_time_s(const State& s);
void pad_blank(State& s);
/// Caller holds feel_mutex: the Presenter on the configured device with
/// `channels` output channels (a study's device with N actuators, a
/// multi-actuator document felt on the strip). Re-opens it when the count
/// differs; a device that cannot open them is refused (Reject naming
/// `what`, the count and the device's reason) and the Presenter stays as
/// it was. The 2-D pad gives the device back first.
void presenter_channels(State& s, std::size_t channels, const std::string& what);
/// The Presenter's options for the configured device (or a null backend in its place).
experiment::PresenterOptions presenter_options(const ServiceOptions& o, bool null_backend = false);

// -------------------------------------------------------------------- table
/// When a message is handled: before handle() returns; on the design lane
/// (one slot per client and type, latest wins); on the FIFO lane, in order.
enum class Lane { now, design, fifo };

using Handler = void (*)(State&, Client&, const Job&);

struct MessageSpec {
  std::string_view type;
  Lane lane;
  std::initializer_list<std::string_view> keys;  ///< allowed besides type and id
  Handler handler;
};

/// Every client message type, in the order error messages list them.
std::span<const MessageSpec> message_table();
/// The row of `type`, or nullptr.
const MessageSpec* find_message(std::string_view type);
/// Refuses keys of `msg` that the row does not allow (one line naming them).
void check_keys(const MessageSpec& spec, const json& msg);

// Handlers, by file.
void on_hello(State&, Client&, const Job&);
void on_design(State&, Client&, const Job&);
void on_match(State&, Client&, const Job&);
void on_import(State&, Client&, const Job&);
void on_export(State&, Client&, const Job&);
void on_feel_select(State&, Client&, const Job&);
void on_feel_move(State&, Client&, const Job&);
void on_feel_state(State&, Client&, const Job&);
void on_experiment_list(State&, Client&, const Job&);
void on_experiment_stations(State&, Client&, const Job&);
void on_experiment_start(State&, Client&, const Job&);
void on_experiment_current(State&, Client&, const Job&);
void on_experiment_select(State&, Client&, const Job&);
void on_experiment_preview(State&, Client&, const Job&);
void on_experiment_answer(State&, Client&, const Job&);
void on_experiment_stop(State&, Client&, const Job&);
void on_experiment_trials(State&, Client&, const Job&);
void on_experiment_export(State&, Client&, const Job&);
void on_experiment_protocol(State&, Client&, const Job&);
void on_experiment_validate(State&, Client&, const Job&);
void on_experiment_suspend(State&, Client&, const Job&);
void on_experiment_resume(State&, Client&, const Job&);
void on_experiment_stroke(State&, Client&, const Job&);
void on_surface2d_view(State&, Client&, const Job&);
void on_surface2d_scan(State&, Client&, const Job&);
void on_feel2d_select(State&, Client&, const Job&);
void on_feel2d_move(State&, Client&, const Job&);
void on_feel2d_state(State&, Client&, const Job&);
void on_feel2d_raster(State&, Client&, const Job&);

}  // namespace texel::studio::detail
