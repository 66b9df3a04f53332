#include <orogen/error.hpp>
#include <orogen/node.hpp>
#include <orogen/process.hpp>
#include <orogen/tiles.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace orogen {

std::string_view to_string(ParamType type) {
    switch (type) {
        case ParamType::integer: return "integer";
        case ParamType::real: return "number";
        case ParamType::boolean: return "boolean";
        case ParamType::string: return "string";
        case ParamType::choice: return "choice";
        case ParamType::point: return "point";
        case ParamType::points: return "points";
        case ParamType::path: return "path";
    }
    return "?";
}

std::string describe_type(ValueType type, bool series) {
    if (type == ValueType::none) return series ? "series" : "value";  // an input that takes any value
    if (!series) return std::string(to_string(type));
    // Plurals: heightmaps, images, plates (already plural), particles (already plural).
    std::string entry(to_string(type));
    if (type == ValueType::heightmap || type == ValueType::image) entry += "s";
    return "series of " + entry;
}

Param Param::integer(std::string name, std::optional<std::int64_t> def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::integer;
    if (def) p.default_value = *def;
    return p;
}

Param Param::real(std::string name, std::optional<double> def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::real;
    if (def) p.default_value = *def;
    return p;
}

Param Param::boolean(std::string name, bool def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::boolean;
    p.default_value = def;
    return p;
}

Param Param::string(std::string name, std::optional<std::string> def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::string;
    if (def) p.default_value = *def;
    return p;
}

Param Param::choice(std::string name, std::vector<std::string> options, std::string def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::choice;
    p.choices = std::move(options);
    p.default_value = std::move(def);
    return p;
}

Param Param::point(std::string name, std::optional<Point2> def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::point;
    if (def) p.default_value = *def;
    return p;
}

Param Param::points(std::string name, std::optional<std::vector<Point2>> def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::points;
    if (def) p.default_value = *def;
    return p;
}

Param Param::path(std::string name, PathRole role, std::vector<std::string> extensions,
                  std::optional<std::string> def) {
    Param p;
    p.name = std::move(name);
    p.type = ParamType::path;
    p.path_role = role;
    p.choices = std::move(extensions);
    if (def) p.default_value = *def;
    return p;
}

const Param* NodeDescriptor::find_param(std::string_view n) const {
    for (const auto& p : params)
        if (p.name == n) return &p;
    return nullptr;
}

std::string describe_layers(const ValueInfo& info) {
    if (info.layers.empty()) return "the input has no layers";
    std::string s = "the input's layers are: ";
    bool first = true;
    for (const auto& l : info.layers) {
        s += (first ? "" : ", ") + l;
        first = false;
    }
    return s;
}

bool CheckContext::require_layer(std::size_t i, std::string_view param, std::string_view name, std::string_view hint) {
    const ValueInfo* in = input(i);
    if (!in || !in->layers_known || in->layers.count(name)) return true;
    std::string message = "no layer '" + std::string(name) + "' on the input (" + describe_layers(*in) + ")";
    if (!hint.empty()) message += "; " + std::string(hint);
    // No layers at all: perhaps a node of one's own adds the layer without declaring it.
    if (in->layers.empty())
        message +=
            " (a node that adds a layer declares it in its descriptor's adds_layers, so the checker "
            "knows it is there: docs/plugins.md)";
    error(param, std::move(message));
    return false;
}

namespace {

/// The one finiteness check: the first NaN or infinity among `rows` rows of
/// `width` values, row y starting at data + y·stride, throws Error naming it
/// by its sample index: first_sample + y·sample_stride + x (its index in the
/// whole grid when the rows are part of a tile).
void check_finite_rows(const float* data, std::size_t width, std::size_t rows, std::size_t stride,
                       std::int64_t first_sample, std::int64_t sample_stride, std::string_view what,
                       std::int64_t step) {
    for (std::size_t y = 0; y < rows; ++y) {
        const float* row = data + y * stride;
        for (std::size_t x = 0; x < width; ++x)
            if (!std::isfinite(row[x])) {
                std::ostringstream msg;
                msg << "non-finite " << what << " (" << row[x] << ") at sample "
                    << first_sample + std::int64_t(y) * sample_stride + std::int64_t(x) << " after step " << step
                    << "; the simulation became unstable";
                throw Error(msg.str());
            }
    }
}

}  // namespace

void NodeContext::check_finite(std::span<const float> data, std::string_view what, std::int64_t step) const {
    check_finite_rows(data.data(), data.size(), 1, data.size(), 0, 0, what, step);
}

void TiledFields::check_finite(ConstGridView grid, std::string_view what, std::int64_t step) const {
    // A ghosted grid or an owned tile: its owned part, named in the whole grid.
    const bool tile = grid.width == own_.width && grid.height == own_.height;
    const int x = tile ? 0 : ox_, y = tile ? 0 : oy_;
    check_finite_rows(grid.row(y) + x, std::size_t(own_.width), std::size_t(own_.height), std::size_t(grid.width),
                      std::int64_t(own_.y0) * tiles_.grid_width() + own_.x0, tiles_.grid_width(), what, step);
}

std::vector<std::string> split_names(std::string_view text) {
    std::vector<std::string> names;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string_view item = text.substr(start, comma - start);
        const auto a = item.find_first_not_of(" \t"), b = item.find_last_not_of(" \t");
        if (a != std::string_view::npos) names.emplace_back(item.substr(a, b - a + 1));
        start = comma + 1;
    }
    return names;
}

}  // namespace orogen

// ------------------------------------------------------------------ processes (orogen/process.hpp)

namespace orogen {

namespace {
const std::vector<ProcessCall>& no_processes() {
    static const std::vector<ProcessCall> none;
    return none;
}
}  // namespace

const std::vector<ProcessCall>& NodeContext::processes() const { return no_processes(); }
const std::vector<ProcessCall>& CheckContext::processes() const { return no_processes(); }

std::string_view to_string(FieldAccess access) {
    switch (access) {
        case FieldAccess::reads: return "reads";
        case FieldAccess::reads_if_present: return "reads if present";
        case FieldAccess::writes: return "writes";
        case FieldAccess::adds: return "adds to";
        case FieldAccess::updates: return "updates";
    }
    return "uses";
}

double FlowGraph::distance(std::int64_t i) const {
    const std::int64_t d = std::int64_t(receivers[std::size_t(i)]) - i;
    if (d == 0) return 0.0;
    return (d == 1 || d == -1 || d == width || d == -width) ? cell : cell * 1.4142135623730951;
}

int FlowGraph::direction(std::int64_t i) const {
    const std::int64_t d = std::int64_t(receivers[std::size_t(i)]) - i;
    static constexpr std::int8_t kCode[3][3] = {{5, 6, 7}, {4, -1, 0}, {3, 2, 1}};  // [dy + 1][dx + 1]
    const std::int64_t dy = std::int64_t(d > 1) - std::int64_t(d < -1);
    const std::int64_t dx = d - dy * width;
    if (dx < -1 || dx > 1) return -1;
    return kCode[dy + 1][dx + 1];
}

const ParamValue& ProcessCheckContext::param(std::string_view p) const {
    const auto& params = call().params;
    auto it = params.find(p);
    if (it == params.end())
        throw Error("internal error: process '" + call().label + "' has no parameter '" + std::string(p) + "'");
    return it->second;
}

}  // namespace orogen
