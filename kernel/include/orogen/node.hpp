// orogen/node.hpp — how a node describes itself, once.
//
// A NodeDescriptor is all the kernel knows of a node: its kind and name, a
// one-line summary, typed parameters (default, range, unit, help), its inputs
// and outputs, an optional check hook, and the function that runs it.
// `orogen help`, spec validation and defaults are all read from it.
//
//   registry.add({
//       .kind = "generate", .name = "fault",
//       .summary = "Krten's fault algorithm: random lines raise one side and lower the other",
//       .inputs = {{"base", ValueType::heightmap, Need::optional, "terrain to cut (default: flat grid)"}},
//       .output = ValueType::heightmap,
//       .params = {
//           Param::integer("iterations", 200).min(1).max(1'000'000).help("number of fault lines"),
//           Param::real("displacement", 1.0).min(0).unit("m").help("raise/lower per line"),
//       },
//       .run = [](NodeContext& ctx) -> NodeOutputs { ... },
//   });
#pragma once

#include <orogen/tiles.hpp>
#include <orogen/values.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace orogen {

struct ProcessCall;  // orogen/process.hpp: a process of a loop node's body, checked

// ---------------------------------------------------------------- parameters

enum class ParamType { integer, real, boolean, string, choice, point, points, path };
std::string_view to_string(ParamType type);

/// A parameter value as the spec gives it (after type checking).
/// integer → int64_t, real → double, boolean → bool, string/choice/path →
/// std::string, point → Point2, points → std::vector<Point2>.
using ParamValue = std::variant<std::monostate, std::int64_t, double, bool, std::string, Point2, std::vector<Point2>>;

/// What a path parameter names.
enum class PathRole {
    input,  ///< an existing file to read; must exist at check time
    output,  ///< a file to write, relative to the output folder
};

/// One parameter's description. Build with the named constructors and chain
/// the setters: Param::real("talus", 35).min(0, exclusive).max(90, exclusive).unit("°").
struct Param {
    std::string name;  ///< snake_case, as written in the spec
    ParamType type = ParamType::real;
    ParamValue default_value;  ///< monostate: required
    std::optional<double> minimum, maximum;  ///< for integer, real, and point coordinates
    bool minimum_exclusive = false, maximum_exclusive = false;
    std::string unit_text;  ///< "m", "°", "m/s", ... ("" = dimensionless)
    std::string help_text;
    std::vector<std::string> choices;  ///< for choice (and permitted extensions for output paths, ".png")
    PathRole path_role = PathRole::output;
    std::size_t max_points = std::numeric_limits<std::size_t>::max();  ///< for points

    static Param integer(std::string name, std::optional<std::int64_t> def = std::nullopt);
    static Param real(std::string name, std::optional<double> def = std::nullopt);
    static Param boolean(std::string name, bool def);
    static Param string(std::string name, std::optional<std::string> def = std::nullopt);
    /// One of `options`; written in the spec as a bare word or a string.
    static Param choice(std::string name, std::vector<std::string> options, std::string def);
    /// A point (x, y), written `(0.5, 0.25)`.
    static Param point(std::string name, std::optional<Point2> def = std::nullopt);
    /// One or more points: `(0.5, 0.5)` or `[(0.2, 0.5), (0.8, 0.5)]`.
    static Param points(std::string name, std::optional<std::vector<Point2>> def = std::nullopt);
    /// A file path; `extensions` like {".png"} restricts output names ({} = any).
    static Param path(std::string name, PathRole role, std::vector<std::string> extensions = {},
                      std::optional<std::string> def = std::nullopt);

    Param& min(double v, bool exclusive = false) & {
        minimum = v;
        minimum_exclusive = exclusive;
        return *this;
    }
    Param& max(double v, bool exclusive = false) & {
        maximum = v;
        maximum_exclusive = exclusive;
        return *this;
    }
    Param& unit(std::string u) & {
        unit_text = std::move(u);
        return *this;
    }
    Param& help(std::string h) & {
        help_text = std::move(h);
        return *this;
    }
    Param&& min(double v, bool exclusive = false) && { return std::move(min(v, exclusive)); }
    Param&& max(double v, bool exclusive = false) && { return std::move(max(v, exclusive)); }
    Param&& unit(std::string u) && { return std::move(unit(std::move(u))); }
    Param&& help(std::string h) && { return std::move(help(std::move(h))); }
    Param&& at_most(std::size_t n) && {
        max_points = n;
        return std::move(*this);
    }

