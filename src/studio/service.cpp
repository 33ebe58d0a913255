// Texel Studio's message service (service.hpp, docs/studio.md "Messages").
//
// Shape: handle() checks size and rate, parses, validates the envelope and
// the message's keys and types, then either answers at once (hello, finger
// samples, backend state) or queues a job on one of two lanes:
//   design lane  per client one slot per kind (design, feel.select), newest
//                wins; clients served round robin;
//   FIFO lane    match, import, export and experiment steps, in order.
// Each lane has one worker thread, so a client's messages stay in order
// within a lane and a long match never delays a slider's redraw. Every
// number comes from the library (design.hpp, the experiment runner, the
// Presenter); this file parses and formats.
//
// Hostile input: sizes are checked before parsing, nesting depth before
// nlohmann recurses into it, device names must be built-in (a document's
// "device" may otherwise name a file), maps and texel counts are capped
// before anything is rendered, and library exceptions become error replies.
#include "texel/studio/service.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "base64.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/finger.hpp"
#include "texel/player.hpp"
#include "texel/reference.hpp"
#include "texel/studio/design.hpp"

#ifndef TEXEL_VERSION
#define TEXEL_VERSION "unknown"
#endif

namespace texel::studio {
namespace {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;
namespace ex = texel::experiment;

constexpr std::size_t max_queued_jobs = 64;  // per client, both lanes
constexpr std::size_t max_nesting = 64;      // JSON depth
constexpr std::size_t max_id_chars = 64;
constexpr std::size_t max_name_chars = 255;          // file names, participant codes, protocol names
constexpr std::size_t max_trace_samples = 1u << 18;  // finger samples kept per trial for swipe measures
constexpr double max_abs_mm = 1e6;

/// A refused message: the error code and one line naming field, value, allowed.
struct Reject {
  std::string code;
  std::string message;
};

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// A client-supplied text in an error message: quoted, at most 64 characters.
std::string clipped(std::string_view s) {
  std::string q(s.substr(0, 64));
  return "'" + q + (s.size() > 64 ? "…" : "") + "'";
}

// Deepest nesting of arrays/objects, scanning outside strings; stops early.
std::size_t nesting_depth(std::string_view text, std::size_t limit) {
  std::size_t depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

const char* type_name(const json& j) { return j.type_name(); }

/// The keys of one message: refuses unknown ones and checks each value.
class Fields {
 public:
  Fields(const json& msg, std::string type, std::initializer_list<std::string_view> allowed) : msg_(msg), type_(std::move(type)) {
    for (const auto& [key, value] : msg.items()) {
      if (key == "type" || key == "id") continue;
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string list = "type, id";
        for (const auto a : allowed) list += ", " + std::string(a);
        throw Reject{"bad_message", type_ + ": unknown key " + clipped(key) + "; allowed: " + list};
      }
    }
  }
  [[nodiscard]] bool has(const char* key) const { return msg_.contains(key) && !msg_[key].is_null(); }
  [[nodiscard]] const json& raw(const char* key) const {
    if (!has(key)) throw Reject{"bad_message", type_ + ": missing '" + key + "'"};
    return msg_[key];
  }
  [[nodiscard]] const json& object(const char* key) const {
    const json& v = raw(key);
    if (!v.is_object()) throw wrong(key, "an object", v);
    return v;
  }
  [[nodiscard]] double number(const char* key, double lo, double hi) const {
    const json& v = raw(key);
    if (!v.is_number()) throw wrong(key, "a number", v);
    const double d = v.get<double>();
    if (!(d >= lo && d <= hi))
      throw Reject{"invalid", type_ + ": " + key + " is " + v.dump() + "; allowed: " + num(lo) + " … " + num(hi)};
    return d;
  }
  [[nodiscard]] std::int64_t integer(const char* key, std::int64_t lo, std::int64_t hi) const {
    const json& v = raw(key);
    if (!v.is_number_integer()) throw wrong(key, "an integer", v);
    const bool fits = v.is_number_unsigned() ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi) : true;
    const std::int64_t i = fits ? v.get<std::int64_t>() : hi;
    if (!fits || i < lo || i > hi)
      throw Reject{"invalid",
                   type_ + ": " + key + " is " + v.dump() + "; allowed: " + std::to_string(lo) + " … " + std::to_string(hi)};
    return i;
  }
  [[nodiscard]] bool boolean(const char* key, bool fallback) const {
    if (!has(key)) return fallback;
    const json& v = msg_[key];
    if (!v.is_boolean()) throw wrong(key, "true or false", v);
    return v.get<bool>();
  }
  [[nodiscard]] std::string string(const char* key, std::size_t max_chars) const {
    const json& v = raw(key);
    if (!v.is_string()) throw wrong(key, "a string", v);
    const auto& s = v.get_ref<const std::string&>();
    if (s.size() > max_chars)
      throw Reject{"invalid", type_ + ": " + key + " has " + std::to_string(s.size()) + " characters; allowed: at most " +
                                  std::to_string(max_chars)};
    return s;
  }

