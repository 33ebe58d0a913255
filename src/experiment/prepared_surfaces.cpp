// Prepared 2-D surfaces shared within a process (prepared_surfaces.hpp).
#include "prepared_surfaces.hpp"

#include <future>
#include <list>
#include <mutex>
#include <utility>

#include "texel/document.hpp"

namespace texel::experiment {
namespace {

using Entry = std::pair<std::string, std::shared_future<std::shared_ptr<const Surface2D>>>;

struct Cache {
  std::mutex mutex;
  std::list<Entry> entries;  // most recently asked first
};

Cache& cache() {
  static Cache c;
  return c;
}

}  // namespace

std::shared_ptr<const Surface2D> prepared_surface(const std::string& document_json) {
  Cache& c = cache();
  std::promise<std::shared_ptr<const Surface2D>> made;
  std::shared_future<std::shared_ptr<const Surface2D>> ready;
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    for (auto it = c.entries.begin(); it != c.entries.end(); ++it)
      if (it->first == document_json) {
        c.entries.splice(c.entries.begin(), c.entries, it);
        ready = it->second;
        break;
      }
    if (!ready.valid()) {
      c.entries.emplace_front(document_json, made.get_future().share());
      while (c.entries.size() > prepared_surfaces_capacity) c.entries.pop_back();
    }
  }
  if (ready.valid()) return ready.get();  // prepared, or being prepared by another thread
  try {
    auto surface = std::make_shared<const Surface2D>(prepare_surface2d(parse_document(document_json, "stimulus surface")));
    made.set_value(surface);
    return surface;
  } catch (...) {
    made.set_exception(std::current_exception());  // a waiter gets the error too
    std::lock_guard<std::mutex> lock(c.mutex);
    c.entries.remove_if([&](const Entry& e) { return e.first == document_json; });
    throw;
  }
}

}  // namespace texel::experiment
