// paraview_state.cpp — see paraview_state.hpp.
#include "paraview_state.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

namespace orogen::paraview {

namespace {

using RGB = std::array<double, 3>;

RGB rgb(int r, int g, int b) { return {r / 255.0, g / 255.0, b / 255.0}; }

/// Qualitative colours (ColorBrewer Set1/Set3 family), as orogen-view's.
const RGB categorical_palette[] = {rgb(228, 26, 28),   rgb(55, 126, 184),  rgb(77, 175, 74),   rgb(152, 78, 163),
                                   rgb(255, 127, 0),   rgb(255, 255, 51),  rgb(166, 86, 40),   rgb(247, 129, 191),
                                   rgb(141, 211, 199), rgb(190, 186, 218), rgb(128, 177, 211), rgb(179, 222, 105),
                                   rgb(252, 205, 229), rgb(188, 128, 189), rgb(204, 235, 197), rgb(255, 237, 111)};

/// Shortest text that reads back as the same double (deterministic, no locale).
std::string number(double v) {
    if (v == 0.0) return "0.0";  // also turns −0 into 0
    char buffer[64];
    const auto r = std::to_chars(buffer, buffer + sizeof buffer, v);
    std::string s(buffer, r.ptr);
    if (s.find_first_of(".en") == std::string::npos) s += ".0";  // a Python float, not an int
    return s;
}

/// A colour channel 0..1 to 4 decimals: 8-bit colours need no more, and the script stays readable.
std::string channel(double v) { return number(std::round(v * 1e4) / 1e4); }

std::string rgb_list(const RGB& c) {
    std::string s = "[";
    for (int i = 0; i < 3; ++i) (s += i ? ", " : "") += channel(c[std::size_t(i)]);
    return s + "]";
}

/// More than this many distinct ids is not a categorical layer worth a legend.
constexpr std::size_t max_categories = 256;

Colours categories(const std::string& title, const std::vector<int>& ids, const std::map<int, std::string>& names = {},
                   const std::map<int, RGB>& fixed = {}) {
    Colours c;
    c.kind = Colours::categorical;
    c.title = title;
    std::size_t next = 0;
    for (int id : ids) {
        const auto f = fixed.find(id);
        const auto n = names.find(id);
        c.categories.push_back(
            {id, n != names.end() ? n->second : std::to_string(id),
             f != fixed.end() ? f->second : categorical_palette[next++ % std::size(categorical_palette)]});
    }
    if (!ids.empty()) c.low = ids.front(), c.high = ids.back();
    return c;
}

}  // namespace

std::string python_string(const std::string& text) {
    std::string out = "\"";
    for (unsigned char ch : text) {
        if (ch == '"' || ch == '\\') {
            out += '\\';
            out += char(ch);
        } else if (ch < 0x20 || ch == 0x7f) {
            char buffer[8];
            std::snprintf(buffer, sizeof buffer, "\\x%02x", ch);
            out += buffer;
        } else {
            out += char(ch);  // UTF-8 passes through: a Python 3 source is UTF-8
        }
    }
    return out + "\"";
}

Colours plate_colours(std::vector<int> ids) {
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    std::map<int, std::string> names;
    for (int id : ids) names[id] = id < 0 ? "no plate" : "plate " + std::to_string(id);
    return categories("plate", ids, names, {{-1, rgb(200, 200, 200)}});
}

double percentile(std::span<const float> values, double q) {
    std::vector<float> finite;
    finite.reserve(values.size());
    for (float v : values)
        if (std::isfinite(v)) finite.push_back(v);
    if (finite.empty()) return 0.0;
    const std::size_t k =
        std::min(finite.size() - 1, std::size_t(std::llround(std::clamp(q, 0.0, 1.0) * double(finite.size() - 1))));
    std::nth_element(finite.begin(), finite.begin() + std::ptrdiff_t(k), finite.end());
    return finite[k];
}

namespace {

/// The unit of a layer orogen's nodes write, for the scalar bar ("" when unknown).
std::string unit_of(const std::string& name) {
    static const std::map<std::string, std::string> units = {
        {"height", "m"},    {"eroded", "m"},      {"deposited", "m"},   {"uplift", "m"},
        {"uplifted", "m"},  {"water", "m"},       {"sediment", "m"},    {"flow", "m/s"},
        {"drainage", "m²"}, {"hardness", "0..1"}, {"ice_flux", "m³/yr"}};
    const auto u = units.find(name);
    return u == units.end() ? "" : u->second;
}

std::string titled(const std::string& name, const std::string& unit) {
    return unit.empty() ? name : name + " (" + unit + ")";
}

}  // namespace

Colours colours_for(const std::string& name, std::span<const float> values) {
    if (name == "plate" || name == "boundary") {
        std::set<int> ids;
        for (float v : values) {
            if (!std::isfinite(v)) continue;
            ids.insert(int(std::lround(v)));
            if (ids.size() > max_categories) break;
        }
        if (!ids.empty() && ids.size() <= max_categories) {
            Colours c = name == "plate"
                ? plate_colours({ids.begin(), ids.end()})
                : categories(
                      "boundary", {ids.begin(), ids.end()},
                      {{0, "none"}, {1, "convergent"}, {2, "divergent"}, {3, "transform"}},
                      {{0, rgb(200, 200, 200)}, {1, rgb(215, 48, 39)}, {2, rgb(69, 117, 180)}, {3, rgb(26, 152, 80)}});
            if (name == "plate") c.title = "plate (id)";
            c.array = name;
            c.data_low = c.low;
            c.data_high = c.high;
            return c;
        }
    }
    Colours c;
    c.array = name;
    const std::string unit = unit_of(name);
    c.title = titled(name, unit);
    // The range the colours span: the 2nd to 98th percentile, so a few extreme
    // cells (a deep gully, the open boundary's rim, one fast cell) do not wash it out.
    double p2 = percentile(values, 0.02), p98 = percentile(values, 0.98);
    const std::vector<RGB> brbg = {rgb(140, 81, 10), rgb(216, 179, 101), rgb(245, 245, 245), rgb(90, 180, 172),
                                   rgb(1, 102, 94)};
    if (name == "eroded" && (p98 < 0 || p2 > 0)) {
        // Every cell lost (or gained) much the same: 0 is no landmark in the
        // picture. What the user asks first is where the rivers cut deepest
        // relative to the map: the layer minus its median, diverging about it.
        c.shift = percentile(values, 0.5);
        c.array = name + "_vs_median";
        const long long median = std::llround(c.shift);
        c.title = name + " − median (m); median " + (median < 0 ? "−" : "") + std::to_string(std::llabs(median)) + " m";
        p2 -= c.shift;
        p98 -= c.shift;
    }
    c.data_low = p2;
    c.data_high = p98;
    // eroded (about its median, or about 0 when it reaches 0: most cells
    // untouched, as after a short rain) or any other layer with both signs:
    // 0 (no change, or the typical cell) is the landmark.
    if (name == "eroded" || (name != "height" && p2 < 0 && p98 > 0)) {
        // Brown below, white at 0, blue-green above (BrBG), symmetric so equal
        // colours mean equal amounts.
        c.kind = Colours::diverging;
        if (name == "eroded" && c.shift == 0.0) c.title = "eroded (m; − cut, + deposited)";
        const double top = std::max({-p2, p98, 1e-9});  // a constant layer: still a range
        c.low = -top;
        c.high = top;
        c.ramp = brbg;
        return c;
    }
    c.kind = Colours::sequential;
    c.low = p2;
    c.high = p98 > p2 ? p98 : p2 + std::max(1e-9, std::fabs(p2) * 1e-6);  // a constant layer: still a range
    if (name == "height") {  // hypsometric: lowlands green to rock brown to snow
        c.ramp = {rgb(38, 115, 77), rgb(140, 180, 100), rgb(210, 190, 130), rgb(140, 100, 70), rgb(245, 245, 245)};
    } else if (name == "drainage" || (p2 > 0 && p98 > 1000 * p2)) {
        // Upstream area spans decades: a log scale shows the branching network.
        c.log = true;
        c.ramp = {rgb(247, 251, 255), rgb(107, 174, 214), rgb(8, 48, 107)};
    } else if (name == "water" || name == "flow") {
        c.ramp = {rgb(247, 251, 255), rgb(107, 174, 214), rgb(8, 48, 107)};
    } else if (name == "sediment" || name == "deposited") {
        c.ramp = {rgb(255, 247, 188), rgb(254, 153, 41), rgb(102, 37, 6)};
    } else {  // viridis, sampled
        c.ramp = {rgb(68, 1, 84), rgb(59, 82, 139), rgb(33, 145, 140), rgb(94, 201, 98), rgb(253, 231, 37)};
    }
    return c;
}

Colours attribute_colours(const std::string& name, std::span<const float> values, int components) {
    std::vector<float> magnitudes;
    for (std::size_t i = 0; i + std::size_t(components) <= values.size(); i += std::size_t(components)) {
        double sum = 0;
        for (int c = 0; c < components; ++c) sum += double(values[i + std::size_t(c)]) * values[i + std::size_t(c)];
        magnitudes.push_back(float(std::sqrt(sum)));
    }
    Colours c;
    c.kind = Colours::sequential;
    c.array = name;
    c.title = name == "velocity" ? "speed (m/s)" : titled(name, unit_of(name));
    if (name == "velocity")  // water: deep blue where it pools, paler (foam) where it runs fast
        c.ramp = {rgb(8, 48, 107), rgb(33, 113, 181), rgb(107, 174, 214), rgb(222, 235, 247)};
    else c.ramp = {rgb(198, 219, 239), rgb(66, 146, 198), rgb(8, 48, 107)};  // light = low, dark = high
    if (magnitudes.empty()) return c;
    c.low = c.data_low = percentile(magnitudes, 0.02);
    c.data_high = percentile(magnitudes, 0.98);
    c.high = std::max(c.data_high, c.low + 1e-9);
    return c;
}

std::vector<XY> clip_polygon(const std::vector<XY>& polygon, double x0, double y0, double x1, double y1) {
    std::vector<XY> out = polygon;
    // One half-plane at a time: inside(p) for each edge of the rectangle.
    for (int edge = 0; edge < 4 && !out.empty(); ++edge) {
        const int axis = edge % 2;
        const double bound = edge == 0 ? x0 : edge == 1 ? y0 : edge == 2 ? x1 : y1;
        const bool keep_above = edge < 2;
        const auto inside = [&](const XY& p) { return keep_above ? p[axis] >= bound : p[axis] <= bound; };
        std::vector<XY> in = std::move(out);
        out.clear();
        for (std::size_t i = 0; i < in.size(); ++i) {
            const XY& p = in[i];
            const XY& q = in[(i + 1) % in.size()];
            if (inside(p)) out.push_back(p);
            if (inside(p) != inside(q)) {
                const double t = (bound - p[axis]) / (q[axis] - p[axis]);
                XY cut = {p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])};
                cut[std::size_t(axis)] = bound;
                out.push_back(cut);
            }
        }
    }
    if (out.size() < 3) out.clear();
    return out;
}

