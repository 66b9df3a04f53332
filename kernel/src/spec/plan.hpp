// The checked form of a spec: what the runner executes. Produced by check(),
// which resolves every node against the registry, converts and range-checks
// every parameter, binds inputs to earlier values and runs each node's check
// hook; nothing runs until all of that passed.
#pragma once

#include "spec.hpp"

#include <orogen/plugin.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace orogen {

struct PlannedNode {
    const NodeDescriptor* node = nullptr;
    std::string label;  ///< value name, or kind:node for unnamed calls
    std::string value_name;  ///< "" if unnamed; a call written where an input goes: its label
    bool in_place = false;  ///< a call written where an input goes (unnamed, but its value is read)
    spec::Location where;  ///< the call
    std::vector<std::string> inputs;  ///< value keys ("base", "sim.particles"), "" for an optional input not given
    std::map<std::string, ParamValue, std::less<>> params;  ///< every declared parameter, defaults filled in
    std::set<std::string, std::less<>> given;  ///< parameters set in the spec or by --set
    std::vector<std::string> output_files;  ///< output path parameters' values
    /// A loop node's body (NodeDescriptor::processes): its processes, checked, in the spec's order.
    std::vector<ProcessCall> processes;
    /// The input (Many::one) that was given a series: the node is mapped over
    /// its entries and outputs a series (-1: runs once, as usual).
    int mapped_input = -1;
};

struct Plan {
    std::filesystem::path spec_path;
    std::filesystem::path spec_folder;  ///< input paths are relative to it
    std::shared_ptr<const spec::Source> source;
    std::uint64_t seed = 0;
    GridSpec grid;
    bool grid_given = false;  ///< a `grid` line (else 513 x 513)
    bool cell_given = false;  ///< its cell= (else 1 m)
    std::vector<PlannedNode> nodes;
    std::vector<std::string> overrides;  ///< as given on the command line
    /// For each value key, the index of the last node that reads it.
    std::map<std::string, std::size_t, std::less<>> last_use;
};

struct CheckOptions {
    std::vector<std::string> overrides;  ///< "NAME.PARAM=VALUE"
    std::optional<std::uint64_t> seed;  ///< --seed, overrides the spec's
    /// Memory a single heightmap may take before the grid is refused, bytes (0: a quarter of physical memory).
    std::uint64_t heightmap_memory_limit = 0;
    /// --out: every output path must resolve inside it, unless allow_outside_out (--allow-outside-out).
    std::filesystem::path out_dir = "out";
    bool allow_outside_out = false;
    /// A tiled run: the ranks on this machine over all ranks (CheckContext::memory_share of a tiled node).
    double tiled_memory_share = 1.0;
    /// Values the host binds by name before the run (the Python module's node() inputs; run()'s `bound`):
    /// the spec reads `name` as if an earlier line had made a value like this (describe_bound() gives it).
    /// A line that defines one of these names is an error.
    std::map<std::string, ValueInfo, std::less<>> bound;
};

/// "" if `node` runs on every rank's tile in a tiled run (docs/mpi.md), else why it runs on rank 0 over the
/// whole grid: a question the plan answers, for the checker, the tiled run and the messages alike.
std::string untiled_reason(const PlannedNode& node);
inline bool runs_tiled(const PlannedNode& node) { return untiled_reason(node).empty(); }

/// Check `parsed` against `registry`. Errors go to `diags`; the plan is only
/// meaningful if !diags.has_errors().
Plan check(const spec::Spec& parsed, const Registry& registry, const std::filesystem::path& spec_path,
           const CheckOptions& options, spec::Diagnostics& diags);

}  // namespace orogen