 private:
  static std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }
  [[nodiscard]] Reject wrong(const char* key, const char* want, const json& v) const {
    return Reject{"bad_message", type_ + ": " + key + " must be " + want + ", got " + type_name(v)};
  }
  const json& msg_;
  std::string type_;
};

ojson spectrum_json(const SpectrumView& s) { return ojson{{"frequency_cpm", s.frequency_cpm}, {"magnitude_db", s.magnitude_db}}; }

std::string hex(std::span<const std::byte> bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string h;
  for (const std::byte b : bytes) {
    h += digits[std::to_integer<unsigned>(b) >> 4];
    h += digits[std::to_integer<unsigned>(b) & 15];
  }
  return h;
}

ojson encode_json(const codec::EncodeResult& r) {
  return ojson{{"bytes", r.bytes.size()},
               {"hex", hex(r.bytes)},
               {"model_distance", r.model_distance},
               {"central_pitch_db", r.spec.central_pitch.value()},
               {"irregularity_db", r.spec.irregularity.value()},
               {"texel_length_mm", r.spec.texel_length.value()},
               {"coarse", r.coarse},
               {"texel_recovered", r.texel_recovered},
               {"seconds", r.seconds}};
}

ojson reference_param_json(const ReferenceParam& p) {
  static constexpr const char* kinds[] = {"number", "integer", "list", "choice"};
  ojson j{{"key", p.key}, {"kind", kinds[static_cast<int>(p.kind)]}, {"unit", p.unit}, {"description", p.description}};
  std::visit([&](const auto& v) { j["default"] = v; }, p.default_value);
  if (p.kind == ReferenceParamKind::choice) {
    j["choices"] = p.choices;
  } else {
    j["min"] = p.min;
    j["max"] = p.max;
  }
  if (p.kind == ReferenceParamKind::list) {
    j["min_count"] = p.min_count;
    j["max_count"] = p.max_count;
  }
  return j;
}

// What participant screens may see of a question (the library's participant view).
ojson participant_question(const ex::Question& q) { return ojson::parse(q.participant_json()); }

}  // namespace

struct Service::Impl {
  struct Job {
    std::string type;
    json msg;
    json id;
    Clock::time_point received;
  };

  struct Client {
    std::uint64_t id = 0;
    Sink sink;
    std::mutex send_mutex;  // held while the sink runs; disconnect() waits on it
    bool open = true;       // guarded by send_mutex
    // Guarded by Impl::mutex:
    double tokens = 0.0;
    Clock::time_point refilled = Clock::now();
    std::map<std::string, std::pair<std::uint64_t, Job>> slots;  // design lane: kind → (order, newest job)
    std::size_t fifo_jobs = 0;
  };

  ServiceOptions options;
  std::string version = TEXEL_VERSION;

  // The display: one Presenter, control-thread API behind feel_mutex.
  std::mutex feel_mutex;
  std::unique_ptr<ex::Presenter> presenter;
  std::uint64_t finger_client = 0;  // who touched last (lifted on disconnect)
  double finger_x = 0.0;
  bool finger_down = false;
  std::vector<FingerSample> trace;  // finger samples of the current trial (swipe measures)

  // Clients and lanes, behind `mutex`.
  std::mutex mutex;
  std::condition_variable wake;
  bool stopping = false;
  std::uint64_t next_client = 1;
  std::uint64_t next_order = 1;
  std::map<std::uint64_t, std::shared_ptr<Client>> clients;
  std::deque<std::uint64_t> design_turns;  // clients with a filled slot, round robin
  std::deque<std::pair<std::shared_ptr<Client>, Job>> fifo;

  // Experiments: touched by the FIFO worker only.
  std::optional<ex::Store> store;
  std::optional<ex::ActiveSession> active;

  ojson hello;
  std::thread design_worker, fifo_worker;

  explicit Impl(ServiceOptions o) : options(std::move(o)) {
    if (!(options.max_message_bytes >= 1024 && options.max_message_bytes <= (std::size_t{1} << 30)))
      throw InvalidArgument("max_message_bytes is " + std::to_string(options.max_message_bytes) + "; allowed: 1024 … 2^30");
    if (!(options.max_messages_per_s >= 1 && options.max_messages_per_s <= 1e6))
      throw InvalidArgument("max_messages_per_s is " + std::to_string(options.max_messages_per_s) + "; allowed: 1 … 1e6");
    ex::PresenterOptions po;
    po.backend = options.backend;
    po.audio_device = options.audio_device;
    po.finger = ex::FingerSource::external;
    po.response_handling = parse_response_handling(options.response, "response");
    presenter = std::make_unique<ex::Presenter>(po);
    hello = make_hello();
    design_worker = std::thread([this] { run_design_lane(); });
    fifo_worker = std::thread([this] { run_fifo_lane(); });
  }

  ~Impl() {
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    wake.notify_all();
    design_worker.join();
    fifo_worker.join();
    active.reset();  // releases the writer lock: the session stays resumable
    presenter->stop();
  }