bool clip_segment(XY& a, XY& b, double x0, double y0, double x1, double y1) {
    double t0 = 0.0, t1 = 1.0;
    const double d[2] = {b[0] - a[0], b[1] - a[1]};
    const double lo[2] = {x0, y0}, hi[2] = {x1, y1};
    for (int axis = 0; axis < 2; ++axis) {
        if (d[axis] == 0.0) {
            if (a[std::size_t(axis)] < lo[axis] || a[std::size_t(axis)] > hi[axis]) return false;
            continue;
        }
        double ta = (lo[axis] - a[std::size_t(axis)]) / d[axis], tb = (hi[axis] - a[std::size_t(axis)]) / d[axis];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    const XY start = a;
    a = {start[0] + t0 * d[0], start[1] + t0 * d[1]};
    b = {start[0] + t1 * d[0], start[1] + t1 * d[1]};
    return true;
}

std::vector<XY> densify(const std::vector<XY>& points, double step, bool closed) {
    std::vector<XY> out;
    const std::size_t n = points.size();
    const std::size_t edges = closed ? n : (n ? n - 1 : 0);
    for (std::size_t i = 0; i < edges; ++i) {
        const XY& p = points[i];
        const XY& q = points[(i + 1) % n];
        const double length = std::hypot(q[0] - p[0], q[1] - p[1]);
        const int pieces = std::max(1, int(std::ceil(length / step - 1e-9)));
        for (int k = 0; k < pieces; ++k) {
            const double t = double(k) / pieces;
            out.push_back({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])});
        }
    }
    if (!closed && n) out.push_back(points.back());
    if (closed && n < 2) return points;
    return out;
}