    bool required() const { return std::holds_alternative<std::monostate>(default_value); }
};

/// Whether an input must be given.
enum class Need { required, optional };

/// Whether an input takes one value or a series of them (values.hpp: Series).
enum class Many {
    /// One value of the input's type. Given a series of that type instead, the
    /// kernel maps the node over it: the node's result becomes a series with
    /// the same times whose entry j is the node run on entry j (made on demand,
    /// other inputs unchanged). So an image pass applies to every frame of a
    /// turntable with no code of its own. Only nodes with a main output map,
    /// and over one input at a time.
    one,
    series,  ///< a series whose entries are of the input's type
    either,  ///< one value or a series of the input's type; the node looks at input(i).type()
};

struct InputSpec {
    std::string name;  ///< for help and messages
    /// The value type it takes (with Many::series/either: the type of the
    /// entries); ValueType::none takes any (the node's check hook then refuses
    /// the types it cannot use, e.g. export:png takes a heightmap or an image).
    ValueType type = ValueType::heightmap;
    Need need = Need::required;
    std::string help;
    Many many = Many::one;
};

/// A value a node produces besides its main one, addressed `node.name` in the spec.
struct SideOutput {
    std::string name;
    ValueType type = ValueType::none;  ///< with `series`: the type of the entries
    std::string help;
    bool series = false;  ///< a series of `type` (e.g. an eroder's heightmap time-lapse)
};

/// "heightmap", or "series of heightmaps" when `series`.
std::string describe_type(ValueType type, bool series);

// ------------------------------------------------------------ check context

/// What the checker knows of a value before anything runs.
struct ValueInfo {
    ValueType type = ValueType::none;
    int width = 0, height = 0;  ///< heightmap/image size, 0 if unknown
    double cell = 0.0;  ///< heightmap cell size in metres, 0 if unknown
    std::set<std::string, std::less<>> layers;  ///< heightmap layers known to exist
    bool layers_known = true;  ///< false if an input may carry layers nobody declared (imports)
    /// For a series: the type of its entries (the fields above then describe an entry).
    ValueType element = ValueType::none;
    std::size_t count = 0;  ///< for a series: entries, 0 if unknown
    /// A series known to hold no entries at run time (a time-lapse with timelapse_every=0): a
    /// consumer that needs entries can refuse it at check time.
    bool empty = false;
};

/// The default grid from the spec's `grid` statement.
struct GridSpec {
    int width = 513, height = 513;  ///< vertices
    double cell = 1.0;  ///< metres
};

/// Handed to a node's check hook after the kernel has type-checked every
/// parameter and input. The hook reports errors against parameters (the
/// kernel prints them at the parameter's place in the spec) and may refine
/// what the node will output (its size, the layers it adds).
class CheckContext {
public:
    virtual ~CheckContext() = default;
    virtual const GridSpec& grid() const = 0;
    /// The share of the whole grid this machine holds for this node: in a
    /// tiled run (mpirun) of a node that runs tiled, its ranks on this machine
    /// over all ranks; 1 otherwise. For a memory check of the node's own
    /// model, which each rank holds for its tile only (plugin API 5).
    virtual double memory_share() const { return 1.0; }
    /// Info of input `i`, or nullptr if an optional input was not given.
    virtual const ValueInfo* input(std::size_t i) const = 0;
    virtual bool given(std::string_view param) const = 0;  ///< set in the spec (not defaulted)
    virtual const ParamValue& param(std::string_view name) const = 0;
    std::int64_t integer(std::string_view name) const { return std::get<std::int64_t>(param(name)); }
    double real(std::string_view name) const { return std::get<double>(param(name)); }
    bool flag(std::string_view name) const { return std::get<bool>(param(name)); }
    const std::string& text(std::string_view name) const { return std::get<std::string>(param(name)); }
    /// The path of a path parameter as the node will see it (resolved against the spec's folder for inputs).
    virtual std::filesystem::path resolved_path(std::string_view name) const = 0;
    /// Report an error at parameter `param` (or at the node call if empty).
    virtual void error(std::string_view param, std::string message) = 0;
    /// What the node outputs; starts as the kernel's default guess (see NodeDescriptor::adds_layers).
    virtual ValueInfo& output() = 0;
    /// What side value `name` will hold, to refine (e.g. mark a time-lapse that records nothing
    /// as empty); nullptr if the node declares no such side output.
    virtual ValueInfo* side_output(std::string_view name) {
        (void)name;
        return nullptr;
    }

