// analyze:discriminate — can a classifier tell the generated terrains from the real DEMs, window by window?
// Cuts every input into square windows, measures each by scale-free geomorphic figures, and cross-validates an
// XGBoost classifier leaving one whole input out at a time (orogen_analysis's discriminate(),
// docs/analysis.md "Telling windows apart"). Writes PATH (JSON), its stem + .txt (the table `orogen analyze
// --discriminate` prints) and a picture of the most generated-looking windows beside the most real ones.
#include "report.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <sstream>
#include <stdexcept>

namespace {

using namespace orogen;

constexpr int max_sources = 32;

std::vector<std::string> split_list(const std::string& text) {
    std::vector<std::string> out;
    if (text.empty()) return out;
    std::string item;
    std::istringstream in(text);
    while (std::getline(in, item, ',')) {
        const auto b = item.find_first_not_of(' '), e = item.find_last_not_of(' ');
        out.push_back(b == std::string::npos ? std::string() : item.substr(b, e - b + 1));
    }
    return out;
}

void check(CheckContext& ctx) {
    std::size_t n = 0;
    while (n < std::size_t(max_sources) && ctx.input(n)) ++n;
    const auto names = split_list(ctx.text("names"));
    if (ctx.given("names") && names.size() != n)
        ctx.error("names",
                  "names= gives " + std::to_string(names.size()) + " names for " + std::to_string(n) +
                      " inputs; give one per input, comma-separated");
    const auto real = std::size_t(ctx.integer("real"));
    if (real < 2 || n - std::min(real, n) < 2)
        ctx.error("real",
                  "real=" + std::to_string(real) + " of " + std::to_string(n) +
                      " inputs: leaving one source out needs at least two real DEMs (the last `real` "
                      "inputs) and two generated terrains (the others)");
}

NodeOutputs run(NodeContext& ctx) {
    std::size_t n = 0;
    while (n < std::size_t(max_sources) && ctx.has_input(n)) ++n;
    auto names = split_list(ctx.text("names"));
    for (std::size_t i = names.size(); i < n; ++i) names.push_back("terrain" + std::to_string(i + 1));
    const std::size_t real = std::size_t(ctx.integer("real"));
    std::vector<std::vector<std::uint8_t>> masks(n);
    std::vector<analysis::Source> sources;
    for (std::size_t i = 0; i < n; ++i) {
        const Heightmap& hm = *ctx.input(i).heightmap();
        // A `nodata` layer (import:geotiff holes=mask) marks holes; windows holding more than 1 % are skipped.
        if (hm.has_layer("nodata")) {
            const ConstGridView holes = hm.layer("nodata");
            masks[i].resize(hm.size());
            for (std::size_t k = 0; k < hm.size(); ++k) masks[i][k] = holes.data[k] == 0.0f;
        }
        sources.push_back(
            {names[i],
             {hm.heights().data(), hm.width(), hm.height(), hm.cell(), masks[i].empty() ? nullptr : masks[i].data()},
             i >= n - real});
    }
    analysis::DiscriminateOptions options;
    options.window_m = ctx.real("window_m");
    if (const std::string problem = analysis::check_sources(sources, options); !problem.empty())
        throw BadInput(problem);
    ctx.progress(0.05);
    analysis::Discrimination d;
    try {
        d = analysis::discriminate(sources, options);
    } catch (const std::invalid_argument& e) {
        throw BadInput(e.what());  // too many holes left a kind with no window to learn from
    } catch (const std::runtime_error& e) {
        throw Error(e.what());  // XGBoost failed
    }
    ctx.check_cancelled();
    const std::string json_rel = ctx.text("path");
    const auto stem = std::filesystem::path(json_rel).stem().string();
    const auto folder = std::filesystem::path(json_rel).parent_path();
    AtomicFile json(ctx.output_path(json_rel)), table(ctx.output_path((folder / (stem + ".txt")).string())),
        picture(ctx.output_path(ctx.text("picture")));
    json.stream() << analyze::discrimination_json(d);
    table.stream() << analyze::discrimination_text(d);
    int width = 0, height = 0;
    const auto pixels = analyze::discrimination_picture(d, sources, analyze::shown_windows(d), width, height);
    write_gray_png(picture.stream(), width, height, 8, pixels);
    AtomicFile* all[] = {&json, &table, &picture};
    commit_all(all);
    ctx.progress(1.0);
    return {};
}

std::string description() {
    std::string text =
        "Cuts every input into square windows of window_m metres, describes each by the figures below, and\n"
        "trains an XGBoost classifier to tell the real inputs (the last `real`) from the generated ones, leaving\n"
        "one whole input out at a time: every window is judged by a model that never saw its input. Writes PATH\n"
        "(JSON), PATH's stem + .txt (the table) and `picture` (PNG: the most generated-looking windows above the\n"
        "most real-looking, hillshaded). The balanced accuracy is the mean of the share of real windows called\n"
        "real and of generated windows called generated: 50 % when nothing tells them apart. Each input's windows\n"
        "are window_m in its own cells; the coarsest cell may be at most 12 % coarser than the finest\n"
        "(docs/analysis.md, \"Telling windows apart\"). Window figures:\n";
    for (const auto& f : analysis::window_figure_table())
        text += "  " + std::string(f.key) + (f.unit.empty() ? "" : " (" + std::string(f.unit) + ")") + ": " +
            std::string(f.definition) + ". [" + std::string(f.source) + "]\n";
    return text;
}

}  // namespace

OROGEN_PLUGIN("analyze-discriminate", "0.1.0", registry) {
    std::vector<InputSpec> inputs = {{"terrain", ValueType::heightmap, Need::required, "a source of windows"}};
    for (int i = 2; i <= max_sources; ++i)
        inputs.push_back({"terrain" + std::to_string(i), ValueType::heightmap, Need::optional, "another source"});
    registry.add({
        .kind = "analyze",
        .name = "discriminate",
        .summary = "can a classifier tell the generated terrains from real DEMs, window by window?",
        .description = description(),
        .inputs = std::move(inputs),
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".json"}, "discriminate.json")
                    .help("the report (JSON), relative to --out; the table (.txt) goes beside it"),
                Param::path("picture", PathRole::output, {".png"}, "discriminate.png")
                    .help("the most generated-looking windows above the most real-looking ones, hillshaded"),
                Param::string("names", "").help("a name per input, comma-separated (default: terrain1, terrain2...)"),
                Param::integer("real", 2)
                    .min(2)
                    .max(max_sources - 2)
                    .help("how many of the last inputs are real DEMs; the others are generated terrains"),
                Param::real("window_m", 3840.0)
                    .min(0, true)
                    .unit("m")
                    .help("the windows' side (3840 m: 128 cells at 30 m)"),
            },
        .check = check,
        .run = run,
    });
}
