// The displays a Presenter drives with the participant's finger (internal;
// presenter.hpp, docs/experiments.md): a 2-D display the participant strokes
// and a 1-D serial display with a finger sensor (its slots, uploads, host
// watchdog and reports). Their members are in presenter_displays.cpp; the
// Presenter that owns them in presenter.cpp.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "texel/document.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/surface_maps.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/surface.hpp"

namespace texel::experiment {

namespace presenter_parts {

// A document plays on a presenter of as many channels as its device has
// actuators, or of any number if it has one (presenter.hpp). Refused in one
// line naming the device, its actuators and the fix.
void check_channels(const Document& doc, std::size_t here);

// The one map a one-channel display plays of `doc`: the document's own
// surface, or, for a simultaneous document of one actuator, that actuator's
// chain (its channel seed; the base seed's chain is none of its channels).
std::shared_ptr<const Surface> one_channel_surface(const Document& doc);

}  // namespace presenter_parts

// ------------------------------------------------------------- 2-D display

// The participant's finger on a 2-D display: the display's FINGER reports,
// read on their own thread, queued into the Player2D at their place on the
// player's clock and summarised per interval.
struct Presenter::Display2D {
  explicit Display2D(const PlayerConfig& config, const StrokeRules& r) : player(config), rules(r) {}
  ~Display2D() { stop(); }

  void start(SerialLink& l);
  void stop();
  [[nodiscard]] bool running() const { return reader && !reader->stopping(); }
  [[nodiscard]] std::string error() const { return reader ? reader->error() : std::string(); }

  // Stops recording into the current interval (its stroke in progress ends).
  void leave();
  void enter(const std::string& label);

  SurfaceMaps maps;  // stopped in stop(), before the player goes
  Player2D player;
  StrokeRules rules;
  SerialLink* link = nullptr;
  std::unique_ptr<SerialLink> own_link;
  ReportTimeline timeline;   // the reader's
  ReportClock clock;         // the reader's
  mutable std::mutex mutex;  // guards what follows (the reader thread writes it)
  std::map<std::string, StrokeRecorder> recorders;
  std::string current;  // the interval being recorded
  double last_t = 0.0;
  std::uint64_t reports = 0, dropped = 0;
  std::optional<ReportReader> reader;  // last: stopped first
};

// --------------------------------------------------------- 1-D serial display

// A 1-D serial display with a finger sensor: its reports (read on the
// control thread by pump() in display-plays, where requests and reports
// share the thread, or on their own thread in host-streams, where the
// player takes them) become the trial's finger trace; in display-plays the
// display's slots hold the trial's stimuli.
struct Presenter::Display1D {
  std::unique_ptr<SerialLink> own_link;  // FingerSource::sensor: the sensor's own link (the backend has another)
  SerialLink* link = nullptr;
  DisplayInfo info;
  bool sensor = false;
  std::uint32_t report_interval_us = 1000;
  ReportClock clock;        // the display's t_us unwrapped (the trace's time)
  ReportTimeline timeline;  // host-streams: the reports on the player's clock

  // display-plays: which stimulus each slot holds (its document), and when it was last felt.
  struct Slot {
    std::string document;
    std::uint64_t used = 0;
  };
  std::vector<Slot> slots;
  int selected = -1;
  std::uint64_t tick = 0;
  // Rendered maps (u16 samples), most recent first: a reference recurs.
  struct Rendered {
    std::string document;
    std::vector<std::uint16_t> samples;
    std::uint32_t spacing_nm = 0;
    std::int32_t origin_nm = 0;
  };
  std::list<Rendered> rendered;
  UploadCounts uploads;

  mutable std::mutex mutex;  // guards what follows (host-streams: the reader thread writes it)
  bool recording = false;
  std::vector<FingerSample> trace;
  std::uint64_t reports = 0, dropped = 0;
  double first_s = 0.0;
  std::string error;
  std::optional<ReportReader> reader;  // host-streams only; last: stopped first

  // display-plays: nothing streams, so no stream watchdog covers the map the
  // display plays under the finger. A display of revision 1.2 has its host
  // watchdog armed (host_watchdog_ms) and fed from a thread of its own every
  // keepalive_ms, whatever the control thread is doing (rendering, an
  // upload, waiting for a key): when this host dies (kill -9) or hangs, the
  // display rests by itself within host_watchdog_ms. Re-armed at every
  // trial (a display that timed out disarms itself).
  static constexpr std::uint32_t host_watchdog_ms = 200;
  static constexpr auto keepalive_every = std::chrono::milliseconds(40);
  bool host_watchdog = false;  // the display took HOST_WATCHDOG
  std::mutex keepalive_mutex;
  std::condition_variable_any keepalive_wake;
  std::jthread keepalive;  // stopped before the link is rested or goes

  void arm_host_watchdog();
  void stop_keepalive();

  void record(const FingerReport& r);  // under mutex

  // display-plays: drains the reports that arrived (control thread).
  void drain();

  const Rendered& render(const std::string& document_json);

  // The slot holding `document_json`, uploading it over the least recently
  // felt slot that is not playing (or, with one slot, after SELECT none).
  int hold(const std::string& document_json, bool at_switch);

  void select(int slot);
};

}  // namespace texel::experiment