  ojson make_hello() const {
    ojson h{{"type", "hello"}, {"version", version}, {"backend", presenter->describe()}};
    h["devices"] = ojson::array();
    for (const auto& name : builtin_device_names()) h["devices"].push_back(ojson::parse(device_profile_json(load_device(name))));
    h["references"] = ojson::array();
    for (const auto& info : reference_catalogue()) {
      ojson r{{"name", info.name}, {"family", info.family}, {"description", info.description}, {"uses_seed", info.uses_seed}};
      r["parameters"] = ojson::array();
      for (const auto& p : info.params) r["parameters"].push_back(reference_param_json(p));
      h["references"].push_back(std::move(r));
    }
    h["parameterizations"] = {"moments", "log"};
    h["export_formats"] = {"document", "bitstream", "device", "npy", "csv"};
    h["import_extensions"] = {".texel.json", ".json", ".texel", ".bin", ".npy", ".csv", ".wav"};
    h["limits"] = {{"max_message_bytes", options.max_message_bytes},
                   {"max_messages_per_s", options.max_messages_per_s},
                   {"max_queued_jobs", max_queued_jobs},
                   {"max_map_samples", options.max_map_samples},
                   {"max_name_chars", max_name_chars}};
    return h;
  }

  // ------------------------------------------------------------- replies

  static void send(Client& c, const ojson& reply) {
    std::string text = reply.dump(-1, ' ', false, ojson::error_handler_t::replace);
    std::lock_guard lock(c.send_mutex);
    if (c.open) c.sink(std::move(text));
  }

  static ojson reply(const char* type, const json& id) {
    ojson r{{"type", type}};
    r["id"] = id;
    return r;
  }

  static void send_error(Client& c, const json& id, const std::string& code, const std::string& message) {
    ojson r = reply("error", id);
    r["code"] = code;
    r["message"] = message;
    send(c, r);
  }

  // Runs `work`, turning every exception into an error reply.
  template <typename F>
  static void guarded(Client& c, const json& id, F&& work) {
    try {
      work();
    } catch (const Reject& r) {
      send_error(c, id, r.code, r.message);
    } catch (const InvalidArgument& e) {
      send_error(c, id, "invalid", e.what());
    } catch (const FormatError& e) {
      send_error(c, id, "invalid", e.what());
    } catch (const IoError& e) {
      send_error(c, id, "internal", e.what());
    } catch (const Error& e) {
      send_error(c, id, "invalid", e.what());
    } catch (const std::bad_alloc&) {
      send_error(c, id, "too_large", "out of memory while handling the message");
    } catch (const std::exception& e) {
      send_error(c, id, "internal", e.what());
    }
  }

  // ------------------------------------------------------------ handling

  std::shared_ptr<Client> find(std::uint64_t id) {
    std::lock_guard lock(mutex);
    const auto it = clients.find(id);
    return it == clients.end() ? nullptr : it->second;
  }

  bool take_token(Client& c) {
    std::lock_guard lock(mutex);
    const auto now = Clock::now();
    const double rate = options.max_messages_per_s;
    c.tokens = std::min(rate, c.tokens + rate * std::chrono::duration<double>(now - c.refilled).count());
    c.refilled = now;
    if (c.tokens < 1.0) return false;
    c.tokens -= 1.0;
    return true;
  }

  void handle(std::uint64_t client_id, std::string_view text) {
    const auto c = find(client_id);
    if (!c) return;  // unknown or gone: nobody to answer
    json id;
    guarded(*c, id, [&] {
      if (!take_token(*c))
        throw Reject{"rate_limited", "more than " + std::to_string(static_cast<long long>(options.max_messages_per_s)) +
                                         " messages per second; slow down"};
      if (text.size() > options.max_message_bytes)
        throw Reject{"too_large", "message has " + std::to_string(text.size()) + " bytes; allowed: at most " +
                                      std::to_string(options.max_message_bytes)};
      if (nesting_depth(text, max_nesting) > max_nesting)
        throw Reject{"bad_json", "message nests deeper than " + std::to_string(max_nesting) + " levels"};
      json msg = json::parse(text, nullptr, false);
      if (msg.is_discarded()) throw Reject{"bad_json", "message is not valid JSON"};
      if (!msg.is_object()) throw Reject{"bad_message", std::string("message must be a JSON object, got ") + type_name(msg)};
      if (msg.contains("id")) {
        const json& i = msg["id"];
        const bool ok = (i.is_number_integer()) || (i.is_string() && i.get_ref<const std::string&>().size() <= max_id_chars);
        if (!ok) throw Reject{"bad_message", "id must be an integer or a string of at most 64 characters"};
        id = i;
      }
      if (!msg.contains("type") || !msg["type"].is_string()) throw Reject{"bad_message", "message needs a string 'type'"};
      const std::string type = msg["type"].get<std::string>();
      dispatch(c, type, std::move(msg), id);
    });
  }

