// export:png — a heightmap as an 8- or 16-bit grayscale PNG.
#include "heightmap_png.hpp"

#include <orogen/io.hpp>
#include <orogen/plugin.hpp>

using namespace orogen;

OROGEN_PLUGIN("png-export", "0.1.0", registry) {
    registry.add({
        .kind = "export",
        .name = "png",
        .summary = "write a heightmap as a grayscale PNG (8 or 16 bits, min-max normalised)",
        .description =
            "The lowest vertex becomes black and the highest white; 16 bits keep 65536 levels,\n"
            "which a 1025² terrain needs (8 bits band visibly beyond about 512²).",
        .inputs = {{"terrain", ValueType::heightmap, Need::required, "the heightmap to write"}},
        .output = ValueType::none,
        .params =
            {
                Param::path("path", PathRole::output, {".png"}).help("output file, relative to --out"),
                Param::integer("bits", 8).min(8).max(16).help("bits per sample: 8 or 16"),
            },
        .check = [](CheckContext& ctx) {
            const auto bits = ctx.integer("bits");
            if (bits != 8 && bits != 16) ctx.error("bits", "bits must be 8 or 16, got " + std::to_string(bits));
        },
        .run = [](NodeContext& ctx) -> NodeOutputs {
            const Heightmap& hm = *ctx.input(0).heightmap();
            const int bits = int(ctx.integer("bits"));
            const auto samples = png_export::quantise(hm.view(), bits, png_export::range_of(hm.view()));
            AtomicFile file(ctx.output_path(ctx.text("path")));
            write_gray_png(file.stream(), hm.width(), hm.height(), bits, samples);
            file.commit();
            return {};
        },
    });
}
