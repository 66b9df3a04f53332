// orogen/process.hpp — processes: the parts of a landscape-evolution loop, each a plugin of its own.
//
// A node that runs a loop over time (erode:evolve) takes the loop's body from the spec as a list of
// processes in braces after its call, run in that order every step:
//
//   range = erode:evolve(core, years=3e6, dt=6e4, open="ns") {
//       uplift(rate=1, layer="uplift", layer_years=4.5e5, smoothing=4000)
//       flow()
//       creep(diffusivity=1.2)
//       stream-power(m=0.5, erodibility=1.25e-5, channel_area=4e4)
//       landslides(angle=35)
//   }
//
// A process describes itself once, in a ProcessDescriptor (as a node does in a NodeDescriptor): its
// typed parameters, the fields it reads and writes with their units, when in a step it runs, and how
// far it reaches under tiles. `orogen list` and `orogen help` read it, and the checker checks every
// list against it before anything runs: an unknown process, a field that a process reads and none
// before it makes, two processes that both make one field. The model is landlab's components
// (run_one_step, declared fields with units) and fastscapelib's shared flow graph, composed as LLVM
// composes passes: by a text pipeline that is checked first.
//
// Parameters bind to the members of a plain settings struct (ProcessParams below): the default is
// the member's own initialiser, written once.
//
//   struct Creep { double diffusivity = 0.01; };  // m²/yr
//   ProcessParams<Creep> p;
//   p.real(&Creep::diffusivity, "diffusivity").min(0).unit("m²/yr").help("hillslope diffusivity D");
//   registry.add(ProcessDescriptor{
//       .name = "creep", .summary = "...", .params = p.params(),
//       .fields = {{"elevation", FieldAccess::updates, "m", "diffused"}},
//       .make = [p](const ProcessCall& call) { return std::make_unique<CreepProcess>(p.bind(call.params)); },
//   });
#pragma once

#include <orogen/node.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace orogen {

// ------------------------------------------------------------------ fields

/// How a process uses a field (a grid of doubles, one per vertex, shared by the processes of a loop).
enum class FieldAccess {
    reads,  ///< needs it: made by the node (elevation, uplifted) or by a process before this one
    reads_if_present,  ///< uses it when a process before this one makes it, does without otherwise
    writes,  ///< makes it anew each time it runs; one process writes a field
    adds,  ///< adds to it (after its writer, if any); any number may add
    updates,  ///< changes it in place (elevation): any number, in the list's order
};
std::string_view to_string(FieldAccess access);

struct FieldUse {
    std::string field;  ///< snake_case: "elevation", "erodibility_factor", ... ("flow": the flow graph)
    FieldAccess access = FieldAccess::reads;
    std::string unit;  ///< "m", "m/m", "1" (dimensionless), ...
    std::string help;
};

/// The fields every loop starts with (the node makes them): elevation (m) and uplifted (m, the rock
/// uplift received so far, for the `eroded` layer).
inline constexpr const char* kElevation = "elevation";
inline constexpr const char* kUplifted = "uplifted";
/// The flow graph: not a grid but a shared service, made by a routing process once a step and read by
/// the processes that follow water downhill. The checker treats it as a field.
inline constexpr const char* kFlowGraph = "flow";

/// The flow graph of the current surface, as plain arrays over the grid's cells (index y·width + x).
/// Receivers come before their donors in `stack`; the stack splits into independent groups of outlet
/// basins at `chunks` (chunk g is stack[chunks[g], chunks[g+1])), which a process may solve in parallel.
struct FlowGraph {
    int width = 0, height = 0;
    double cell = 0.0;  ///< m
    std::span<const std::int32_t> receivers;  ///< each cell's receiver; itself at an outlet or a pit
    std::span<const std::int32_t> stack;  ///< receivers before donors
    std::span<const std::int64_t> chunks;  ///< stack bounds of independent groups of basins
    std::span<const double> area;  ///< drainage area, m² (weighed by the rain_factor field when one is made)
    std::span<const std::uint8_t> outlets;  ///< 1 at base level (an open side, or the sink of a closed map)
    std::span<const std::int8_t> directions;  ///< direction(i) of every cell, made once with the graph
    std::int64_t pits = 0;  ///< pits resolved when it was made
    /// The area is split among several lower neighbours (multiple flow directions), not summed down
    /// the receivers alone (D8); the receivers are the steepest either way.
    bool multiple = false;
    bool valid() const { return !receivers.empty(); }
    /// Distance (m) from cell i to its receiver: cell, cell·√2, or 0 at a root.
    double distance(std::int64_t i) const;
    /// The direction from cell i to its receiver, 0..7 counter-clockwise from east with y down
    /// (dx, dy) = (1,0), (1,1), (0,1), (-1,1), (-1,0), (-1,-1), (0,-1), (1,-1); −1 at a root.
    int direction(std::int64_t i) const;
};

