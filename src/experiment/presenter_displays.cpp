// The displays' members (presenter_displays.hpp): a 2-D display's finger
// reports queued into its player and recorded per interval; a 1-D serial
// display's reports, its host watchdog's keepalive thread, and the
// stimuli it holds in its slots (rendered once, uploaded over the least
// recently felt slot).
#include "presenter_displays.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include "texel/error.hpp"

namespace texel::experiment {

using namespace presenter_parts;

// ------------------------------------------------------------- 2-D display

void Presenter::Display2D::start(SerialLink& l) {
  link = &l;
  reader.emplace(l, [this](std::span<const FingerReport> batch) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const FingerReport& r : batch) {
      const double t = timeline.place(r.t_us, player.time_s());
      if (!player.push(FingerSample2D{t, r.x_mm, r.y_mm, r.touch})) ++dropped;
      ++reports;
      last_t = clock.seconds(r.t_us);
      if (!current.empty()) recorders.at(current).add(last_t, r.x_mm, r.y_mm, r.touch);
    }
  });
}

void Presenter::Display2D::stop() {
  if (reader) reader->stop();
  maps.stop();
}

void Presenter::Display2D::leave() {
  std::lock_guard<std::mutex> lock(mutex);
  if (!current.empty()) recorders.at(current).add(last_t, 0.0, 0.0, false);
  current.clear();
}

void Presenter::Display2D::enter(const std::string& label) {
  std::lock_guard<std::mutex> lock(mutex);
  if (!current.empty()) recorders.at(current).add(last_t, 0.0, 0.0, false);
  recorders.try_emplace(label, rules);
  current = label;
}

// --------------------------------------------------------- 1-D serial display

void Presenter::Display1D::arm_host_watchdog() {
  host_watchdog = link->arm_host_watchdog(host_watchdog_ms);
  if (!host_watchdog || keepalive.joinable()) return;
  keepalive = std::jthread([this](std::stop_token stop) {
    std::unique_lock lock(keepalive_mutex);
    while (!stop.stop_requested()) {
      try {
        link->keepalive();
      } catch (const std::exception&) {
        return;  // the link is gone: the display's watchdog rests it
      }
      keepalive_wake.wait_for(lock, stop, keepalive_every, [] { return false; });
    }
  });
}

void Presenter::Display1D::stop_keepalive() {
  if (!keepalive.joinable()) return;
  keepalive.request_stop();
  keepalive.join();
}

void Presenter::Display1D::record(const FingerReport& r) {  // under mutex
  ++reports;
  // The display's own clock, unwrapped: its t_us at the first report plus the time since.
  if (reports == 1) first_s = static_cast<double>(r.t_us) * 1e-6;
  const double t = first_s + clock.seconds(r.t_us);
  if (recording) trace.push_back(FingerSample{t, r.x_mm, r.touch});
}

void Presenter::Display1D::drain() {
  std::array<FingerReport, 256> buf;
  for (;;) {
    const std::size_t n = link->read_reports(buf, 0);
    std::lock_guard<std::mutex> lock(mutex);
    for (std::size_t i = 0; i < n; ++i) record(buf[i]);
    if (n < buf.size()) return;
  }
}

const Presenter::Display1D::Rendered& Presenter::Display1D::render(const std::string& document_json) {
  auto it = std::find_if(rendered.begin(), rendered.end(), [&](const Rendered& r) { return r.document == document_json; });
  if (it != rendered.end()) {
    rendered.splice(rendered.begin(), rendered, it);
    return rendered.front();
  }
  // texel render's bytes: the document's surface encoded as u16le (round(a·65535)).
  const Document doc = parse_document(document_json, "stimulus");
  check_channels(doc, 1);  // a serial display is one channel
  const std::shared_ptr<const Surface> held = one_channel_surface(doc);
  const Surface& surface = *held;
  const Grid& g = surface.grid();
  if (static_cast<std::uint64_t>(g.count) > info.max_samples)
    throw InvalidArgument("a stimulus map has " + std::to_string(g.count) + " samples; the display '" + info.name +
                          "' holds at most " + std::to_string(info.max_samples) +
                          " (its HELLO): use a device profile the display can hold, or --mode host-streams");
  const std::vector<std::byte> bytes = surface.render_native(SampleFormat::u16le);
  Rendered r;
  r.document = document_json;
  r.samples.resize(bytes.size() / 2);
  for (std::size_t i = 0; i < r.samples.size(); ++i)
    r.samples[i] =
        static_cast<std::uint16_t>(std::to_integer<unsigned>(bytes[2 * i]) | (std::to_integer<unsigned>(bytes[2 * i + 1]) << 8));
  r.spacing_nm = static_cast<std::uint32_t>(std::lround(g.spacing.value() * 1e6));
  r.origin_nm = static_cast<std::int32_t>(std::lround(g.origin.value() * 1e6));
  rendered.push_front(std::move(r));
  if (rendered.size() > 8) rendered.pop_back();
  return rendered.front();
}

int Presenter::Display1D::hold(const std::string& document_json, bool at_switch) {
  for (std::size_t k = 0; k < slots.size(); ++k)
    if (slots[k].document == document_json) {
      slots[k].used = ++tick;
      return static_cast<int>(k);
    }
  const Rendered& r = render(document_json);
  int victim = -1;
  for (std::size_t k = 0; k < slots.size(); ++k)
    if (static_cast<int>(k) != selected && (victim < 0 || slots[k].used < slots[static_cast<std::size_t>(victim)].used))
      victim = static_cast<int>(k);
  if (victim < 0) {  // one slot, playing: rest while it is replaced
    select(-1);
    victim = 0;
  }
  const auto t0 = std::chrono::steady_clock::now();
  slots[static_cast<std::size_t>(victim)].document.clear();  // a failed upload leaves the slot unknown
  link->upload_raw(static_cast<std::uint8_t>(victim), r.samples, r.spacing_nm, r.origin_nm);
  uploads.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++uploads.uploads;
  if (at_switch) ++uploads.at_switch;
  slots[static_cast<std::size_t>(victim)] = Slot{document_json, ++tick};
  return victim;
}

void Presenter::Display1D::select(int slot) {
  if (slot == selected) return;
  link->select(slot < 0 ? serial::no_map : static_cast<std::uint8_t>(slot));
  selected = slot;
}

}  // namespace texel::experiment
