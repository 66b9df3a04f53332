// Runs a checked plan: nodes in spec order, values handed from one to the
// next, each node timed, every error stopped at the node boundary. What a run
// is told (RunOptions) and what it consults around each node are in
// hooks/hooks.hpp; what it returns (RunResult) is public (orogen/session.hpp).
#pragma once

#include "hooks/hooks.hpp"
#include "spec/plan.hpp"

#include <orogen/session.hpp>

namespace orogen {

/// What the checker knows of a bound value: its type, and a heightmap's size, cell and layers.
ValueInfo describe_bound(const Value& value);

/// True if a node of `plan` declares an output path (it may write files): such a plan needs an out_dir.
bool writes_files(const Plan& plan);

/// Runs `plan`. `bound` is taken over: a value whose only holder was the caller's map is the node's to
/// change in place when no later node reads it (NodeContext::take_heightmap: no copy).
RunResult run(const Plan& plan, const RunOptions& options, BoundValues bound = {});

}  // namespace orogen