/// Which sides of the map are held at base level (water leaves there); all closed: the lowest cell.
struct OpenSides {
    bool north = true, east = true, south = true, west = true;  ///< north = row 0, west = column 0
    bool any() const { return north || east || south || west; }
};

// ------------------------------------------------------------------ running

/// What a running process sees: the grid, the loop's clock, the shared fields and the flow graph.
/// The loop's node makes it; a process keeps its own state in its own members.
class ProcessState {
public:
    virtual ~ProcessState() = default;

    virtual int width() const = 0;
    virtual int height() const = 0;
    virtual double cell() const = 0;  ///< m
    std::size_t size() const { return std::size_t(width()) * std::size_t(height()); }
    virtual const OpenSides& open() const = 0;
    /// 1 where a cell is at base level: the open sides' cells, or the lowest cell of a closed map.
    virtual const std::vector<std::uint8_t>& outlets() const = 0;

    /// Years simulated before this step; the step is step_years() long, in substeps() sub-steps of
    /// which this is substep() (0-based).
    virtual double time() const = 0;
    virtual double step_years() const = 0;
    virtual int substep() const = 0;
    virtual int substeps() const = 0;
    virtual std::int64_t step() const = 0;  ///< 1-based; 0 in start()
    virtual double run_years() const = 0;  ///< how long the whole run lasts

    /// A field this process declared (FieldAccess), as a grid of size() doubles, or empty where a
    /// process that makes it has not made it (yet) or makes it uniform this step (a reader then uses
    /// its own default, e.g. an erodibility factor of 1).
    virtual std::vector<double>& field(std::string_view name) = 0;
    /// Whether a process later in the list (or the node) reads `name`: a writer may skip a field
    /// nobody reads.
    virtual bool wanted(std::string_view name) const = 0;

    /// The flow graph made this step by the routing process; invalid before it.
    virtual const FlowGraph& flow() const = 0;
    /// For the routing process: publish the graph (its arrays must live until the next publish).
    virtual void set_flow(const FlowGraph& graph) = 0;

    /// The process's seed: the node's, mixed with the process's label when the process appears more
    /// than once in the list (so the first of each name draws what the whole node drew before).
    virtual std::uint64_t seed() const = 0;
    /// The node's terrain as it was given (its layers: e.g. an 'uplift' layer) and its other inputs.
    virtual const Heightmap& terrain() const = 0;
    virtual const Value& node_input(std::size_t i) const = 0;
    /// In a tiled run: the tiling (the grid above is then this rank's tile); nullptr otherwise.
    virtual Tiling* tiling() { return nullptr; }

    virtual void info(std::string_view message) = 0;
    virtual void warn(std::string_view message) = 0;
};

/// One process of a loop, made by its descriptor's `make` from its checked parameters.
class Process {
public:
    virtual ~Process() = default;
    /// Once, before the first step: build what depends on the start (rates, tables, solvers).
    virtual void start(ProcessState& state) { (void)state; }
    /// One (sub-)step of `dt` years.
    virtual void step(ProcessState& state, double dt) = 0;
    /// Once, after the last step: add output layers to `out` (the node's result, heights written).
    virtual void finish(ProcessState& state, Heightmap& out) {
        (void)state;
        (void)out;
    }
    /// One clause for the node's summary line ("" = nothing to say), e.g. "1.2 km³ of sediment left".
    virtual std::string summary() const { return {}; }
};

/// When a process runs within a step of `substeps` sub-steps.
enum class Cadence {
    every_substep,  ///< every sub-step (uplift, creep, incision, landslides)
    once_per_step,  ///< on the first sub-step only (routing, rain): its result serves the whole step
};

/// A process as the spec calls it, checked: every parameter (defaults filled in) and which were given.
struct ProcessDescriptor;
struct ProcessCall {
    const ProcessDescriptor* process = nullptr;
    std::string label;  ///< its name, or name#2, name#3 for later ones of the same name
    std::map<std::string, ParamValue, std::less<>> params;
    std::set<std::string, std::less<>> given;
    bool flag(std::string_view n) const { return std::get<bool>(params.find(n)->second); }
    double real(std::string_view n) const { return std::get<double>(params.find(n)->second); }
};