  void dispatch(const std::shared_ptr<Client>& c, const std::string& type, json msg, const json& id) {
    if (type == "hello") {
      (void)Fields(msg, type, {});
      ojson r = hello;
      r["id"] = id;
      send(*c, r);
    } else if (type == "feel.move") {
      feel_move(*c, msg, id);
    } else if (type == "feel.state") {
      feel_state(*c, msg, id);
    } else if (type == "design" || type == "feel.select") {
      if (type == "design")
        (void)Fields(msg, type, {"document", "region", "bins"});
      else
        (void)Fields(msg, type, {"document"});
      enqueue_design_lane(c, Job{type, std::move(msg), id, Clock::now()});
    } else if (type == "match" || type == "import" || type == "export" || type.rfind("experiment.", 0) == 0) {
      static const std::vector<std::string> fifo_types = {"match",
                                                          "import",
                                                          "export",
                                                          "experiment.list",
                                                          "experiment.start",
                                                          "experiment.current",
                                                          "experiment.select",
                                                          "experiment.preview",
                                                          "experiment.answer",
                                                          "experiment.stop"};
      if (std::find(fifo_types.begin(), fifo_types.end(), type) == fifo_types.end()) unknown_type(type);
      enqueue_fifo(c, Job{type, std::move(msg), id, Clock::now()});
    } else {
      unknown_type(type);
    }
  }

  [[noreturn]] static void unknown_type(const std::string& type) {
    throw Reject{"bad_message", "unknown message type " + clipped(type) +
                                    "; allowed: hello, design, match, import, export, feel.select, feel.move, feel.state, "
                                    "experiment.list, experiment.start, experiment.current, experiment.select, "
                                    "experiment.preview, experiment.answer, experiment.stop"};
  }

  void enqueue_design_lane(const std::shared_ptr<Client>& c, Job job) {
    {
      std::lock_guard lock(mutex);
      auto it = c->slots.find(job.type);
      if (it != c->slots.end()) {
        it->second.second = std::move(job);  // latest wins; keeps its place in the order
        return;
      }
      if (c->slots.size() + c->fifo_jobs >= max_queued_jobs) throw busy();
      if (c->slots.empty()) design_turns.push_back(c->id);
      std::string kind = job.type;  // not job.type itself: the job is moved from in the same call
      c->slots.emplace(std::move(kind), std::make_pair(next_order++, std::move(job)));
    }
    wake.notify_all();
  }

  void enqueue_fifo(const std::shared_ptr<Client>& c, Job job) {
    {
      std::lock_guard lock(mutex);
      if (c->slots.size() + c->fifo_jobs >= max_queued_jobs) throw busy();
      ++c->fifo_jobs;
      fifo.emplace_back(c, std::move(job));
    }
    wake.notify_all();
  }

  static Reject busy() {
    return Reject{"busy", "more than " + std::to_string(max_queued_jobs) + " messages queued; wait for replies"};
  }

  void run_design_lane() {
    std::unique_lock lock(mutex);
    while (true) {
      wake.wait(lock, [&] { return stopping || !design_turns.empty(); });
      if (stopping) return;
      const std::uint64_t cid = design_turns.front();
      design_turns.pop_front();
      const auto it = clients.find(cid);
      if (it == clients.end() || it->second->slots.empty()) continue;
      const std::shared_ptr<Client> c = it->second;
      auto first = std::min_element(c->slots.begin(), c->slots.end(),
                                    [](const auto& a, const auto& b) { return a.second.first < b.second.first; });
      Job job = std::move(first->second.second);
      c->slots.erase(first);
      if (!c->slots.empty()) design_turns.push_back(cid);
      lock.unlock();
      guarded(*c, job.id, [&] { job.type == "design" ? design(*c, job) : feel_select(*c, job); });
      pump();
      lock.lock();
    }
  }

  void run_fifo_lane() {
    std::unique_lock lock(mutex);
    while (true) {
      wake.wait(lock, [&] { return stopping || !fifo.empty(); });
      if (stopping) return;
      const std::shared_ptr<Client> c = std::move(fifo.front().first);
      const Job job = std::move(fifo.front().second);
      fifo.pop_front();
      --c->fifo_jobs;
      lock.unlock();
      guarded(*c, job.id, [&] { run_fifo_job(*c, job); });
      pump();
      lock.lock();
    }
  }

  void pump() {
    std::lock_guard lock(feel_mutex);
    presenter->pump();
  }

  // -------------------------------------------------------------- design

  // A client's document: built-in devices only (a device name may be a path
  // to any file), and a map and texel count the service will render. The
  // caps are checked on the JSON before parse_document, which prepares every
  // texture to validate it (a 1 nm texel length would mean 10^8 texels).
  Document document_of(const json& j, const std::string& where) const {
    if (!j.is_object()) throw Reject{"bad_message", where + " must be a document object, got " + type_name(j)};
    std::optional<DeviceProfile> device;
    if (j.contains("device") && j["device"].is_string()) {
      const auto names = builtin_device_names();
      const auto& name = j["device"].get_ref<const std::string&>();
      if (std::find(names.begin(), names.end(), name) == names.end()) {
        std::string list;
        for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
        throw Reject{"invalid", where + ".device is " + clipped(name) + "; allowed: " + list + " or an inline profile"};
      }
      device = load_device(name);
    } else if (j.contains("device") && j["device"].is_object()) {
      device = parse_device_profile(j["device"].dump(), where + ".device");
    }
    if (device && j.contains("device_grid") && j["device_grid"].is_object()) {
      const json& g = j["device_grid"];
      auto opt = [&](const char* k) {
        return g.contains(k) && g[k].is_number() ? std::optional(g[k].get<double>()) : std::nullopt;
      };
      device = with_grid(*device, millimetres(opt("length_mm")), millimetres(opt("spacing_mm")));
    }
    if (device) check_cost(j, *device, where);
    return parse_document(j.dump(), where);
  }

