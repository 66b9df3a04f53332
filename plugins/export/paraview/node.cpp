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

    std::vector<vtk::NamedGrid> layers;
    for (const auto& name : hm.layer_names()) layers.push_back({name, hm.layer(name)});
    vtk::write_heightmap(hm.view(), layers, folder / s.terrain, o);

    const ConstGridView heights = hm.view();
    const std::span<const float> h(heights.data, heights.size());
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    s.height_min = *lo;
    s.height_max = *hi;
    s.size_x = (hm.width() - 1) * hm.cell();
    s.size_y = (hm.height() - 1) * hm.cell();
    const ConstGridView coloured = s.layer == "height" ? heights : hm.layer(s.layer);
    s.colours = paraview::colours_for(s.layer, {coloured.data, coloured.size()});
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
    if (plates_in) {
        const PlateHistory& plates = *plates_in->plates();
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
            "larger side), coloured by LAYER with a scalar bar and a colour map that suits it (categorical for plate "
            "and boundary, diverging for eroded, hypsometric for height), viewed from an oblique camera; plates and "
            "particles are set to play over their time steps.",
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
