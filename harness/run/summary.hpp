#pragma once
// The run summary: the contract metric names of README "Summary metrics" (flat keys such as
// "time_s.tool"), plus a few extras, computed from a RunResult.
#include <nlohmann/json.hpp>

#include "harness/run/runner.hpp"

namespace sb {

using Json = nlohmann::ordered_json;

// Timing metrics cover the stroke's steps; the relaxation after the stroke is reported
// separately as "time_s.relax" so per-step figures describe interactive work.
Json summarize(const RunResult& run, const PreparedScene& prepared);

}  // namespace sb
