// "Feel it" messages: the one Presenter (external finger) shared by all
// clients. feel.select swaps a document's map in (design lane, latest wins);
// feel.move and feel.state are answered before handle() returns. Selecting a
// map or touching the strip takes the configured device back from the 2-D
// pad (device_to_presenter, handlers_surface2d.cpp).
#include <algorithm>
#include <cmath>

#include "messages.hpp"
#include "texel/detail/format.hpp"
#include "texel/player.hpp"

namespace texel::studio::detail {

experiment::PresenterOptions presenter_options(const ServiceOptions& o, bool null_backend) {
  experiment::PresenterOptions po;
  po.backend = null_backend ? "null" : o.backend;
  po.audio_device = o.audio_device;
  po.finger = experiment::FingerSource::external;
  po.response_handling = parse_response_handling(o.response, "response");
  po.channels = o.channels;
  return po;
}

void on_feel_select(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const Document doc = document_of(s, f.object("document"), "document");
  if (doc.device.channels() > 1) {
    // A document for an actuator array plays on its channels, each its own map
    // (simultaneous texels, or the one chain at each actuator's offset).
    std::lock_guard lock(s.feel_mutex);
    if (s.active && !s.active->session.finished() && s.presenter->channels() != doc.device.channels())
      throw Reject{"conflict", "feel.select: the document's device '" + doc.device.name + "' has " +
                                   std::to_string(doc.device.channels()) + " actuators and the running study plays " +
                                   std::to_string(s.presenter->channels()) + " channels"};
    presenter_channels(s, doc.device.channels(), "feel.select: device '" + doc.device.name + "'");
    device_to_presenter(s);
    s.presenter->show(document_json(doc));
    s.feel_map.reset();
    send(c, reply("feel.selected", job.id));
    return;
  }
  // Rendered here, outside feel_mutex: finger samples keep flowing meanwhile.
  // The map carries the document's device response (presenter.hpp).
  auto map = PlayerMap::from_document(doc);
  auto kept = std::make_unique<const PlayerMap>(map->grid(), std::vector<float>(map->values().begin(), map->values().end()),
                                                map->response());
  {
    std::lock_guard lock(s.feel_mutex);
    device_to_presenter(s);
    s.presenter->show(std::move(map));
    s.feel_map = std::move(kept);
  }
  send(c, reply("feel.selected", job.id));
}

namespace {

/// feel.move's `coalesced`: earlier [t_ms, x_mm] samples of the same pointer
/// event (getCoalescedEvents), oldest first, none after `t_ms`.
std::vector<std::pair<double, double>> coalesced_samples(const Fields& f, double t_ms) {
  std::vector<std::pair<double, double>> out;
  if (!f.has("coalesced")) return out;
  const json& list = f.raw("coalesced");
  if (!list.is_array() || list.size() > max_coalesced)
    throw Reject{"bad_message", "feel.move: coalesced must be an array of at most " + std::to_string(max_coalesced) +
                                    " [t_ms, x_mm] samples, got " + clipped(list.dump())};
  out.reserve(list.size());
  for (std::size_t k = 0; k < list.size(); ++k) {
    const json& e = list[k];
    const std::string where = "feel.move: coalesced[" + std::to_string(k) + "]";
    if (!e.is_array() || e.size() != 2 || !e[0].is_number() || !e[1].is_number())
      throw Reject{"bad_message", where + " must be [t_ms, x_mm] (two numbers), got " + clipped(e.dump())};
    const double t = e[0].get<double>(), x = e[1].get<double>();
    if (!(t >= 0 && t <= max_t_ms) || !(std::abs(x) <= max_abs_mm))
      throw Reject{"invalid", where + " is " + clipped(e.dump()) + "; allowed: t_ms 0 … " + texel::detail::num(max_t_ms) +
                                  ", |x_mm| <= " + texel::detail::num(max_abs_mm)};
    if (t > t_ms || (!out.empty() && t < out.back().first))
      throw Reject{"invalid", where + ": t_ms " + texel::detail::num(t) +
                                  " is out of order; allowed: non-decreasing and at most t_ms " + texel::detail::num(t_ms)};
    out.emplace_back(t, x);
  }
  return out;
}

}  // namespace

// One finger sample (and the samples coalesced into its pointer event). The
// player plays the newest at its arrival (push_finger: arrival + lead); the
// trace keeps every sample at the page's own time for the swipe measures, so
// how the messages travelled (paced, or queued and sent in one burst) does
// not change a measured speed.
void on_feel_move(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::int64_t seq = f.integer("seq", 0, std::int64_t{1} << 53);
  const double t_ms = f.number("t_ms", 0, max_t_ms);
  const double x = f.number("x_mm", -max_abs_mm, max_abs_mm);
  const bool touch = f.boolean("touch", true);
  const auto earlier = coalesced_samples(f, t_ms);
  const double arrival_ms = std::chrono::duration<double, std::milli>(job.received.time_since_epoch()).count();
  std::optional<FingerSample> sample;
  {
    std::lock_guard lock(s.feel_mutex);
    const double first_ms = earlier.empty() ? t_ms : earlier.front().first;
    if (first_ms < c.pointer_t_ms)
      throw Reject{"invalid", "feel.move: t_ms " + texel::detail::num(first_ms) + " is before this page's previous sample (" +
                                  texel::detail::num(c.pointer_t_ms) +
                                  " ms); allowed: non-decreasing (the page's PointerEvent.timeStamp, a monotonic clock)"};
    const double lag_ms = arrival_ms - t_ms;
    if (std::isfinite(c.pointer_lag_ms) && lag_ms < c.pointer_lag_ms - max_ahead_ms)
      throw Reject{"invalid", "feel.move: t_ms " + texel::detail::num(t_ms) + " runs " +
                                  texel::detail::fixed(c.pointer_lag_ms - lag_ms, 1) +
                                  " ms ahead of the studio's clock; allowed: at most " + texel::detail::num(max_ahead_ms) +
                                  " ms (the page's PointerEvent.timeStamp)"};
    c.pointer_lag_ms = std::min(c.pointer_lag_ms, lag_ms);
    c.pointer_t_ms = t_ms;
    if (touch) device_to_presenter(s);
    sample = s.presenter->push_finger(x, touch);
    if (sample) {
      s.finger_client = c.id;
      s.finger_x = x;
      s.finger_down = touch;
      // Another page's clock: its samples start after a lift, so no interval spans two clocks.
      if (s.trace_client != c.id) {
        if (!s.trace.empty() && s.trace.back().touch && s.trace.size() < max_trace_samples) {
          FingerSample lift = s.trace.back();
          lift.touch = false;
          s.trace.push_back(lift);
        }
        s.trace_offset_ms = s.trace.empty() ? 0.0 : s.trace.back().t_s * 1000.0 - first_ms;
      }
      s.trace_client = c.id;
      for (const auto& [t, xe] : earlier)
        if (s.trace.size() < max_trace_samples) s.trace.push_back({(t + s.trace_offset_ms) / 1000.0, xe, touch});
      if (s.trace.size() < max_trace_samples) s.trace.push_back({(t_ms + s.trace_offset_ms) / 1000.0, x, touch});
    }
    s.presenter->pump();
  }
  if (!sample) throw Reject{"busy", "the player's finger queue is full; send fewer positions"};
  ojson r = reply("feel.ack", job.id);
  r["seq"] = seq;
  r["t_s"] = sample->t_s;
  send(c, r);
}

void on_feel_state(State& s, Client& c, const Job& job) {
  BackendStats st;
  std::string backend, error;
  {
    std::lock_guard lock(s.feel_mutex);
    s.presenter->pump();
    st = s.presenter->stats();
    backend = s.presenter->describe();
    error = s.presenter->error();
    if (error.empty()) error = s.device_error;
    if (s.feel2d_holds_device) backend = s.device_description + " (playing the 2-D pad; touch the strip to take it back)";
  }
  ojson r = reply("feel.state", job.id);
  r["position_mm"] = st.position_mm;
  r["touching"] = st.touching;
  r["blocks"] = st.blocks;
  r["peak"] = st.peak;
  r["underruns"] = st.underruns;
  r["backend"] = backend;
  r["error"] = error;
  send(c, r);
}

void lift_finger(State& s, std::uint64_t client) {
  lift_finger_2d(s, client);
  std::lock_guard lock(s.feel_mutex);
  if (s.finger_client == client && s.finger_down) {
    (void)s.presenter->push_finger(s.finger_x, false);
    s.finger_down = false;
  }
}

}  // namespace texel::studio::detail
