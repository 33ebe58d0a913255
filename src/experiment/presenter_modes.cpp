// The presentation mode a display gets (presenter.hpp, docs/experiments.md
// "Running a study with a display"): from the backend and the display's HELLO (its
// slots, whether it senses the finger) or from a separate finger sensor, each
// refusal naming the flag and the fix; and the check of the first question
// against what that mode can play (map sizes, slots, the stream's band).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "presenter_displays.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/texture.hpp"

namespace texel::experiment {

using namespace presenter_parts;

void Presenter::choose_mode(const BackendChoice& choice) {
  const bool external = options_.finger == FingerSource::external;
  if (choice.kind != BackendChoice::Kind::serial || external) {
    // A sound card or no hardware: no map storage; a finger only if pushed from outside.
    mode_ = options_.mode.value_or(external ? PresentationMode::host_streams : PresentationMode::passive);
    if (mode_ == PresentationMode::display_plays)
      throw InvalidArgument("--mode display-plays: " + backend_->describe() +
                            " stores no maps; give a serial display that does (--backend serial:PATH)");
    if (mode_ == PresentationMode::host_streams && !external)
      throw InvalidArgument("--mode host-streams: " + backend_->describe() +
                            " has no finger to stream from; give a display that senses it (--backend serial:PATH) or "
                            "--mode passive");
    if (mode_ == PresentationMode::passive && external)
      throw InvalidArgument("mode passive: this presenter is given a finger (external); passive plays a simulated sweep");
    return;
  }
  // A serial display: what its HELLO says it holds, and whether it senses the finger.
  auto d = std::make_unique<Display1D>();
  d->link = backend_->serial_link();
  d->info = d->link->hello();
  d->report_interval_us = options_.report_interval_us;
  if (d->report_interval_us < serial::min_report_interval_us)
    throw InvalidArgument("report interval is " + std::to_string(d->report_interval_us) +
                          " µs; allowed >= " + std::to_string(serial::min_report_interval_us));
  try {
    d->link->start_reports(d->report_interval_us);
    d->sensor = true;
  } catch (const SerialError& e) {
    if (e.code != serial::ErrorCode::no_sensor && e.code != serial::ErrorCode::unknown_type) throw;
  }
  const PresentationMode chosen = d->sensor
                                      ? (d->info.slots >= 1 ? PresentationMode::display_plays : PresentationMode::host_streams)
                                      : PresentationMode::passive;
  mode_ = options_.mode.value_or(chosen);
  const std::string who = "the display '" + d->info.name + "' on " + choice.serial_path;
  auto refuse = [&](const std::string& why) {
    if (d->sensor) try {
        d->link->start_reports(0);
      } catch (const Error&) {
      }
    throw InvalidArgument("--mode " + std::string(to_string(mode_)) + ": " + who + " " + why);
  };
  if (mode_ == PresentationMode::display_plays && d->info.slots < 1) refuse("stores no maps (0 slots in its HELLO)");
  if (mode_ != PresentationMode::passive && !d->sensor)
    refuse("does not sense the finger (it refused FINGER reports); give --mode passive for a passive hand");
  if (mode_ == PresentationMode::passive && d->sensor)
    refuse("senses the finger; passive would ignore the participant's exploration (give display-plays or host-streams)");
  if (mode_ == PresentationMode::passive) return;  // streams the simulated sweep's drive, as before
  d->slots.resize(static_cast<std::size_t>(std::max(0, d->info.slots)));
  if (mode_ == PresentationMode::display_plays) d->arm_host_watchdog();
  display1d_ = std::move(d);
}

void Presenter::open_sensor(const BackendChoice& choice) {
  const std::string& f = options_.finger_display;
  if (!f.starts_with("serial:") || f.size() <= 7)
    throw InvalidArgument("finger sensor is '" + f + "'; allowed: serial:PATH (a display or strip that reports the finger)");
  const std::string path = f.substr(7);
  if (choice.kind == BackendChoice::Kind::serial && choice.serial_path == path)
    throw InvalidArgument("--finger " + f +
                          " is the backend's own display: a display with a sensor is its own finger (give no --finger)");
  mode_ = options_.mode.value_or(PresentationMode::host_streams);
  if (mode_ != PresentationMode::host_streams)
    throw InvalidArgument("--mode " + std::string(to_string(mode_)) + ": with a separate finger sensor (" + f +
                          ") the host streams the stimulus from its reports; give --mode host-streams or none");
  if (options_.report_interval_us < serial::min_report_interval_us)
    throw InvalidArgument("report interval is " + std::to_string(options_.report_interval_us) +
                          " µs; allowed >= " + std::to_string(serial::min_report_interval_us));
  auto d = std::make_unique<Display1D>();
  d->own_link = std::make_unique<SerialLink>(path, options_.baud);
  d->link = d->own_link.get();
  d->info = d->link->hello();
  d->report_interval_us = options_.report_interval_us;
  try {
    d->link->start_reports(d->report_interval_us);
  } catch (const SerialError& e) {
    if (e.code == serial::ErrorCode::no_sensor || e.code == serial::ErrorCode::unknown_type)
      throw InvalidArgument("--finger " + f + ": the display '" + d->info.name +
                            "' does not report the finger (it refused FINGER reports); give a sensor that does");
    throw;
  }
  d->sensor = true;
  display1d_ = std::move(d);
}

std::vector<std::string> Presenter::check(const Question& first) const {
  std::vector<std::string> out;
  if (display_ || first.stimuli.empty()) return out;
  for (const auto& s : first.stimuli) check_channels(parse_document(s.document_json, "stimulus"), options_.channels);
  constexpr double swipe_mm_s = 100.0;  // the studies' typical swipe
  if (mode_ == PresentationMode::display_plays) {
    Display1D& d = *display1d_;
    std::uint64_t samples = 0;
    std::vector<std::string> distinct;  // an oddity trial shows one texture twice
    for (const auto& s : first.stimuli) {
      const Document doc = parse_document(s.document_json, "stimulus");
      samples = std::max<std::uint64_t>(samples, static_cast<std::uint64_t>(doc.device.samples));
      if (std::find(distinct.begin(), distinct.end(), s.document_json) == distinct.end()) distinct.push_back(s.document_json);
    }
    if (samples > d.info.max_samples)
      throw InvalidArgument("a stimulus map has " + std::to_string(samples) + " samples; the display '" + d.info.name +
                            "' holds at most " + std::to_string(d.info.max_samples) + " (its HELLO)");
    if (d.slots.size() < distinct.size()) {
      // Each MAP_DATA frame carries up to 509 samples (1,032 bytes with framing) and waits for its ACK.
      const double bytes = std::ceil(static_cast<double>(samples) / 509.0) * 1032.0;
      const double s = bytes * 10.0 / static_cast<double>(options_.baud);
      out.push_back("the display holds " + std::to_string(d.slots.size()) + " map(s) and a trial has " +
                    std::to_string(distinct.size()) + " different stimuli: a switch to a stimulus not held uploads its " +
                    std::to_string(samples) + " samples first (about " + detail::fixed(s * 1e3, 0) + " ms at " +
                    std::to_string(options_.baud) + " baud; less on a USB link), during which the display is at rest");
    }
    return out;
  }
  if (mode_ != PresentationMode::host_streams) return out;
  // What the stream can carry: at rate R and speed v, spatial frequencies up to R / (2 v).
  const double rate = rate_hz_;
  const double limit = rate / (2.0 * swipe_mm_s);
  std::size_t texels = 0, above = 0;
  double highest = 0.0;
  for (const auto& s : first.stimuli) {
    const Surface surface = prepare_surface(parse_document(s.document_json, "stimulus"));
    for (const auto& r : surface.regions())
      if (const auto* t = dynamic_cast<const TexelTexture*>(r.texture.get()))
        for (const auto& texel : t->texels()) {
          ++texels;
          highest = std::max(highest, texel.frequency.value());
          if (texel.frequency.value() > limit) ++above;
        }
  }
  if (above > 0)
    out.push_back("host-streams at " + detail::num(rate) + " Hz carries at most " + detail::fixed(limit, 2) + " cycles/mm at a " +
                  detail::num(swipe_mm_s) + " mm/s swipe (" + detail::fixed(20.0 * std::log10(limit), 1) + " dB); " +
                  detail::fixed(100.0 * static_cast<double>(above) / static_cast<double>(texels), 0) +
                  " % of the first trial's texels lie above it (up to " + detail::fixed(highest, 2) +
                  " cycles/mm): the display cannot render them this way; a display that stores maps plays them "
                  "(display-plays)");
  return out;
}

}  // namespace texel::experiment