double auto_exaggeration(double relief, double side) {
    if (!(relief > 0) || !(side > 0)) return 1.0;
    const double e = std::clamp(0.2 * side / relief, 1.0, 20.0);
    const double scale = std::pow(10.0, std::floor(std::log10(e)) - 1);  // two significant digits
    return std::round(e / scale) * scale;
}

namespace {

std::string colours_python(const Colours& c) {
    std::ostringstream s;
    const char* kind = c.kind == Colours::categorical ? "categorical"
        : c.kind == Colours::diverging                ? "diverging"
                                                      : "sequential";
    s << "{\n        \"kind\": \"" << kind << "\",\n        \"title\": " << python_string(c.title)
      << ",\n        \"array\": " << python_string(c.array) << ",\n        \"range\": [" << number(c.low) << ", "
      << number(c.high) << "],\n        \"data_range\": [" << number(c.data_low) << ", " << number(c.data_high)
      << "],  # 2nd and 98th percentiles\n        \"log\": " << (c.log ? "True" : "False") << ",\n        \"ramp\": [";
    for (std::size_t i = 0; i < c.ramp.size(); ++i) s << (i ? ", " : "") << rgb_list(c.ramp[i]);
    s << "],\n        \"categories\": [";
    for (std::size_t i = 0; i < c.categories.size(); ++i)
        s << (i ? ",\n                       " : "") << "[" << c.categories[i].value << ", "
          << python_string(c.categories[i].name) << ", " << rgb_list(c.categories[i].rgb) << "]";
    s << "],\n    }";
    return s.str();
}

std::string optional_file(const std::string& f) { return f.empty() ? "None" : python_string(f); }

// The script's code: everything it needs comes from RUN above it.
const char* const script_body = R"py(
import argparse
import math
import os
import sys

import paraview.simple
from paraview.simple import *  # noqa: F401,F403 (ParaView's own scripting API)


def _folder():
    """The folder that holds this script and the run's files."""
    if os.environ.get("OROGEN_RUN_FOLDER"):
        return os.environ["OROGEN_RUN_FOLDER"]
    try:
        return os.path.dirname(os.path.abspath(__file__))
    except NameError:  # a ParaView that runs state scripts without __file__: the working folder
        return os.getcwd()


HERE = _folder()


def _file(name):
    path = os.path.join(HERE, name)
    if not os.path.isfile(path):
        raise SystemExit("orogen state: cannot find %s in %s; keep the run's files together (move the whole "
                         "folder), or set OROGEN_RUN_FOLDER to the folder that holds them" % (name, HERE))
    return path


def _options():
    parser = argparse.ArgumentParser(
        prog="pvbatch " + RUN["script"],
        description="Opens an orogen run in ParaView; with pvbatch, saves pictures of it.")
    parser.add_argument("--screenshot", metavar="PNG", help="save a picture of the view")
    parser.add_argument("--animation", metavar="PNG", help="save one picture per time step (NAME.0000.png ...)")
    parser.add_argument("--size", default="1600x900", help="picture size, WIDTHxHEIGHT (default 1600x900)")
    parser.add_argument("--time", type=float, help="show this time step (default: the last)")
    parser.add_argument("--save-state", metavar="PVSM", help="save the state as a .pvsm (absolute paths: on Load "
                        "State choose 'Search files under specified directory' after moving the folder)")
    # Known options only: inside the ParaView GUI (Load State, --script) sys.argv
    # holds the application's own arguments, which are not ours to refuse.
    args, _ = parser.parse_known_args(getattr(sys, "argv", [])[1:])
    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        parser.error("--size must be WIDTHxHEIGHT, e.g. 1600x900, not %r" % args.size)
    args.size = [width, height]
    return args


def _apply_colours(lut, colours):
    """The run's colour map for one array (categorical, diverging or sequential)."""
    lut.AutomaticRescaleRangeMode = "Never"
    if colours["kind"] == "categorical":
        lut.InterpretValuesAsCategories = 1
        lut.AnnotationsInitialized = 1
        annotations, indexed = [], []
        for value, name, rgb in colours["categories"]:
            annotations += [str(value), name]
            indexed += rgb
        lut.Annotations = annotations
        lut.IndexedColors = indexed
        return
    lut.InterpretValuesAsCategories = 0
    low, high = colours["range"]
    ramp = colours["ramp"]
    log = colours.get("log", False) and low > 0
    points = []
    for i, rgb in enumerate(ramp):
        t = i / (len(ramp) - 1)
        points += [low * (high / low) ** t if log else low + (high - low) * t] + rgb
    lut.RGBPoints = points
    lut.ColorSpace = "Diverging" if colours["kind"] == "diverging" else "Lab"
    lut.UseLogScale = 1 if log else 0
    lut.NanColor = [0.5, 0.5, 0.5]
    lut.RescaleTransferFunction(low, high)


def _colour_by(display, view, association, array, colours, bar=True, separate=False):
    # The table first, then the array: ColorBy() would rescale to the data,
    # which is empty at some time steps (no collisions yet) and is not wanted.
    # `separate`: a table of this display's own, so plates or particles
    # sharing an array name with a terrain layer keep their own colours.
    display.UseSeparateColorMap = 1 if separate else 0
    lut = GetColorTransferFunction(array, display, separate=separate)
    _apply_colours(lut, colours)
    display.LookupTable = lut
    display.ColorArrayName = [association, array]
    display.SetScalarBarVisibility(view, bar)
    if bar:
        scalar_bar = GetScalarBar(lut, view)
        scalar_bar.Title = colours["title"]
        scalar_bar.ComponentTitle = ""
        scalar_bar.WindowLocation = "Lower Right Corner"
        scalar_bar.ScalarBarLength = 0.4
        scalar_bar.AddRangeLabels = 1
        scalar_bar.RangeLabelFormat = "%-#.4g"
    return lut


# Run by ParaView (a Programmable Filter) at every time step: the first
# input's points (lines or polygons in the terrain's plane, Z = 0) raised to
# the height of the terrain (the second input, an image with "height")
# under them, interpolated bilinearly, times SCALE, plus LIFT. Plain Python:
# no numpy needed (and ParaView's own min and max are numpy's here).
_DRAPE_SCRIPT = """
import builtins
from vtkmodules.vtkCommonCore import vtkPoints
lines = self.GetInputDataObject(0, 0)
image = self.GetInputDataObject(0, 1)
out = self.GetOutputDataObject(0)
out.ShallowCopy(lines)
heights = image.GetPointData().GetArray("height")
nx, ny, _ = image.GetDimensions()
ox, oy, _ = image.GetOrigin()
sx, sy, _ = image.GetSpacing()
clamp = lambda v, top: builtins.min(builtins.max(v, 0.0), top)
raised = vtkPoints()
raised.SetDataTypeToFloat()
raised.SetNumberOfPoints(lines.GetNumberOfPoints())
for k in range(lines.GetNumberOfPoints()):
    x, y, _ = lines.GetPoint(k)
    fi, fj = clamp((x - ox) / sx, nx - 1.0), clamp((y - oy) / sy, ny - 1.0)
    i, j = builtins.min(int(fi), nx - 2), builtins.min(int(fj), ny - 2)
    u, v = fi - i, fj - j
    h = lambda a, b: heights.GetValue(a + b * nx)
    z = (1 - v) * ((1 - u) * h(i, j) + u * h(i + 1, j)) + v * ((1 - u) * h(i, j + 1) + u * h(i + 1, j + 1))
    raised.SetPoint(k, x, y, z * SCALE + LIFT)
out.SetPoints(raised)
"""


def _drape(name, source, terrain, exaggeration, lift):
    """`source` (lines or polygons in the terrain's plane) laid on the warped
    terrain, `lift` above it so it is not hidden; at every time step."""
    draped = ProgrammableFilter(registrationName=name + " (draped)", Input=[source, terrain])
    draped.Script = "SCALE = %r\nLIFT = %r\n%s" % (float(exaggeration), float(lift), _DRAPE_SCRIPT)
    draped.CopyArrays = 0
    return draped


def open_run():
    """Builds the pipeline, colours and camera; returns the render view."""
    # Keep the camera set below (ParaView's own state scripts do the same):
    # the first Render() would otherwise reset it to a default view.
    paraview.simple._DisableFirstRenderCameraReset()
    view = GetActiveViewOrCreate("RenderView")
    exaggeration = RUN["exaggeration"]
    low, high = RUN["heights"]

