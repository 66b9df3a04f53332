// export:paraview-state — a ParaView Python state script beside the run's
// data (paraview_state.hpp). The node takes the values themselves (the
// heightmap, optionally plates and particles) and writes its own Z-up VTK
// files beside the script with export:vtk's writers, so the script always
// names files that exist, in the frame it expects, with the layer it colours
// by (checked when the spec is checked, before anything runs).
#include "paraview_state.hpp"
#include <orogen/vtk/vtk_writer.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

namespace {

using namespace orogen;
namespace fs = std::filesystem;

/// Inputs 2 and 3 are a plate history and particle frames, in either order.
void check(CheckContext& ctx) {
    bool plates = false, particles = false;
    for (std::size_t i = 1; i <= 2; ++i) {
        const ValueInfo* in = ctx.input(i);
        if (!in) continue;
        bool& seen = in->type == ValueType::plates ? plates : particles;
        if (in->type != ValueType::plates && in->type != ValueType::particles)
            ctx.error("",
                      "export:paraview-state input " + std::to_string(i + 1) +
                          " must be a plate history (e.g. plates.plates) or particle frames (e.g. wet.particles), "
                          "not a " +
                          describe_type(in->type == ValueType::series ? in->element : in->type,
                                        in->type == ValueType::series));
        else if (seen)
            ctx.error("",
                      std::string("export:paraview-state takes one ") +
                          (in->type == ValueType::plates ? "plate history" : "particle series") +
                          "; inputs 2 and 3 are both one");
        seen = true;
    }
    const std::string& layer = ctx.text("layer");
    if (layer != "height")
        ctx.require_layer(0, "layer", layer, "use \"height\" (the default) or the name of an existing layer");
}

/// The plates as the state draws them: each polygon clipped to the terrain
/// (x 0..width, y 0..height, metres) and given a point every `step` metres
/// along its edges, the collisions clipped and cut into pieces as long, so
/// that the terrain's height sampled under every point lays them on it.
PlateHistory drapable(const PlateHistory& plates, double width, double height, double step) {
    PlateHistory out = plates;
    const double e = 1e-6 * std::max(width, height);  // just inside: every point samples the terrain
    const double x0 = e, y0 = e, x1 = width - e, y1 = height - e;
    for (PlateSnapshot& snap : out.snapshots) {
        std::vector<PlateState> kept;
        for (PlateState& p : snap.plates) {
            std::vector<paraview::XY> polygon;
            for (const Point2& v : p.polygon) polygon.push_back({v.x, v.y});
            polygon = paraview::densify(paraview::clip_polygon(polygon, x0, y0, x1, y1), step, true);
            if (polygon.size() < 3) continue;  // the plate lies off the map at this instant
            p.polygon.clear();
            for (const auto& v : polygon) p.polygon.push_back({v[0], v[1]});
            kept.push_back(std::move(p));
        }
        snap.plates = std::move(kept);
    }
    out.collisions.clear();
    for (const CollisionEvent& c : plates.collisions) {
        paraview::XY a = {c.a.x, c.a.y}, b = {c.b.x, c.b.y};
        if (!paraview::clip_segment(a, b, x0, y0, x1, y1)) continue;
        const auto line = paraview::densify({a, b}, step, false);
        for (std::size_t i = 0; i + 1 < line.size(); ++i) {
            CollisionEvent piece = c;
            piece.a = {line[i][0], line[i][1]};
            piece.b = {line[i + 1][0], line[i + 1][1]};
            out.collisions.push_back(piece);
        }
    }
    return out;
}

/// The attribute that colours particles: velocity (by magnitude) if there is one, else the first other one.
std::string particle_colour(const ParticleSeries& series) {
    if (series.frames.empty()) return {};
    const auto& attributes = series.frames.front().attributes;
    if (attributes.count("velocity")) return "velocity";
    for (const auto& [name, a] : attributes)
        if (name != "position") return name;
    return {};
}

NodeOutputs run(NodeContext& ctx) {
    const Heightmap& hm = *ctx.input(0).heightmap();
    const fs::path script = ctx.output_path(ctx.text("path"));
    const fs::path folder = script.parent_path();
    const std::string stem = script.stem().string();
    vtk::Options o;
    o.up = vtk::Up::z;
    o.compress = ctx.flag("compress");

    paraview::StateScript s;
    s.script_name = script.filename().string();
    s.terrain = stem + ".vti";
    s.layer = ctx.text("layer");

    if (s.layer != "height" && !hm.has_layer(s.layer)) {
        std::string there;
        for (const auto& name : hm.layer_names()) there += (there.empty() ? "" : ", ") + name;
        throw BadInput("export:paraview-state: the terrain has no layer '" + s.layer +
                       "' to colour by (it has: " + (there.empty() ? "no layers" : there) + "); no state written");
    }
    const ConstGridView heights = hm.view();
    const std::span<const float> h(heights.data, heights.size());
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    s.height_min = *lo;
    s.height_max = *hi;
    s.size_x = (hm.width() - 1) * hm.cell();
    s.size_y = (hm.height() - 1) * hm.cell();
    const ConstGridView coloured = s.layer == "height" ? heights : hm.layer(s.layer);
    s.colours = paraview::colours_for(s.layer, {coloured.data, coloured.size()});

    std::vector<vtk::NamedGrid> layers;
    for (const auto& name : hm.layer_names()) layers.push_back({name, hm.layer(name)});
    std::vector<float> shifted;  // the layer relative to its median, when that is what is shown
    if (s.colours.array != s.layer) {
        shifted.assign(coloured.data, coloured.data + coloured.size());
        for (float& v : shifted) v = float(double(v) - s.colours.shift);
        layers.push_back({s.colours.array, {shifted.data(), coloured.width, coloured.height, coloured.cell}});
    }
    vtk::write_heightmap(hm.view(), layers, folder / s.terrain, o);
    const double given = ctx.real("exaggeration");
    s.exaggeration =
        given > 0 ? given : paraview::auto_exaggeration(s.height_max - s.height_min, std::max(s.size_x, s.size_y));
    s.azimuth = ctx.real("azimuth");
    s.elevation = ctx.real("elevation");

    const Value* plates_in = nullptr;
    const Value* particles_in = nullptr;
    for (std::size_t i = 1; i <= 2; ++i)
        if (ctx.has_input(i)) (ctx.input(i).type() == ValueType::plates ? plates_in : particles_in) = &ctx.input(i);

    std::size_t files = 2;
    if (plates_in && plates_in->plates()->snapshots.empty()) {
        ctx.warn("export:paraview-state: the plate history has no snapshots; the state shows no plates");
        plates_in = nullptr;
    }
    if (particles_in && particles_in->particles()->frames.empty()) {
        ctx.warn("export:paraview-state: the particle series has no frames; the state shows no particles");
        particles_in = nullptr;
    }
    if (plates_in) {
        // Drawn on the terrain: a point every two cells (at most 512 along a side) samples its height.
        const PlateHistory plates = drapable(*plates_in->plates(), s.size_x, s.size_y,
                                             std::max(2 * hm.cell(), std::max(s.size_x, s.size_y) / 512));
        s.plates = stem + "-plates.pvd";
        s.collisions = stem + "-collisions.pvd";
        files += vtk::write_plates(plates, folder / s.plates, o, folder / s.collisions);
        std::vector<int> ids;
        for (const auto& snap : plates.snapshots)
            for (const auto& p : snap.plates) ids.push_back(p.id);
        s.plates_colours = paraview::plate_colours(ids);
    }
    if (particles_in) {
        const ParticleSeries& particles = *particles_in->particles();
        s.particles = stem + "-particles.pvd";
        files += vtk::write_particles(particles, folder / s.particles, o);
        s.particle_colour = particle_colour(particles);
        if (!s.particle_colour.empty()) {
            std::vector<float> values;
            int components = 1;
            for (const auto& f : particles.frames) {
                const auto a = f.attributes.find(s.particle_colour);
                if (a == f.attributes.end()) continue;
                components = a->second.components;
                values.insert(values.end(), a->second.data.begin(), a->second.data.end());
            }
            s.particle_colours = paraview::attribute_colours(s.particle_colour, values, components);
        }
        std::vector<float> sediment;
        for (const auto& f : particles.frames) {
            const auto a = f.attributes.find("sediment");
            if (a != f.attributes.end() && a->second.components == 1)
                sediment.insert(sediment.end(), a->second.data.begin(), a->second.data.end());
        }
        if (!sediment.empty()) s.sediment_threshold = std::max(0.0, paraview::percentile(sediment, 0.9));
    }

    AtomicFile file(script);
    const std::string text = paraview::state_script(s);
    file.write({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    file.commit();
    ctx.info("wrote " + ctx.text("path") + " and " + std::to_string(files - 1) +
             " data file(s) beside it; exaggeration " + std::to_string(s.exaggeration).substr(0, 6) + ", coloured by " +
             s.layer);
    return {};
}

}  // namespace

OROGEN_PLUGIN("export-paraview", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "paraview-state",
        .summary = "write a ParaView state script (.py) that opens the run: terrain warped and coloured, plates and "
                   "particles playing",
        .description =
            "Writes PATH (a Python state for ParaView: File > Load State, paraview --script, or pvbatch PATH "
            "--screenshot view.png) and beside it, with the same stem, its data in ParaView's frame (X east, Y north, "
            "Z up): STEM.vti (height and every layer), STEM-plates.pvd and STEM-collisions.pvd (given a plate "
            "history), STEM-particles.pvd (given particle frames; the two optional inputs in either order). The script "
            "opens them by relative path, so the "
            "folder can be moved. The terrain is raised by Warp By Scalar (exaggeration, auto: relief a fifth of the "
            "larger side), coloured by LAYER with a scalar bar and a colour map that suits it over its 2-98 % range "
            "(categorical for plate and boundary; diverging about 0 for eroded and layers of both signs, or about "
            "its median for an eroded of one sign: where rivers cut deeper than the typical cell; hypsometric for "
            "height, log for drainage), viewed from an oblique camera; plates and collisions are laid on the "
            "terrain; plates and particles play over their time steps, opening at the last. tools/pvbatch runs "
            "pvbatch without a display.",
        .inputs =
            {
                {"terrain", ValueType::heightmap, Need::required, "the heightmap to show (with its layers)"},
                {"plates or particles", ValueType::none, Need::optional,
                 "a plate history (plates.plates) or particle frames (an SPH eroder's .particles) to play"},
                {"particles or plates", ValueType::none, Need::optional, "the other of the two, in either order"},
            },
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".py"})
                    .help("the state script; its data files go beside it with the same stem"),
                Param::string("layer", std::string("height"))
                    .help("what colours the terrain: height or a layer of the input (eroded, plate, water, ...)"),
                Param::real("exaggeration", 0.0)
                    .min(0)
                    .max(1000)
                    .help("vertical exaggeration of Warp By Scalar; 0: automatic (relief a fifth of the larger side, "
                          "1..20)"),
                Param::real("azimuth", 200.0)
                    .min(0)
                    .max(360)
                    .unit("°")
                    .help("camera bearing from the terrain's centre, clockwise from north"),
                Param::real("elevation", 30.0).min(1).max(89).unit("°").help("camera height angle above the horizon"),
                Param::boolean("compress", false).help("zlib-compress the data files' arrays: smaller, slower"),
            },
        .check = check,
        .run = run,
    });
}
