// Texel Studio's message service (service.hpp, docs/studio.md "Messages").
//
// Shape: handle() checks size and rate, parses, validates the envelope, looks
// the type up in the message table (messages.cpp: {type, lane, keys,
// handler}) and either answers at once or queues a job on one of two lanes:
//   design lane  per client one slot per type (design, feel.select), newest
//                wins; clients served round robin;
//   FIFO lane    match, import, export and experiment steps, in order.
// Each lane has one worker thread, so a client's messages stay in order
// within a lane and a long match never delays a slider's redraw. Unknown
// keys are refused from the table when the handler's turn comes (and, on
// the design lane, already when queued). The handlers (handlers_*.cpp) call
// the library and format; this file is only transport between them.
//
// Hostile input: sizes are checked before parsing, nesting depth before
// nlohmann recurses into it, device names must be built-in (a document's
// "device" may otherwise name a file), maps and texel counts are capped
// before anything is rendered, and library exceptions become error replies.
#include "texel/studio/service.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <thread>

#include "messages.hpp"
#include "texel/error.hpp"

namespace texel::studio {
namespace {

using namespace detail;

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

void send_error(Client& c, const json& id, const std::string& code, const std::string& message) {
  ojson r = reply("error", id);
  r["code"] = code;
  r["message"] = message;
  send(c, r);
}

// Runs `work`, turning every exception into an error reply.
template <typename F>
void guarded(Client& c, const json& id, F&& work) {
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

// The table's row of a job taken from a lane, its keys checked, its handler run.
void run(State& s, Client& c, const Job& job) {
  const MessageSpec& spec = *find_message(job.type);
  check_keys(spec, job.msg);
  spec.handler(s, c, job);
}

[[noreturn]] void unknown_type(const std::string& type) {
  std::string allowed;
  for (const MessageSpec& m : message_table()) allowed += (allowed.empty() ? "" : ", ") + std::string(m.type);
  throw Reject{"bad_message", "unknown message type " + clipped(type) + "; allowed: " + allowed};
}

Reject busy() { return Reject{"busy", "more than " + std::to_string(max_queued_jobs) + " messages queued; wait for replies"}; }

}  // namespace

struct Service::Impl {
  State state;

  // Clients and lanes, behind `mutex`.
  std::mutex mutex;
  std::condition_variable wake;
  bool stopping = false;
  std::uint64_t next_client = 1;
  std::uint64_t next_order = 1;
  std::map<std::uint64_t, std::shared_ptr<Client>> clients;
  std::deque<std::uint64_t> design_turns;  // clients with a filled slot, round robin
  std::deque<std::pair<std::shared_ptr<Client>, Job>> fifo;

  std::thread design_worker, fifo_worker;

  explicit Impl(ServiceOptions o) {
    ServiceOptions& options = state.options;
    options = std::move(o);
    if (!(options.max_message_bytes >= 1024 && options.max_message_bytes <= (std::size_t{1} << 30)))
      throw InvalidArgument("max_message_bytes is " + std::to_string(options.max_message_bytes) + "; allowed: 1024 … 2^30");
    if (!(options.max_messages_per_s >= 1 && options.max_messages_per_s <= 1e6))
      throw InvalidArgument("max_messages_per_s is " + std::to_string(options.max_messages_per_s) + "; allowed: 1 … 1e6");
    state.presenter_options = presenter_options(options);
    state.presenter = std::make_unique<experiment::Presenter>(state.presenter_options);
    state.device_shared = parse_backend(options.backend).kind != BackendChoice::Kind::null;
    state.device_description = state.presenter->describe();
    state.hello = make_hello(state);
    state.broadcast = [this](const std::function<ojson(bool)>& make, std::uint64_t except) { broadcast(make, except); };
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
    state.active.reset();  // releases the writer lock: the session stays resumable
    std::lock_guard lock(state.feel_mutex);
    state.presenter->stop();
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
    const double rate = state.options.max_messages_per_s;
    c.tokens = std::min(rate, c.tokens + rate * std::chrono::duration<double>(now - c.refilled).count());
    c.refilled = now;
    if (c.tokens < 1.0) return false;
    c.tokens -= 1.0;
    return true;
  }

  void handle(std::uint64_t client_id, std::string_view text) {
    const auto c = find(client_id);
    if (!c) return;  // unknown or gone: nobody to answer
    const ServiceOptions& options = state.options;
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
      if (!msg.is_object()) throw Reject{"bad_message", std::string("message must be a JSON object, got ") + msg.type_name()};
      if (msg.contains("id")) {
        const json& i = msg["id"];
        const bool ok = (i.is_number_integer()) || (i.is_string() && i.get_ref<const std::string&>().size() <= max_id_chars);
        if (!ok) throw Reject{"bad_message", "id must be an integer or a string of at most 64 characters"};
        id = i;
      }
      if (!msg.contains("type") || !msg["type"].is_string()) throw Reject{"bad_message", "message needs a string 'type'"};
      std::string type = msg["type"].get<std::string>();
      const MessageSpec* spec = find_message(type);
      if (!spec) unknown_type(type);
      Job job{std::move(type), std::move(msg), id, Clock::now()};
      switch (spec->lane) {
        case Lane::now: run(state, *c, job); break;
        case Lane::design:
          check_keys(*spec, job.msg);
          enqueue_design_lane(c, std::move(job));
          break;
        case Lane::fifo: enqueue_fifo(c, std::move(job)); break;
      }
    });
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
      guarded(*c, job.id, [&] { run(state, *c, job); });
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
      guarded(*c, job.id, [&] { run(state, *c, job); });
      pump();
      lock.lock();
    }
  }

  void pump() {
    std::lock_guard lock(state.feel_mutex);
    state.presenter->pump();
  }

  // ------------------------------------------------------------- clients

  // Sends to every open client but `except` (runs on the FIFO worker): participant
  // screens' message first (handing a question to a screen starts its clock).
  void broadcast(const std::function<ojson(bool)>& make, std::uint64_t except) {
    std::vector<std::shared_ptr<Client>> to;
    {
      std::lock_guard lock(mutex);
      for (const auto& [id, c] : clients)
        if (id != except) to.push_back(c);
    }
    std::optional<ojson> screens, others;
    for (const auto& c : to)
      if (c->participant_screen) send(*c, screens ? *screens : *(screens = make(true)));
    for (const auto& c : to)
      if (!c->participant_screen) send(*c, others ? *others : *(others = make(false)));
  }

  std::uint64_t connect(Sink sink) {
    auto c = std::make_shared<Client>();
    c->sink = std::move(sink);
    c->tokens = state.options.max_messages_per_s;
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
    lift_finger(state, id);
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
  std::lock_guard lock(impl_->state.feel_mutex);
  return impl_->state.presenter->describe();
}

}  // namespace texel::studio