    # The terrain: image data in the XY plane (Z up), raised by its height.
    terrain = XMLImageDataReader(registrationName=RUN["terrain"], FileName=[_file(RUN["terrain"])])
    warped = WarpByScalar(registrationName="warped x%g" % exaggeration, Input=terrain)
    warped.Scalars = ["POINTS", "height"]
    warped.ScaleFactor = exaggeration
    warped.Normal = [0.0, 0.0, 1.0]
    warped.UseNormal = 1
    surface = ExtractSurface(registrationName="surface", Input=warped)
    shaded = GenerateSurfaceNormals(registrationName="terrain", Input=surface)
    shaded.Splitting = 0  # smooth shading across ridges
    display = Show(shaded, view)
    display.Representation = "Surface"
    _colour_by(display, view, "POINTS", RUN["colours"]["array"], RUN["colours"])

    # Plates: their outlines (one colour per plate, so the terrain's colours
    # stay readable) and the collisions since the previous snapshot, laid on
    # the terrain (its final heights) a little above it.
    lift = 0.002 * max(RUN["size"])
    if RUN["plates"]:
        plates = PVDReader(registrationName=RUN["plates"], FileName=_file(RUN["plates"]))
        shown = Show(_drape("plates", plates, terrain, exaggeration, lift), view)
        shown.Representation = "Wireframe"
        shown.LineWidth = 3.0
        shown.Ambient = 1.0
        shown.Diffuse = 0.0
        _colour_by(shown, view, "CELLS", "plate", RUN["plate_colours"], bar=False, separate=True)
    if RUN["collisions"]:
        collisions = PVDReader(registrationName=RUN["collisions"], FileName=_file(RUN["collisions"]))
        shown = Show(_drape("collisions", collisions, terrain, exaggeration, 1.5 * lift), view)
        shown.LineWidth = 5.0
        shown.Ambient = 1.0
        shown.Diffuse = 0.0
        _colour_by(shown, view, "CELLS", "kind", RUN["collision_colours"], bar=False, separate=True)

