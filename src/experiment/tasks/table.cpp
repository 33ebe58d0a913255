// The task table: every task kind a protocol may name, in one list
// (docs/experiments.md "Adding a task kind"). A kind is one file in this
// folder defining make_<kind>_task(), and one row here.
#include <mutex>

#include "../task.hpp"
#include "texel/error.hpp"

namespace texel::experiment {

// X(kind): one row per task kind, in the order protocols list them.
#define TEXEL_TASK_TABLE(X) \
  X(oddity)                 \
  X(two_alternative)        \
  X(match)                  \
  X(rating)                 \
  X(guided)                 \
  X(same_different)         \
  X(familiarisation)        \
  X(oddity_2d)              \
  X(playback_oddity)

#define TEXEL_DECLARE_TASK(kind) std::unique_ptr<TaskType> make_##kind##_task();
TEXEL_TASK_TABLE(TEXEL_DECLARE_TASK)
#undef TEXEL_DECLARE_TASK

namespace {

struct Table {
  std::mutex mutex;
  std::vector<std::unique_ptr<TaskType>> kinds;
  Table() {
#define TEXEL_ADD_TASK(kind) kinds.push_back(make_##kind##_task());
    TEXEL_TASK_TABLE(TEXEL_ADD_TASK)
#undef TEXEL_ADD_TASK
  }
};

/// Never destroyed: a thread still running at exit (a studio Service held in
/// a static, its worker finishing a job while statics are torn down) may
/// still look a task kind up.
Table& table() {
  static Table* const t = new Table;
  return *t;
}

}  // namespace

const TaskType* find_task_type(std::string_view name) {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  for (const auto& k : t.kinds)
    if (k->name() == name) return k.get();
  return nullptr;
}

const TaskType& task_type(std::string_view name, std::string_view field) {
  if (const TaskType* k = find_task_type(name)) return *k;
  Table& t = table();
  std::lock_guard lock(t.mutex);
  std::string known;
  for (const auto& k : t.kinds) known += (known.empty() ? "" : ", ") + std::string(k->name());
  throw FormatError(std::string(field) + " is '" + std::string(name) + "'; allowed: " + known);
}

void register_task(std::unique_ptr<TaskType> type) {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  for (const auto& k : t.kinds)
    if (k->name() == type->name()) throw InvalidArgument("task kind '" + std::string(type->name()) + "' is registered already");
  t.kinds.push_back(std::move(type));
}

std::vector<const TaskType*> task_types() {
  Table& t = table();
  std::lock_guard lock(t.mutex);
  std::vector<const TaskType*> out;
  for (const auto& k : t.kinds) out.push_back(k.get());
  return out;
}

std::vector<std::string> task_names() {
  std::vector<std::string> out;
  for (const TaskType* k : task_types()) out.emplace_back(k->name());
  return out;
}

}  // namespace texel::experiment