  void check_cost(const json& j, const DeviceProfile& device, const std::string& where) const {
    const auto cap = options.max_map_samples;
    if (static_cast<double>(device.samples) > static_cast<double>(cap))
      throw Reject{"too_large",
                   where + ".device has " + std::to_string(device.samples) + " samples; allowed: at most " + std::to_string(cap)};
    std::vector<const json*> textures;
    if (j.contains("texture")) textures.push_back(&j["texture"]);
    if (j.contains("regions") && j["regions"].is_array())
      for (const auto& r : j["regions"])
        if (r.is_object() && r.contains("texture")) textures.push_back(&r["texture"]);
    for (const json* t : textures) {
      if (!t->is_object() || !t->contains("texel_length_mm") || !(*t)["texel_length_mm"].is_number()) continue;
      const double length = (*t)["texel_length_mm"].get<double>();
      if (length > 0 && device.length().value() / length > static_cast<double>(cap))
        throw Reject{"too_large", where + ": texel_length_mm " + json(length).dump() + " makes more than " + std::to_string(cap) +
                                      " texels; allowed: at least " +
                                      json(device.length().value() / static_cast<double>(cap)).dump() + " mm on this device"};
    }
  }

  static std::optional<std::size_t> region_field(const Fields& f, const char* key) {
    if (!f.has(key)) return std::nullopt;
    return static_cast<std::size_t>(f.integer(key, 0, 1023));
  }

  void design(Client& c, const Job& job) {
    const auto t0 = Clock::now();
    const Fields f(job.msg, job.type, {"document", "region", "bins"});
    DesignOptions o;
    o.region = region_field(f, "region");
    if (f.has("bins")) o.histogram_bins = static_cast<std::size_t>(f.integer("bins", 0, 1000));
    const Document doc = document_of(f.object("document"), "document");
    const DesignView v = design_view(doc, o);

    ojson r = reply("design", job.id);
    r["grid"] = {{"origin_mm", v.grid.origin.value()}, {"spacing_mm", v.grid.spacing.value()}, {"count", v.grid.count}};
    static_assert(std::endian::native == std::endian::little, "map_f32 is little-endian float32");
    r["map_f32"] =
        detail::base64_encode(std::span(reinterpret_cast<const unsigned char*>(v.map.data()), v.map.size() * sizeof(float)));
    r["regions"] = ojson::array();
    for (const auto& g : v.regions)
      r["regions"].push_back(
          {{"name", g.name}, {"kind", g.kind}, {"start_mm", g.start.value()}, {"length_mm", g.length.value()}});
    r["region"] = v.analysed;
    r["spectrum"] = spectrum_json(v.spectrum);
    if (v.regions[v.analysed].kind == "texel") {
      r["histogram"] = {{"edges_cpm", v.histogram.edges_cpm}, {"counts", v.histogram.counts}, {"pdf", v.histogram.expected}};
      r["encoded"] = v.encoded_error.empty() ? ojson{{"bytes", v.encoded.size()}, {"hex", hex(v.encoded)}}
                                             : ojson{{"bytes", nullptr}, {"error", v.encoded_error}};
      r["central_pitch_cpm"] = v.central_pitch_cpm;
      r["irregularity_cpm"] = v.irregularity_cpm;
    } else {
      r["histogram"] = nullptr;
      r["encoded"] = nullptr;
      r["central_pitch_cpm"] = nullptr;
      r["irregularity_cpm"] = nullptr;
    }
    r["texels"] = v.texels;
    r["queued_ms"] = std::chrono::duration<double, std::milli>(t0 - job.received).count();
    r["elapsed_ms"] = ms_since(t0);
    send(c, r);
  }

  void run_fifo_job(Client& c, const Job& job) {
    const std::string& t = job.type;
    if (t == "match")
      match(c, job);
    else if (t == "import")
      import(c, job);
    else if (t == "export")
      export_(c, job);
    else if (t == "experiment.list")
      experiment_list(c, job);
    else if (t == "experiment.start")
      experiment_start(c, job);
    else if (t == "experiment.current")
      experiment_current(c, job);
    else if (t == "experiment.select")
      experiment_select(c, job);
    else if (t == "experiment.preview")
      experiment_preview(c, job);
    else if (t == "experiment.answer")
      experiment_answer(c, job);
    else
      experiment_stop(c, job);
  }