    /// For a node that takes processes (NodeDescriptor::processes): the body's processes, checked (plugin API 9).
    virtual const std::vector<ProcessCall>& processes() const;
    /// Report an error at parameter `param` of the body's process `index` (at its call if empty).
    virtual void process_error(std::size_t index, std::string_view param, std::string message) {
        (void)index;
        error(param, std::move(message));
    }

    /// True if heightmap input `i` has layer `name` (or may have it: its layers
    /// are not known before the run). Otherwise reports at `param`
    /// "no layer 'NAME' on the input (the input's layers are: a, b); HINT" and returns false.
    bool require_layer(std::size_t i, std::string_view param, std::string_view name, std::string_view hint = {});
};

/// "the input has no layers" or "the input's layers are: a, b, c".
std::string describe_layers(const ValueInfo& info);

/// A comma-separated list parameter, e.g. layers="water, eroded" → {"water", "eroded"}: each item
/// without its surrounding spaces and tabs; empty items dropped ("" → {}).
std::vector<std::string> split_names(std::string_view text);

// -------------------------------------------------------------- run context

/// Handed to a node when it runs.
class NodeContext {
public:
    virtual ~NodeContext() = default;

    /// The node's label for messages: its value name, or `kind:name` if unnamed.
    virtual const std::string& label() const = 0;
    /// The node's own seed: derived from the spec's seed and the node's label,
    /// so adding a node does not change the others' output.
    virtual std::uint64_t seed() const = 0;
    virtual const GridSpec& grid() const = 0;

    // Parameters (already checked: right type, in range, defaults filled in).
    virtual const ParamValue& param(std::string_view name) const = 0;
    std::int64_t integer(std::string_view name) const { return std::get<std::int64_t>(param(name)); }
    double real(std::string_view name) const { return std::get<double>(param(name)); }
    bool flag(std::string_view name) const { return std::get<bool>(param(name)); }
    const std::string& text(std::string_view name) const { return std::get<std::string>(param(name)); }
    Point2 point(std::string_view name) const { return std::get<Point2>(param(name)); }
    const std::vector<Point2>& points(std::string_view name) const {
        return std::get<std::vector<Point2>>(param(name));
    }

    // Inputs, in declaration order. An optional input not given is empty.
    virtual std::size_t input_count() const = 0;
    virtual const Value& input(std::size_t i) const = 0;
    bool has_input(std::size_t i) const { return i < input_count() && bool(input(i)); }
    /// A heightmap to modify: input `i` itself when no later node reads it, else a copy.
    virtual std::shared_ptr<Heightmap> take_heightmap(std::size_t i) = 0;

    /// Where to write output file `relative` (a path parameter's value): inside
    /// the output folder, parent folders created. Write with orogen::AtomicFile.
    /// The file is listed, with its hash, in the run's manifest.json.
    virtual std::filesystem::path output_path(const std::string& relative) = 0;
    /// An input path parameter's value, resolved against the spec file's folder.
    virtual std::filesystem::path input_path(std::string_view param) const = 0;

    /// Progress of this node, 0..1 (shown as a bar on a terminal, lines otherwise).
    virtual void progress(double fraction) = 0;
    /// Throws orogen::Cancelled once the user has asked to stop.
    virtual void check_cancelled() = 0;
    virtual void info(std::string_view message) = 0;
    virtual void warn(std::string_view message) = 0;

    /// Throws orogen::Error naming the node, `what`, the step and the first bad
    /// sample if `data` holds a NaN or infinity.
    void check_finite(std::span<const float> data, std::string_view what, std::int64_t step) const;

    /// For a node that takes processes (NodeDescriptor::processes): the body's processes, in the spec's
    /// order, checked and with every parameter filled in (plugin API 9). Empty for other nodes.
    virtual const std::vector<ProcessCall>& processes() const;

