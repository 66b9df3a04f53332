// analyze:terrain — geomorphometry inside a pipeline: measures up to 16 heightmaps with orogen_analysis
// (libs/analysis), compares them with the ones marked as references, and writes the report: the table
// (.txt), analysis.json, the charts (gnuplot) and a Markdown page. `orogen analyze` runs this node.
#include "report.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

#include <cmath>
#include <sstream>

namespace {

using namespace orogen;

constexpr int max_terrains = 16;

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

std::size_t inputs_given(CheckContext& ctx) {
    std::size_t n = 0;
    while (n < std::size_t(max_terrains) && ctx.input(n)) ++n;
    return n;
}

void check(CheckContext& ctx) {
    const std::size_t n = inputs_given(ctx);
    const auto names = split_list(ctx.text("names"));
    if (ctx.given("names") && names.size() != n) {
        ctx.error("names",
                  "names= gives " + std::to_string(names.size()) + " name" + (names.size() == 1 ? "" : "s") + " for " +
                      std::to_string(n) + " terrain" + (n == 1 ? "" : "s") + "; give one per input, comma-separated");
        return;
    }
    for (const auto& name : names)
        if (name.empty()) {
            ctx.error("names", "names= has an empty name; give one per input, comma-separated");
            return;
        }
    if (std::size_t(ctx.integer("references")) >= n && ctx.integer("references") > 0)
        ctx.error("references",
                  "references=" + std::to_string(ctx.integer("references")) + " marks every one of the " +
                      std::to_string(n) + " inputs as a reference; leave at least one terrain to measure");
    const auto images = split_list(ctx.text("images"));
    if (!images.empty() && images.size() != n)
        ctx.error("images",
                  "images= gives " + std::to_string(images.size()) + " pictures for " + std::to_string(n) +
                      " terrains; give one per input (or none)");
    for (std::size_t i = 0; i < n; ++i) {
        const ValueInfo* in = ctx.input(i);
        if (in->width > 0 && in->height > 0 && (in->width < 3 || in->height < 3))
            ctx.error("",
                      "input " + std::to_string(i + 1) + " is " + std::to_string(in->width) + "x" +
                          std::to_string(in->height) + ": too small to measure (at least 3x3)");
    }
}

std::string stem_of(const std::string& path) {
    const std::filesystem::path p(path);
    return p.stem().string();
}

NodeOutputs run(NodeContext& ctx) {
    std::size_t n = 0;
    while (n < std::size_t(max_terrains) && ctx.has_input(n)) ++n;
    auto names = split_list(ctx.text("names"));
    if (names.empty())
        for (std::size_t i = 0; i < n; ++i) names.push_back(n == 1 ? ctx.label() : "terrain" + std::to_string(i + 1));
    const auto images = split_list(ctx.text("images"));
    const std::size_t references = std::size_t(ctx.integer("references"));

    std::vector<analyze::Terrain> terrains(n);
    bool anything = false;
    for (std::size_t i = 0; i < n; ++i) {
        ctx.check_cancelled();
        const Heightmap& hm = *ctx.input(i).heightmap();
        // A `nodata` layer (import:geotiff holes=mask) marks holes: 1 a hole, 0 a measured sample.
        std::vector<std::uint8_t> valid;
        if (hm.has_layer("nodata")) {
            const ConstGridView holes = hm.layer("nodata");
            valid.resize(hm.size());
            for (std::size_t k = 0; k < hm.size(); ++k) valid[k] = holes.data[k] == 0.0f;
        }
        analyze::Terrain& t = terrains[i];
        t.name = names[i];
        t.reference = i >= n - references;
        if (!images.empty()) t.image = images[i];
        analysis::Options options;
        options.fit_filled_cells = ctx.text("filled_flats") == "fit";
        t.figures = analysis::measure(
            {hm.heights().data(), hm.width(), hm.height(), hm.cell(), valid.empty() ? nullptr : valid.data()}, options);
        for (const auto& m : t.figures.values) anything = anything || m.ok();
        ctx.progress(double(i + 1) / double(n + 1));
    }
    if (!anything)
        throw BadInput("no figure could be measured on any terrain: " +
                       terrains.front().figures.values.front().why_not);

    const auto comparison = analyze::compare(terrains);
    const std::string json_rel = ctx.text("path");
    const std::string stem = stem_of(json_rel);
    const std::filesystem::path folder_rel = std::filesystem::path(json_rel).parent_path();
    auto relative = [&](const std::string& file) { return (folder_rel / file).string(); };

    const std::string table = analyze::table_text(terrains, comparison);
    const std::string json = analyze::json_text(terrains, comparison);
    analyze::ChartsWritten charts;
    if (ctx.flag("charts")) {
        const std::filesystem::path folder = ctx.output_path(relative(stem + "-slopes.png")).parent_path();
        charts = analyze::write_charts(terrains, folder, stem);
        if (!charts.problem.empty()) ctx.warn("no charts: " + charts.problem);
    }
    const std::string& page_rel = ctx.text("page");
    // The page links the other files relative to its own folder.
    const auto page_folder = std::filesystem::path(page_rel).parent_path();
    auto from_page = [&](const std::string& rel_to_out) {
        return std::filesystem::path(rel_to_out).lexically_relative(page_folder).generic_string();
    };
    std::vector<analyze::Chart> linked = charts.charts;
    for (auto& c : linked) c.file = from_page(relative(c.file));
    auto page_terrains = terrains;
    for (auto& t : page_terrains)
        if (!t.image.empty()) t.image = from_page(t.image);
    const std::string page = analyze::markdown_text(page_terrains, comparison, linked, from_page(json_rel));

    AtomicFile json_file(ctx.output_path(json_rel)), table_file(ctx.output_path(relative(stem + ".txt"))),
        page_file(ctx.output_path(page_rel));
    json_file.stream() << json;
    table_file.stream() << table;
    page_file.stream() << page;
    AtomicFile* all[] = {&json_file, &table_file, &page_file};
    commit_all(all);
    ctx.progress(1.0);
    return {};
}

std::string description() {
    std::string text =
        "Measures each input heightmap (a `nodata` layer, 1 = hole, masks samples out) and writes PATH (JSON: every\n"
        "figure with its units, definition and source), PATH's stem + .txt (the table `orogen analyze` prints),\n"
        "+ -slopes.png, -hypsometry.png, -spectrum.png, -slope-area.png, -hack.png (gnuplot-nox), and a Markdown\n"
        "page (page=). The last `references` inputs are references (real DEMs): the\n"
        "table gives their min–max per figure, whether each other terrain is inside, and which reference it\n"
        "resembles most (RMS over the figures of the difference in units of the references' standard deviation).\n"
        "Definitions as shared/realism/README.md and terrain_stats.py (docs/analysis.md). Figures:\n";
    for (const auto& f : analysis::figure_table()) {
        text += "  " + std::string(f.key) + (f.unit.empty() ? "" : " (" + std::string(f.unit) + ")") + ": " +
            std::string(f.definition) + ". [" + std::string(f.source) + "]\n";
    }
    return text;
}

}  // namespace