    # Particles: positions in metres, stretched with the terrain.
    if RUN["particles"]:
        particles = PVDReader(registrationName=RUN["particles"], FileName=_file(RUN["particles"]))
        stretched = Transform(registrationName="particles (stretched)", Input=particles)
        stretched.Transform.Scale = [1.0, 1.0, exaggeration]
        # Water: flat, slightly translucent splats (not shaded spheres, which
        # read as dark beads), deep blue where it pools, paler as it runs fast.
        shown = Show(stretched, view)
        shown.SetRepresentationType("Point Gaussian")
        shown.GaussianRadius = 0.002 * max(RUN["size"])  # the ground shows between them
        shown.ShaderPreset = "Plain circle"
        shown.Opacity = 0.85
        shown.Ambient = 1.0
        shown.Diffuse = 0.0
        if RUN["particle_colour"]:  # one range over every frame, so colours compare across time
            lut = _colour_by(shown, view, "POINTS", RUN["particle_colour"], RUN["particle_colours"],
                             bar=RUN["particle_colour"] == "velocity", separate=True)
            lut.VectorMode = "Magnitude"
            if RUN["particle_colour"] == "velocity":
                GetScalarBar(lut, view).WindowLocation = "Lower Left Corner"
                view.OrientationAxesVisibility = 0  # it would sit on the bar
        else:
            shown.ColorArrayName = ["POINTS", ""]
            shown.AmbientColor = shown.DiffuseColor = [0.2, 0.45, 0.9]
        # The water that carries the most sediment (its top tenth over the whole
        # run) in a colour of its own, orange, drawn over the rest.
        if RUN["sediment_threshold"] is not None:
            laden = Threshold(registrationName="sediment-laden particles", Input=stretched)
            laden.Scalars = ["POINTS", "sediment"]
            laden.LowerThreshold = RUN["sediment_threshold"]
            laden.UpperThreshold = 1e30
            laden.ThresholdMethod = "Between"
            muddy = Show(laden, view)
            muddy.SetRepresentationType("Point Gaussian")
            muddy.GaussianRadius = 0.003 * max(RUN["size"])
            muddy.ShaderPreset = "Plain circle"
            muddy.Ambient = 1.0
            muddy.Diffuse = 0.0
            muddy.ColorArrayName = ["POINTS", ""]
            muddy.AmbientColor = muddy.DiffuseColor = [0.902, 0.333, 0.051]  # orange: no terrain colour