// ------------------------------------------------------------------ checking

/// Handed to a process's check hook, after its parameters were type- and range-checked.
class ProcessCheckContext {
public:
    virtual ~ProcessCheckContext() = default;
    virtual const GridSpec& grid() const = 0;
    virtual const ProcessCall& call() const = 0;
    bool given(std::string_view p) const { return call().given.count(p) > 0; }
    const ParamValue& param(std::string_view p) const;
    double real(std::string_view p) const { return std::get<double>(param(p)); }
    std::int64_t integer(std::string_view p) const { return std::get<std::int64_t>(param(p)); }
    bool flag(std::string_view p) const { return std::get<bool>(param(p)); }
    const std::string& text(std::string_view p) const { return std::get<std::string>(param(p)); }
    /// Info of the loop node's input `i` (nullptr if not given), e.g. to check a layer exists.
    virtual const ValueInfo* node_input(std::size_t i) const = 0;
    /// Report an error at parameter `param` of this process's call (at the call if empty).
    virtual void error(std::string_view param, std::string message) = 0;
};

// ------------------------------------------------------------------ descriptor

struct ProcessDescriptor {
    std::string name;  ///< kebab-case, unique among processes: "stream-power"
    std::string summary;  ///< one line, for `orogen list`
    std::string description;  ///< longer text for `orogen help` (optional)
    std::vector<Param> params;  ///< at most ~15: a process does one thing
    std::vector<FieldUse> fields;
    Cadence cadence = Cadence::every_substep;
    /// Layers it adds to the node's result in finish() (for the checker and help).
    std::vector<std::string> adds_layers;
    /// Under tiles: −1 it is not tiled (a loop with it runs on rank 0 over the whole grid); h ≥ 0 it
    /// runs on each tile and reads h vertices of its neighbours' fields.
    int tile_halo = -1;
    /// Optional: the longest stable sub-step (years) for these parameters on cells of `cell` metres
    /// (an explicit scheme's limit); the loop's node refuses a longer one at check time.
    std::function<double(const ProcessCall& call, double cell)> max_dt;
    std::function<void(ProcessCheckContext&)> check;
    std::function<std::unique_ptr<Process>(const ProcessCall& call)> make;
};

// ------------------------------------------------------------------ typed parameters

/// A process's parameters bound to the members of its settings struct S: each parameter's default is
/// the member's initial value in S{}, and bind() fills an S from a checked call. Angles, rates and the
/// like stay in the units the spec writes (°, mm/yr): the process converts them where it uses them.
template <class S>
class ProcessParams {
public:
    Param& real(double S::*member, std::string name) {
        return add(Param::real(std::move(name), S{}.*member),
                   [member](S& s, const ParamValue& v) { s.*member = std::get<double>(v); });
    }
    Param& integer(int S::*member, std::string name) {
        return add(Param::integer(std::move(name), S{}.*member),
                   [member](S& s, const ParamValue& v) { s.*member = int(std::get<std::int64_t>(v)); });
    }
    Param& flag(bool S::*member, std::string name) {
        return add(Param::boolean(std::move(name), S{}.*member),
                   [member](S& s, const ParamValue& v) { s.*member = std::get<bool>(v); });
    }
    Param& text(std::string S::*member, std::string name) {
        return add(Param::string(std::move(name), S{}.*member),
                   [member](S& s, const ParamValue& v) { s.*member = std::get<std::string>(v); });
    }
    Param& choice(std::string S::*member, std::string name, std::vector<std::string> options) {
        return add(Param::choice(std::move(name), std::move(options), S{}.*member),
                   [member](S& s, const ParamValue& v) { s.*member = std::get<std::string>(v); });
    }

    const std::vector<Param>& params() const { return params_; }
    /// S with every bound member set from `values` (a checked call's params: every one present).
    S bind(const std::map<std::string, ParamValue, std::less<>>& values) const {
        S s{};
        for (std::size_t k = 0; k < params_.size(); ++k)
            if (auto it = values.find(params_[k].name); it != values.end()) setters_[k](s, it->second);
        return s;
    }

private:
    using Setter = std::function<void(S&, const ParamValue&)>;
    Param& add(Param p, Setter set) {
        params_.push_back(std::move(p));
        setters_.push_back(std::move(set));
        return params_.back();
    }
    std::vector<Param> params_;
    std::vector<Setter> setters_;
};

}  // namespace orogen
