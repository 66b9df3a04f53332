// import:exr — one channel of an OpenEXR file (what export:exr writes, or Houdini's, Nuke's, Gaea's) as a
// heightmap, other channels as layers.
#include <orogen/exr/exr.hpp>

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

#include <sstream>

namespace {

using namespace orogen;

exr::ReadOptions options_from(const std::string& channel, const std::string& layers, double cell) {
    exr::ReadOptions o;
    o.channel = channel;
    o.layers = split_names(layers);
    if (o.layers.size() == 1 && o.layers[0] == "all") {
        o.layers.clear();
        o.all_layers = true;
    }
    o.cell = cell;
    return o;
}

NodeOutputs run(NodeContext& ctx) {
    const auto o = options_from(ctx.text("channel"), ctx.text("layers"), ctx.real("cell"));
    auto hm = exr::read(ctx.input_path("path"), o);
    std::ostringstream msg;
    msg << hm->width() << "×" << hm->height() << " vertices, cell " << hm->cell() << " m, channel '" << o.channel
        << "'";
    const auto layers = hm->layer_names();
    if (!layers.empty()) {
        msg << ", layers";
        for (std::size_t i = 0; i < layers.size(); ++i) msg << (i ? ", " : " ") << layers[i];
    }
    ctx.info(msg.str());
    ctx.progress(1.0);
    return hm;
}

void check(CheckContext& ctx) {
    const auto o = options_from(ctx.text("channel"), ctx.text("layers"), ctx.real("cell"));
    exr::FileInfo info;
    try {
        info = exr::probe(ctx.resolved_path("path"), o);
    } catch (const exr::ChannelError& e) {
        ctx.error(e.param, e.what());
        return;
    } catch (const BadInput& e) {
        ctx.error("path", e.what());
        return;
    }
    if (o.cell <= 0.0 && !info.cell) {
        ctx.error("cell", "the file has no cellSize attribute to take a cell size from; give cell=METRES");
        return;
    }
    if (!info.height_units.empty() && info.height_units != "m")
        ctx.error("path",
                  "the file says its heights are in '" + info.height_units +
                      "' (its heightUnits attribute); import:exr reads metres: convert the file first");
    ValueInfo& out = ctx.output();
    out.width = info.width;
    out.height = info.height;
    out.cell = o.cell > 0.0 ? o.cell : *info.cell;
    out.layers.clear();
    if (o.all_layers) {
        for (const auto& c : info.channels)
            if (c.name != o.channel && c.type != exr::SampleType::uint32 && c.x_sampling == 1 && c.y_sampling == 1)
                out.layers.insert(c.name);
    } else {
        out.layers.insert(o.layers.begin(), o.layers.end());
    }
    out.layers_known = true;
}

}  // namespace

OROGEN_PLUGIN("import-exr", "0.1.0", registry) {
    registry.add({
        .kind = "import",
        .name = "exr",
        .summary = "read an OpenEXR channel (export:exr's, Houdini's, Nuke's, Gaea's) as a heightmap, others as layers",
        .description =
            "Channel `channel` of a single-part scanline or tiled OpenEXR file, in metres, at the file's own size "
            "(its data window; rows north to south), 32-bit float or 16-bit half (converted exactly); the channels "
            "named in `layers` (or all the others) become layers of the same names. The cell size comes from the "
            "cellSize attribute export:exr writes unless cell is given. Lossless compressions only (none, rle, zips, "
            "zip, piz). At check time the header and every chunk of the image are checked against the file and "
            "the memory budget, so a truncated, damaged or hostile file fails with one message before anything "
            "large is allocated.",
        .inputs = {},
        .output = ValueType::heightmap,
        .params =
            {
                Param::path("path", PathRole::input).help("the .exr file, relative to the spec's folder"),
                Param::string("channel", "Y").help("the channel read as heights"),
                Param::string("layers", "")
                    .help("channels read as layers, comma-separated (\"water, eroded\"), or "
                          "all"),
                Param::real("cell", 0.0).min(0.0).max(1e6).unit("m").help("vertex spacing; 0 = the file's cellSize"),
            },
        .check = check,
        .run = run,
    });
}
