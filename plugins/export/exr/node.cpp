// export:exr — registers the OpenEXR writer (exr.hpp) with the kernel.
#include <orogen/exr/exr.hpp>

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>
#include <orogen/plugin.hpp>

#include <memory>
#include <sstream>

namespace {

using namespace orogen;

bool is_all(const std::vector<std::string>& names) { return names.size() == 1 && names[0] == "all"; }

/// "" if layer `name` can be part of a file name (split=true), else why not.
std::string file_name_problem(const std::string& name) {
    if (name.empty() || name.front() == '.' || name.find_first_of("/\\") != std::string::npos ||
        name.find('\0') != std::string::npos)
        return "layer '" + name + "' cannot be part of a file name (split=true writes <stem>.<layer>.exr); " +
            "leave it out of layers or write one file (split=false)";
    return "";
}

/// "out/t.exr" and "water" → "out/t.water.exr".
std::string layer_file(const std::string& path, const std::string& layer) {
    const std::filesystem::path p(path);
    return (p.parent_path() / (p.stem().string() + "." + layer + p.extension().string())).string();
}

NodeOutputs run(NodeContext& ctx) {
    const auto& hm = ctx.input(0).heightmap();
    std::vector<std::string> layers = split_names(ctx.text("layers"));
    if (is_all(layers)) layers = hm->layer_names();
    for (const auto& name : layers)
        if (!hm->has_layer(name)) hm->layer(name);  // throws, naming the layers there are
    const std::string& channel = ctx.text("channel");
    const std::string& path = ctx.text("path");
    exr::WriteOptions o;
    o.compression = exr::parse_compression(ctx.text("compression"));
    o.cell = hm->cell();
    o.threads = thread_count();
    const int w = hm->width(), h = hm->height();

    if (!ctx.flag("split")) {
        std::vector<exr::Plane> planes{{channel, hm->heights().data()}};
        for (const auto& name : layers) {
            if (name == channel)
                throw BadInput("layer '" + name + "' would share channel '" + channel +
                               "' with the heights; give the heights another channel name (channel=height)");
            planes.push_back({name, hm->layer(name).data});
        }
        AtomicFile file(ctx.output_path(path));
        file.stream().close();  // OpenEXR writes the temporary by name
        exr::write(file.temporary(), w, h, planes, o);
        file.commit();
        std::string names;
        for (const auto& p : planes) names += (names.empty() ? "" : ", ") + p.channel;
        ctx.info("wrote " + path + " (" + std::to_string(planes.size()) + " float channel" +
                 (planes.size() == 1 ? "" : "s") + ": " + names + "; " + ctx.text("compression") + ")");
        return {};
    }

    // One file a layer, all committed together.
    for (const auto& name : layers)
        if (const std::string problem = file_name_problem(name); !problem.empty()) throw BadInput(problem);
    std::vector<std::unique_ptr<AtomicFile>> files;
    std::vector<std::string> written;
    auto write_one = [&](const std::string& relative, const float* data, const std::string& what) {
        files.push_back(std::make_unique<AtomicFile>(ctx.output_path(relative)));
        files.back()->stream().close();
        exr::WriteOptions one = o;
        one.layer = what;
        const exr::Plane plane{channel, data};
        exr::write(files.back()->temporary(), w, h, std::span(&plane, 1), one);
        written.push_back(relative);
        ctx.check_cancelled();
    };
    write_one(path, hm->heights().data(), "height");
    for (const auto& name : layers) write_one(layer_file(path, name), hm->layer(name).data, name);
    std::vector<AtomicFile*> all;
    for (auto& f : files) all.push_back(f.get());
    commit_all(all);
    std::string names;
    for (const auto& f : written) names += (names.empty() ? "" : ", ") + f;
    ctx.info("wrote " + names + " (one float channel '" + channel + "' each; " + ctx.text("compression") + ")");
    return {};
}

void check(CheckContext& ctx) {
    const std::string& channel = ctx.text("channel");
    if (const std::string problem = exr::channel_name_problem(channel); !problem.empty()) ctx.error("channel", problem);
    const auto names = split_names(ctx.text("layers"));
    if (is_all(names)) return;
    const bool split = ctx.flag("split");
    for (const auto& name : names) {
        if (!ctx.require_layer(0, "layers", name, "name layers the terrain has, or all")) continue;
        if (!split && name == channel)
            ctx.error("layers",
                      "layer '" + name + "' would share channel '" + channel +
                          "' with the heights; give the heights another channel name (channel=height)");
        if (split)
            if (const std::string problem = file_name_problem(name); !problem.empty()) ctx.error("layers", problem);
    }
}

}  // namespace

OROGEN_PLUGIN("export-exr", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "exr",
        .summary = "write the heightmap as OpenEXR 32-bit float channels (Houdini, Nuke, Blender), layers as more "
                   "channels or files",
        .description =
            "One scanline OpenEXR file: the heights in metres in channel `channel` (default Y, which viewers show as "
            "grayscale), and each layer named in `layers` (or all) in a 32-bit float channel of its own name. "
            "split=true writes instead one single-channel file per layer, <stem>.<layer>.exr beside <path>, all "
            "committed together. Rows run north to south (EXR's y grows downwards); the data window is "
            "(0, 0)-(width-1, height-1). The header carries cellSize (double, metres between vertices) and "
            "heightUnits (\"m\"); a one-layer file also orogenLayer (\"height\" or the layer's name). Lossless "
            "compression only, so every bit comes back: zip (default), zips, piz, rle or none. import:exr reads "
            "these files back.",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".exr"}).help("output file: .exr"),
                Param::string("channel", "Y")
                    .help("the heights' channel name (Y: grayscale in viewers; R, height, "
                          "... for tools that want another)"),
                Param::string("layers", "").help("layers written too, comma-separated (\"water, eroded\"), or all"),
                Param::boolean("split", false)
                    .help("one file per layer (<stem>.<layer>.exr, each in channel "
                          "`channel`) instead of one file of many channels"),
                Param::choice("compression", {"zip", "zips", "piz", "rle", "none"}, "zip")
                    .help("lossless compression: zip (16 rows a block), zips (1 row), piz (wavelet), rle, none"),
            },
        .check = check,
        .run = run,
    });
}