    # Time: every series' steps, snapped to (Play in the toolbar runs them).
    # It opens at the last step (the plates where they built the range, the
    # water where it ran to), beside the terrain it left.
    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.PlayMode = "Snap To TimeSteps"
    times = list(GetTimeKeeper().TimestepValues)
    if times:
        scene.AnimationTime = times[-1]
        time_text = AnnotateTime(registrationName="time")
        time_text.Format = "t = {time:g}"
        shown = Show(time_text, view)
        shown.WindowLocation = "Upper Right Corner"
        shown.FontSize = 14

    caption = Text(registrationName="caption")
    caption.Text = RUN["caption"]
    shown = Show(caption, view)
    shown.WindowLocation = "Upper Left Corner"
    shown.Justification = "Left"
    shown.FontSize = 14

    # An oblique camera: from the azimuth (clockwise from north) and elevation
    # above the horizon, far enough to see the whole terrain.
    size_x, size_y = RUN["size"]
    centre = [size_x / 2.0, -size_y / 2.0, (low + high) / 2.0 * exaggeration]
    azimuth, elevation = (math.radians(a) for a in RUN["camera"])
    direction = [math.sin(azimuth) * math.cos(elevation), math.cos(azimuth) * math.cos(elevation), math.sin(elevation)]
    radius = 0.5 * math.sqrt(size_x ** 2 + size_y ** 2 + ((high - low) * exaggeration) ** 2)
    distance = 0.8 * radius / math.tan(math.radians(30.0) / 2.0)  # the terrain's diagonal just fits
    view.CameraViewAngle = 30.0
    view.CameraFocalPoint = centre
    view.CameraPosition = [c + distance * d for c, d in zip(centre, direction)]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.CenterOfRotation = centre
    SetActiveSource(shaded)
    Render(view)
    return view


def main():
    args = _options()
    view = open_run()
    if args.screenshot or args.animation:
        view.ViewSize = args.size  # text and bars at their own size, not magnified
    if args.time is not None:
        GetAnimationScene().AnimationTime = args.time
    if args.screenshot:
        SaveScreenshot(args.screenshot, view, ImageResolution=args.size)
    if args.animation:
        SaveAnimation(args.animation, view, ImageResolution=args.size)
    if args.save_state:
        SaveState(args.save_state)


main()
)py";

}  // namespace

