// "Feel it" messages: the one Presenter (external finger) shared by all
// clients. feel.select swaps a document's map in (design lane, latest wins);
// feel.move and feel.state are answered before handle() returns. Selecting a
// map or touching the strip takes the configured device back from the 2-D
// pad (device_to_presenter, handlers_surface2d.cpp).
#include "messages.hpp"
#include "texel/player.hpp"

namespace texel::studio::detail {

experiment::PresenterOptions presenter_options(const ServiceOptions& o, bool null_backend) {
  experiment::PresenterOptions po;
  po.backend = null_backend ? "null" : o.backend;
  po.audio_device = o.audio_device;
  po.finger = experiment::FingerSource::external;
  po.response_handling = parse_response_handling(o.response, "response");
  return po;
}

void on_feel_select(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  // Rendered here, outside feel_mutex: finger samples keep flowing meanwhile.
  // The map carries the document's device response (presenter.hpp).
  auto map = PlayerMap::from_document(document_of(s, f.object("document"), "document"));
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

void on_feel_move(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::int64_t seq = f.integer("seq", 0, std::int64_t{1} << 53);
  const double x = f.number("x_mm", -max_abs_mm, max_abs_mm);
  const bool touch = f.boolean("touch", true);
  std::optional<FingerSample> sample;
  {
    std::lock_guard lock(s.feel_mutex);
    if (touch) device_to_presenter(s);
    sample = s.presenter->push_finger(x, touch);
    if (sample) {
      s.finger_client = c.id;
      s.finger_x = x;
      s.finger_down = touch;
      if (s.trace.size() < max_trace_samples) s.trace.push_back(*sample);
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
