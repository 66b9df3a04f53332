// import:png — a grayscale PNG (8 or 16 bits) as a heightmap.
#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("import-png", "0.1.0", registry) {
    registry.add({
        .kind = "import",
        .name = "png",
        .summary = "read a grayscale PNG (8 or 16 bits) as a heightmap, black = low, white = high",
        .description = "Pixel p of a b-bit image becomes low + (high − low) · p / (2^b − 1) metres. The\n"
                       "heightmap has the image's size, whatever the spec's grid says.",
        .inputs = {},
        .output = ValueType::heightmap,
        .params =
            {
                Param::path("path", PathRole::input).help("the PNG, relative to the spec's folder"),
                Param::real("low", 0.0).min(-1e6).max(1e6).unit("m").help("height of black"),
                Param::real("high", 1000.0).min(-1e6).max(1e6).unit("m").help("height of white"),
                Param::real("cell", 0.0).min(0).max(1e6).unit("m").help("vertex spacing; 0 = the spec's grid cell"),
            },
        .check =
            [](CheckContext& ctx) {
                if (!(ctx.real("high") > ctx.real("low")))
                    ctx.error("high", "high must be above low (" + std::to_string(ctx.real("low")) + " m)");
                try {  // the header now, so a wrong file fails before anything runs
                    const GrayImage header = read_gray_png_header(ctx.resolved_path("path"));
                    ctx.output().width = header.width;
                    ctx.output().height = header.height;
                    ctx.output().cell = ctx.real("cell") > 0 ? ctx.real("cell") : ctx.grid().cell;
                    ctx.output().layers_known = true;
                } catch (const BadInput& e) { ctx.error("path", e.what()); }
            },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            const GrayImage image = read_gray_png(ctx.input_path("path"));
            const double cell = ctx.real("cell") > 0 ? ctx.real("cell") : ctx.grid().cell;
            auto hm = std::make_shared<Heightmap>(image.width, image.height, cell);
            const double low = ctx.real("low"), high = ctx.real("high");
            const double step = (high - low) / double(image.bits == 16 ? 65535 : 255);
            auto& h = hm->heights();
            for (std::size_t i = 0; i < h.size(); ++i) h[i] = float(low + step * image.samples[i]);
            ctx.progress(1.0);
            return hm;
        },
    });
}