  void match(Client& c, const Job& job) {
    const auto t0 = Clock::now();
    const Fields f(job.msg, job.type, {"document", "region", "into"});
    MatchOptions o;
    o.region = static_cast<std::size_t>(f.integer("region", 0, 1023));
    o.into = region_field(f, "into");
    const MatchView m = match_region(document_of(f.object("document"), "document"), o);
    ojson r = reply("match", job.id);
    const ojson doc = ojson::parse(document_json(m.document));
    r["into"] = m.into;
    r["region"] = doc["regions"][m.into];
    r["document"] = doc;
    r["encoded"] = encode_json(m.result);
    r["model_distance"] = m.result.model_distance;
    r["target_spectrum"] = spectrum_json(m.target);
    r["match_spectrum"] = spectrum_json(m.match);
    r["elapsed_ms"] = ms_since(t0);
    send(c, r);
  }

  void import(Client& c, const Job& job) {
    const auto t0 = Clock::now();
    const Fields f(job.msg, job.type, {"name", "data_base64", "device"});
    const std::string name = f.string("name", max_name_chars);
    const auto bytes = detail::base64_decode(f.string("data_base64", options.max_message_bytes));
    if (!bytes) throw Reject{"invalid", "import: data_base64 is not valid base64 (RFC 4648, padded)"};
    ImportOptions o;
    if (f.has("device")) {
      const std::string dev = f.string("device", max_name_chars);
      const auto names = builtin_device_names();
      if (std::find(names.begin(), names.end(), dev) == names.end())
        throw Reject{"invalid", "import: device is " + clipped(dev) + "; allowed: a built-in device"};
      o.device = load_device(dev);
    }
    ImportResult res = import_file(name, std::as_bytes(std::span(*bytes)), o);
    // A document's inline device may be anything: apply the service's caps.
    const json doc = json::parse(document_json(res.document));
    (void)document_of(doc, "document");
    ojson r = reply("import", job.id);
    r["kind"] = to_string(res.kind);
    r["document"] = ojson::parse(doc.dump());
    r["encoded"] = res.encoded ? encode_json(*res.encoded) : ojson(nullptr);
    r["elapsed_ms"] = ms_since(t0);
    send(c, r);
  }

  void export_(Client& c, const Job& job) {
    const Fields f(job.msg, job.type, {"document", "as", "region"});
    const ExportFormat as = parse_export_format(f.string("as", 32));
    const ExportFile file = export_file(document_of(f.object("document"), "document"), as, region_field(f, "region"));
    ojson r = reply("export", job.id);
    r["name"] = file.name;
    r["mime"] = file.mime;
    r["bytes"] = file.data.size();
    r["data_base64"] = detail::base64_encode(file.data);
    send(c, r);
  }

  // ---------------------------------------------------------------- feel

  void feel_select(Client& c, const Job& job) {
    const Fields f(job.msg, job.type, {"document"});
    // Rendered here, outside feel_mutex: finger samples keep flowing meanwhile.
    // The map carries the document's device response (presenter.hpp).
    auto map = PlayerMap::from_document(document_of(f.object("document"), "document"));
    {
      std::lock_guard lock(feel_mutex);
      presenter->show(std::move(map));
    }
    send(c, reply("feel.selected", job.id));
  }

  void feel_move(Client& c, const json& msg, const json& id) {
    const Fields f(msg, "feel.move", {"seq", "x_mm", "touch"});
    const std::int64_t seq = f.integer("seq", 0, std::int64_t{1} << 53);
    const double x = f.number("x_mm", -max_abs_mm, max_abs_mm);
    const bool touch = f.boolean("touch", true);
    std::optional<FingerSample> s;
    {
      std::lock_guard lock(feel_mutex);
      s = presenter->push_finger(x, touch);
      if (s) {
        finger_client = c.id;
        finger_x = x;
        finger_down = touch;
        if (trace.size() < max_trace_samples) trace.push_back(*s);
      }
      presenter->pump();
    }
    if (!s) throw Reject{"busy", "the player's finger queue is full; send fewer positions"};
    ojson r = reply("feel.ack", id);
    r["seq"] = seq;
    r["t_s"] = s->t_s;
    send(c, r);
  }

  void feel_state(Client& c, const json& msg, const json& id) {
    (void)Fields(msg, "feel.state", {});
    BackendStats s;
    std::string backend, error;
    {
      std::lock_guard lock(feel_mutex);
      presenter->pump();
      s = presenter->stats();
      backend = presenter->describe();
      error = presenter->error();
    }
    ojson r = reply("feel.state", id);
    r["position_mm"] = s.position_mm;
    r["touching"] = s.touching;
    r["blocks"] = s.blocks;
    r["peak"] = s.peak;
    r["underruns"] = s.underruns;
    r["backend"] = backend;
    r["error"] = error;
    send(c, r);
  }

  void lift_finger(std::uint64_t client) {
    std::lock_guard lock(feel_mutex);
    if (finger_client == client && finger_down) {
      (void)presenter->push_finger(finger_x, false);
      finger_down = false;
    }
  }

  // --------------------------------------------------------- experiments

  ex::Store& the_store() {
    if (!store) store.emplace(ex::Store::open(options.db_path, ex::StoreMode::read_write));
    return *store;
  }