OROGEN_PLUGIN("analyze-terrain", "0.1.0", registry) {
    std::vector<InputSpec> inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to measure"}};
    for (int i = 2; i <= max_terrains; ++i)
        inputs.push_back({"terrain" + std::to_string(i), ValueType::heightmap, Need::optional,
                          "another heightmap, measured and compared alongside"});
    registry.add({
        .kind = "analyze",
        .name = "terrain",
        .summary = "geomorphometry: slopes, hypsometry, spectrum, river concavity and more, against real DEMs",
        .description = description(),
        .inputs = std::move(inputs),
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".json"}, "analysis.json")
                    .help("the report (JSON), relative to --out; the table, charts and page go beside it"),
                Param::path("page", PathRole::output, {".md"}, "analysis.md")
                    .help("the Markdown page showing the table, charts and pictures, relative to --out"),
                Param::string("names", "").help("a name per input, comma-separated (default: terrain1, terrain2...)"),
                Param::integer("references", 0)
                    .min(0)
                    .max(max_terrains - 1)
                    .help("how many of the last inputs are references (real DEMs) the others are compared with"),
                Param::string("images", "")
                    .help(
                        "a picture per input, comma-separated paths relative to --out, shown side by side on the page"),
                Param::boolean("charts", true).help("draw the charts (needs gnuplot-nox)"),
                Param::choice("filled_flats", {"fit", "skip"}, "skip")
                    .help("whether the channel cells the priority flood raised (filled flats, slope 1e-4 give or "
                          "take rounding) enter the fits of θ, k_sn and Hack's h: skip them (steady across cell "
                          "sizes and reprojections), or fit them as terrain_stats.py does (docs/analysis.md)"),
            },
        .check = check,
        .run = run,
    });
}