static std::string caption(const StateScript& s) {
    std::ostringstream o;
    if (s.colours.shift != 0.0)
        o << s.layer << " relative to the map's median: brown where the rivers cut deeper than the typical cell, "
          << "blue-green where less";
    else if (s.colours.kind == Colours::diverging) o << s.layer << ": brown lowered, blue-green raised";
    else o << "coloured by " << s.layer;
    char factor[32];
    std::snprintf(factor, sizeof factor, "%g", s.exaggeration);
    o << "; heights x" << factor;
    if (!s.plates.empty())
        o << "\nplates' outlines on the terrain (a colour each); collisions: red convergent, "
          << "blue divergent, green transform";
    if (!s.particles.empty()) {
        if (s.particle_colour == "velocity") o << "\nwater particles: deep blue where slow, pale where fast";
        else o << "\nparticles coloured by " << (s.particle_colour.empty() ? "nothing" : s.particle_colours.title);
        if (s.sediment_threshold > 0) o << "; orange: the most laden with sediment (top 10 %)";
    }
    return o.str();
}

std::string state_script(const StateScript& s) {
    std::ostringstream o;
    o << "# " << s.script_name << ": a ParaView state written by orogen's export:paraview-state.\n"
      << "# It opens this run: the terrain warped by its height, coloured by '" << s.layer << "',\n"
      << "# plates and particles over time, an oblique camera. Its files are found beside it\n"
      << "# (relative paths): move the whole folder, not the script alone.\n"
      << "#\n"
      << "#   ParaView:  File > Load State... > " << s.script_name << "   (or: paraview --script=" << s.script_name
      << ")\n"
      << "#   Batch:     pvbatch " << s.script_name << " --screenshot view.png [--size 1600x900] [--time T]\n"
      << "#              pvbatch " << s.script_name << " --animation frames.png     (a picture per time step)\n"
      << "#              pvbatch " << s.script_name << " --save-state view.pvsm\n"
      << "#   (in orogen's clone, tools/pvbatch is pvbatch fetched on first use and run without a display.)\n"
      << "# Frame: X east, Y north, Z up, metres; origin at the north-west corner sample.\n"
      << "\n"
      << "RUN = {\n"
      << "    \"script\": " << python_string(s.script_name) << ",\n"
      << "    \"terrain\": " << python_string(s.terrain) << ",\n"
      << "    \"plates\": " << optional_file(s.plates) << ",\n"
      << "    \"collisions\": " << optional_file(s.collisions) << ",\n"
      << "    \"particles\": " << optional_file(s.particles) << ",\n"
      << "    \"layer\": " << python_string(s.layer) << ",\n"
      << "    \"caption\": " << python_string(caption(s)) << ",\n"
      << "    \"colours\": " << colours_python(s.colours) << ",\n"
      << "    \"plate_colours\": " << colours_python(s.plates_colours) << ",\n"
      << "    \"collision_colours\": " << colours_python(colours_for("boundary", std::vector<float>{1.0f, 2.0f, 3.0f}))
      << ",\n"
      << "    \"particle_colour\": " << optional_file(s.particle_colour) << ",\n"
      << "    \"particle_colours\": " << colours_python(s.particle_colours) << ",\n"
      << "    \"sediment_threshold\": "
      << (s.sediment_threshold > 0 ? number(s.sediment_threshold) : std::string("None"))
      << ",  # particles carrying at least this much sediment are drawn apart\n"
      << "    \"exaggeration\": " << number(s.exaggeration) << ",  # vertical, applied by Warp By Scalar\n"
      << "    \"heights\": [" << number(s.height_min) << ", " << number(s.height_max) << "],  # m\n"
      << "    \"size\": [" << number(s.size_x) << ", " << number(s.size_y) << "],  # m, east and north\n"
      << "    \"camera\": [" << number(s.azimuth) << ", " << number(s.elevation)
      << "],  # azimuth clockwise from north, elevation, degrees\n"
      << "}\n"
      << script_body;
    return o.str();
}

}  // namespace orogen::paraview