  struct Shipped {
    std::string file;
    ex::Protocol protocol;
  };
  std::vector<Shipped> shipped_protocols() const {
    std::vector<Shipped> out;
    if (options.protocols_dir.empty()) return out;
    std::error_code ec;
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(options.protocols_dir, ec))
      if (e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& p : files) {
      try {
        out.push_back({p.filename().string(), ex::load_protocol(p.string())});
      } catch (const Error&) {
        // A broken shipped file is the CLI's to report (texel experiment validate), not a client's.
      }
    }
    return out;
  }

  // The running session as the library serialises it (as stored now), with
  // "simulated" for the spec in force.
  ojson session_json() {
    ojson j = ojson::parse(ex::to_json(the_store().session(active->info.id)));
    j["simulated"] = !active->simulate.empty();
    return j;
  }

  ojson progress_json() const {
    return ojson{{"done", active->session.trials_done()}, {"planned", active->session.trials_planned()}};
  }

  // The state participant screens show: the question, finished or idle.
  ojson current_state(const json& id) {
    if (!active) return reply("experiment.idle", id);
    ojson r = reply(active->session.finished() ? "experiment.finished" : "experiment.question", id);
    r["session"] = session_json();
    r["progress"] = progress_json();
    if (!active->session.finished()) r["question"] = participant_question(active->session.question());
    return r;
  }

  const ex::Question& current_question(const Fields& f, const std::string& type) {
    if (!active) throw Reject{"not_found", type + ": no session is running; start one in the experimenter view"};
    if (active->session.finished()) throw Reject{"conflict", type + ": the session is finished"};
    const ex::Question& q = active->session.question();
    const std::int64_t trial = f.integer("trial", 0, 1 << 30);
    if (trial != q.trial)
      throw Reject{"conflict", type + ": trial " + std::to_string(trial) + " is not the current trial (" +
                                   std::to_string(q.trial) + "); ask experiment.current"};
    return q;
  }

  void show_stimulus(const std::string& document_json_text) {
    std::lock_guard lock(feel_mutex);
    presenter->show(document_json_text);
  }

  void new_trial() {
    std::lock_guard lock(feel_mutex);
    presenter->blank();
    trace.clear();
  }

  void experiment_list(Client& c, const Job& job) {
    (void)Fields(job.msg, job.type, {});
    ojson r = reply("experiment.list", job.id);
    r["protocols"] = ojson::array();
    for (const auto& s : shipped_protocols())
      r["protocols"].push_back({{"name", s.protocol.name},
                                {"file", s.file},
                                {"study", s.protocol.study},
                                {"title", s.protocol.title},
                                {"description", s.protocol.description},
                                {"trials_planned", s.protocol.planned_trials()}});
    r["sessions"] = ojson::array();
    for (const auto& s : the_store().sessions()) r["sessions"].push_back(ojson::parse(ex::to_json(s)));
    r["active"] = active ? session_json() : ojson(nullptr);
    send(c, r);
  }

  void experiment_start(Client& c, const Job& job) {
    const Fields f(job.msg, job.type, {"protocol", "participant", "resume", "simulate"});
    const json& p = f.raw("protocol");
    ex::OpenOptions o;
    o.participant = f.string("participant", 32);
    o.resume = f.boolean("resume", false);
    if (f.has("simulate")) o.simulate = f.string("simulate", max_name_chars);
    std::optional<ex::Protocol> protocol;
    if (p.is_string()) {
      for (auto& s : shipped_protocols())
        if (s.protocol.name == p.get_ref<const std::string&>()) protocol = std::move(s.protocol);
      if (!protocol)
        throw Reject{"not_found", "experiment.start: protocol " + clipped(p.get<std::string>()) +
                                      " is not a shipped protocol (see experiment.list)"};
    } else if (p.is_object()) {
      if (p.contains("device") && p["device"].is_string()) {
        const auto names = builtin_device_names();
        if (std::find(names.begin(), names.end(), p["device"].get<std::string>()) == names.end())
          throw Reject{"invalid", "experiment.start: protocol.device must be a built-in device"};
      }
      protocol = ex::parse_protocol(p.dump(), "protocol");
    } else {
      throw Reject{"bad_message", std::string("experiment.start: protocol must be a name or an object, got ") + type_name(p)};
    }
    if (active && !active->session.finished()) {
      if (active->info.participant != o.participant || active->info.protocol != protocol->name || !o.resume)
        throw Reject{"conflict", "experiment.start: session " + std::to_string(active->info.id) + " (participant " +
                                     active->info.participant + ", " + active->info.protocol +
                                     ") is running; stop it first (experiment.stop)"};
    } else {
      active.reset();
      ex::Store& st = the_store();
      const bool unfinished = st.unfinished_session(o.participant, protocol->name).has_value();
      if (unfinished && !o.resume)
        throw Reject{"conflict", "experiment.start: participant " + clipped(o.participant) + " has an unfinished " +
                                     protocol->name + " session; resume it (resume: true)"};
      if (!unfinished && o.resume)
        throw Reject{"not_found", "experiment.start: participant " + clipped(o.participant) + " has no unfinished " +
                                      protocol->name + " session to resume"};
      try {
        active.emplace(ex::open_session(st, *protocol, o));
      } catch (const InvalidArgument&) {
        throw;
      } catch (const FormatError&) {
        throw;
      } catch (const IoError&) {
        throw;
      } catch (const Error& e) {  // another process is writing this session
        throw Reject{"conflict", std::string("experiment.start: ") + e.what()};
      }
      new_trial();
    }
    ojson r = reply("experiment.started", job.id);
    r["session"] = session_json();
    r["progress"] = progress_json();
    r["resumed"] = o.resume;
    send(c, r);
  }

  void experiment_current(Client& c, const Job& job) {
    (void)Fields(job.msg, job.type, {});
    send(c, current_state(job.id));
  }

  void experiment_select(Client& c, const Job& job) {
    const Fields f(job.msg, job.type, {"trial", "stimulus"});
    const ex::Question& q = current_question(f, job.type);
    if (q.stimuli.empty()) throw Reject{"invalid", "experiment.select: this question has no stimuli"};
    const auto s = static_cast<std::size_t>(f.integer("stimulus", 0, static_cast<std::int64_t>(q.stimuli.size()) - 1));
    show_stimulus(q.stimuli[s].document_json);
    ojson r = reply("experiment.selected", job.id);
    r["trial"] = q.trial;
    r["stimulus"] = s;
    r["label"] = q.stimuli[s].label;
    send(c, r);
  }

  void experiment_preview(Client& c, const Job& job) {
    const Fields f(job.msg, job.type, {"trial", "slider_p", "slider_i"});
    const ex::Question& q = current_question(f, job.type);
    if (q.sliders.size() != 2) throw Reject{"invalid", "experiment.preview: this question has no sliders"};
    const double sp = f.number("slider_p", q.sliders[0].min, q.sliders[0].max);
    const double si = f.number("slider_i", q.sliders[1].min, q.sliders[1].max);
    show_stimulus(active->session.preview_document(sp, si));
    ojson r = reply("experiment.selected", job.id);
    r["trial"] = q.trial;
    r["slider_p"] = sp;
    r["slider_i"] = si;
    send(c, r);
  }

  void experiment_answer(Client& c, const Job& job) {
    const Fields f(job.msg, job.type, {"trial", "response", "simulated"});
    (void)current_question(f, job.type);
    ex::Response response;
    if (f.boolean("simulated", false)) {
      if (active->simulate.empty())
        throw Reject{"invalid", "experiment.answer: simulated answers need a session started with 'simulate'"};
      response = ex::simulated_participant(*active).respond(active->session);
    } else {
      response = ex::Response::from_json(f.object("response").dump());
    }
    if (!response.swipe_mean_speed_mm_s) {
      std::lock_guard lock(feel_mutex);
      const SwipeMeasures m = swipe_measures(trace);
      if (m.intervals > 0) {
        response.swipe_mean_speed_mm_s = m.mean_speed_mm_s;
        response.swipe_sd_speed_mm_s = m.sd_speed_mm_s;
        response.directional_proportion = m.directional_proportion;
      }
    }
    (void)ex::record(the_store(), *active, response);  // committed before the next question goes out
    new_trial();
    send(c, current_state(job.id));
  }

  void experiment_stop(Client& c, const Job& job) {
    (void)Fields(job.msg, job.type, {});
    active.reset();
    new_trial();
    send(c, reply("experiment.idle", job.id));
  }

  // ------------------------------------------------------------- clients

  std::uint64_t connect(Sink sink) {
    auto c = std::make_shared<Client>();
    c->sink = std::move(sink);
    c->tokens = options.max_messages_per_s;
    std::lock_guard lock(mutex);
    c->id = next_client++;
    clients.emplace(c->id, c);
    return c->id;
  }

  void disconnect(std::uint64_t id) {
    std::shared_ptr<Client> c;
    {
      std::lock_guard lock(mutex);
      const auto it = clients.find(id);
      if (it == clients.end()) return;
      c = it->second;
      clients.erase(it);
      c->slots.clear();
      std::erase_if(fifo, [&](const auto& e) { return e.first->id == id; });
      c->fifo_jobs = 0;
    }
    {
      std::lock_guard lock(c->send_mutex);  // waits out a reply being sent
      c->open = false;
    }
    lift_finger(id);
  }
};

Service::Service(ServiceOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}
Service::~Service() = default;

std::uint64_t Service::connect(Sink sink) { return impl_->connect(std::move(sink)); }

void Service::handle(std::uint64_t client, std::string_view text) {
  try {
    impl_->handle(client, text);
  } catch (...) {
    // handle() reports through the sink; a sink that throws has no one left to tell.
  }
}

void Service::disconnect(std::uint64_t client) { impl_->disconnect(client); }

std::string Service::describe() const {
  std::lock_guard lock(impl_->feel_mutex);
  return impl_->presenter->describe();
}

}  // namespace texel::studio
