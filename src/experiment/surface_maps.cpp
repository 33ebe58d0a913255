// The player maps of a 2-D session's intervals (surface_maps.hpp).
#include "texel/experiment/surface_maps.hpp"

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include "prepared_surfaces.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/surface2d.hpp"

namespace texel::experiment {
namespace {

// The preload's thread yields to the participant's (nice +10 on Linux; the
// threads it starts to render inherit it). Elsewhere it runs as it is.
void lower_this_threads_priority() {
#if defined(__linux__)
  (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 10);
#endif
}

void check(const Document& doc) {
  if (!doc.surface2d || doc.surface2d->regions.size() != 1 || !doc.device.bitmap)
    throw InvalidArgument("a stimulus surface must be a version-4 document of one region on a display with a bitmap grid");
}

}  // namespace

std::unique_ptr<const PlayerMap2D> SurfaceMaps::map(const SurfaceStimulus& s) {
  if (s.kind == SurfaceStimulus::Kind::bitmap) return std::make_unique<const PlayerMap2D>(*bitmap(s.document_json, true));
  const Document doc = parse_document(s.document_json, "stimulus surface");
  check(doc);
  const BitmapGeometry& g = *doc.device.bitmap;
  return PlayerMap2D::path_indexed(doc.surface2d->regions[0].texel, Sampling{doc.device.grid(), CyclesPerMm(0.0)}, std::nullopt,
                                   Extent2D{0.0, 0.0, g.width_mm().value(), g.height_mm().value()}, 10000.0, doc.device.response);
}

void SurfaceMaps::prepare(const Question& question) {
  // The bitmaps (a path-indexed map is made when shown, in well under a millisecond).
  for (const auto& s : question.surfaces)
    if (s.kind == SurfaceStimulus::Kind::bitmap) (void)bitmap(s.document_json, true);
}

// The cached bitmap of a surface document, rendered by this thread if no
// other has it or is rendering it. `shown`: the participant needs it now
// (it becomes the most recent); the preload's (shown false) never pushes
// a bitmap out of a full cache, and gives up (nullptr) instead.
std::shared_ptr<const PlayerMap2D> SurfaceMaps::bitmap(const std::string& document_json, bool shown) {
  std::promise<std::shared_ptr<const PlayerMap2D>> made;
  MapFuture ready;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = bitmaps_.begin(); it != bitmaps_.end(); ++it)
      if (it->first == document_json) {
        if (shown) bitmaps_.splice(bitmaps_.begin(), bitmaps_, it);
        ready = it->second;
        break;
      }
    if (!ready.valid()) {
      if (!shown && bitmaps_.size() >= cache_size) return nullptr;
      bitmaps_.emplace_front(document_json, made.get_future().share());
      // The least recently shown ready bitmap makes room (one being
      // rendered stays: its renderer will fill it).
      for (auto it = bitmaps_.end(); bitmaps_.size() > cache_size && it != bitmaps_.begin();) {
        --it;
        if (it->second.wait_for(std::chrono::seconds(0)) == std::future_status::ready) it = bitmaps_.erase(it);
      }
    }
  }
  if (ready.valid()) return ready.get();
  try {
    const Document doc = parse_document(document_json, "stimulus surface");
    check(doc);
    std::shared_ptr<const PlayerMap2D> m =
        PlayerMap2D::bitmap(render_raster(*prepared_surface(document_json)), doc.device.response);
    ++(shown ? rendered_when_shown_ : rendered_ahead_);
    made.set_value(m);
    return m;
  } catch (...) {
    made.set_exception(std::current_exception());
    std::lock_guard<std::mutex> lock(mutex_);
    bitmaps_.remove_if([&](const auto& e) { return e.first == document_json; });
    throw;
  }
}

// Stops at a full cache, at the end, on stop(), or at the first error (the
// trial itself then renders, and reports it).
void SurfaceMaps::preload(const Protocol& protocol, const SessionContext& context) {
  if (preloader_.joinable()) return;
  preloader_ = std::jthread([this, protocol, context](const std::stop_token& stop) {
    lower_this_threads_priority();
    try {
      render_ahead(Session(protocol, context), stop);
    } catch (...) {
      // The trial that needs the map renders it and reports the error.
    }
    preloaded_ = true;
  });
}

void SurfaceMaps::stop() {
  if (preloader_.joinable()) {
    preloader_.request_stop();
    preloader_.join();  // at most the bitmap being rendered (about a second)
  }
}

void SurfaceMaps::render_ahead(Session shadow, const std::stop_token& stop) {
  while (!stop.stop_requested() && !shadow.finished()) {
    const Question& q = shadow.question();
    for (const SurfaceStimulus& s : q.surfaces) {
      if (stop.stop_requested()) return;
      if (s.kind == SurfaceStimulus::Kind::bitmap && !bitmap(s.document_json, false)) return;  // the cache is full
    }
    Response r;
    r.choice = q.choices.empty() ? std::string() : q.choices.front();
    (void)shadow.answer(r);
  }
}

}  // namespace texel::experiment