    /// In a tiled (MPI) run, for a node with tile_halo >= 0: the split, this
    /// rank's tile and the halo exchange (orogen/tiles.hpp). nullptr otherwise:
    /// the node then sees the whole grid, as always.
    virtual Tiling* tiling() { return nullptr; }
};

/// What a node produced: a main value (empty for pure exporters) and side
/// values by name (declared in NodeDescriptor::side_outputs).
struct NodeOutputs {
    Value main;
    std::map<std::string, Value, std::less<>> side;
    NodeOutputs() = default;
    NodeOutputs(Value v) : main(std::move(v)) {}
    template <typename T>
    NodeOutputs(std::shared_ptr<T> v) : main(Value(std::move(v))) {}
};

// -------------------------------------------------------------- descriptor

/// How `orogen run`'s node cache (docs/cache.md) treats a node.
enum class CachePolicy {
    /// The result is a pure function of the parameters, inputs, seed, grid and plugin version: it is kept
    /// (with the files the node wrote through output_path and what it said through info/warn) and reused
    /// while none of them changes.
    store,
    /// Always run: the node reads something the spec does not name (a file's contents, a clock, a device)
    /// or has effects besides its values and output files. The nodes after it are keyed by what it
    /// produced, so an unchanged result still lets them come from the cache. The kernel treats every node
    /// with an input path parameter (the importers) this way whatever it declares.
    rerun,
};

struct NodeDescriptor {
    std::string kind;  ///< generate | erode | tectonics | render | export | import | analyze
    std::string name;  ///< kebab-case, unique within the kind
    std::string summary;  ///< one line, for `orogen list`
    std::string description;  ///< longer text for `orogen help` (optional)
    std::vector<InputSpec> inputs;
    ValueType output = ValueType::none;
    /// The main output is a series whose entries are of type `output` (e.g. render:turntable's frames).
    bool output_series = false;
    std::vector<SideOutput> side_outputs;
    std::vector<Param> params;
    /// Heightmap layers this node adds to its output (for the checker and help).
    std::vector<std::string> adds_layers;
    /// Whether the node runs tiled under MPI (orogen/tiles.hpp): -1 it cannot
    /// (it runs on rank 0 over the whole grid, gathered there); h >= 0 it runs
    /// on every rank's tile and needs a halo of h vertices from each neighbour
    /// (so every tile must be at least h vertices wide and high).
    int tile_halo = -1;
    /// Optional cross-parameter and input checks, run at check time.
    std::function<void(CheckContext&)> check;
    std::function<NodeOutputs(NodeContext&)> run;
    /// A node that runs a loop whose body the spec gives as processes in braces after the call
    /// (orogen/process.hpp): `NAME = erode:evolve(...) { uplift(...) flow() ... }` (plugin API 9).
    /// The kernel checks the body against the registered processes and the fields they declare.
    bool processes = false;
    /// Whether its result may come from the cache (plugin API 3).
    CachePolicy cache = CachePolicy::store;
    /// A tiled node (tile_halo >= 0) that records its time-lapse under mpirun
    /// too (a Timelapse made with the Tiling: rank 0 gathers the frames). If
    /// false, the kernel refuses timelapse_every > 0 in a tiled run at check
    /// time (plugin API 4).
    bool tiled_timelapse = false;
    /// A tiled node (tile_halo >= 0) that tiles only some of its settings:
    /// given the parameters (every one, defaults filled in) and which inputs
    /// the spec gives, "" when it runs tiled, else why it does not (a few
    /// words, e.g. "routing=mfd is not tiled yet"): it then runs on rank 0
    /// over the whole grid, gathered there, as an untiled node does, and the
    /// run says why. Empty: always tiled (plugin API 5).
    std::function<std::string(const std::map<std::string, ParamValue, std::less<>>& params,
                              const std::vector<bool>& inputs_given)>
        untiled_because;

    /// A tiled loop node (processes = true, tile_halo >= 0) that tiles only some bodies: given its checked
    /// body, "" when it runs tiled, else why not (plugin API 9). Asked after untiled_because.
    std::function<std::string(const std::vector<ProcessCall>& body)> untiled_body_because;

    std::string qualified_name() const { return kind + ":" + name; }
    const Param* find_param(std::string_view n) const;
};

}  // namespace orogen
