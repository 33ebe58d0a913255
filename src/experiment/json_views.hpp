// The library's own JSON views of its result types (internal; the public
// headers hand out JSON text so that nlohmann-json stays a private, build-time
// dependency). Every front door's JSON comes from these: the public
// to_json() functions dump them, the engine stores them, analyze() builds on
// them. Field names: docs/format.md "Result field names".
#pragma once

#include <memory>
#include <string_view>

#include <nlohmann/json.hpp>

#include "texel/experiment/guided.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/stats.hpp"
#include "texel/experiment/store.hpp"

namespace texel::experiment {

/// The question as the engine stores it (keys in a fixed order; the bytes
/// are compared on resume, so this order and these names never change).
nlohmann::ordered_json question_view(const Question& q);
nlohmann::ordered_json response_view(const Response& r);
Response response_from(const nlohmann::json& j);
nlohmann::ordered_json session_view(const SessionInfo& s);

/// make_optimizer() from a parsed parameter object.
std::unique_ptr<MatchOptimizer> make_optimizer_from(OptimizerKind kind, const nlohmann::json& params);

/// validate_observer() of a parsed observer object.
void validate_observer_object(const nlohmann::json& observer);

/// Parses JSON text the library wrote itself (or a front end handed in),
/// throwing FormatError naming `what` when it is not JSON.
nlohmann::json parse_json_text(std::string_view text, std::string_view what);

namespace stats {
nlohmann::ordered_json view(const Descriptive& d);
nlohmann::ordered_json view(const TTest& t);
nlohmann::ordered_json view(const AnovaTable& a);
nlohmann::ordered_json view(const Ellipse& e);
nlohmann::ordered_json view(const TwoSampleTTest& t);
nlohmann::ordered_json view(const OneWayAnova& a);
nlohmann::ordered_json view(const Correlation& c);
}  // namespace stats

}  // namespace texel::experiment
