// render:bright-pass, render:blur, render:combine, render:bloom — the
// thesis's bloom (§3.7.2), each pass its own node so it can be tuned or
// swapped; render:bloom chains them with the thesis's defaults.
#include "bloom.hpp"

#include <orogen/error.hpp>
#include <orogen/plugin.hpp>

#include <cmath>

using namespace orogen;
using namespace orogen::render;

namespace {

std::vector<Param> bright_params(int scale) {
    return {
        Param::real("luminance", 0.5).min(0, true).help("the scene's assumed average luminance"),
        Param::real("grey", 0.5).min(0, true).help("the middle grey that average is scaled to"),
        Param::real("white", 1.5).min(0, true).help("luminance Reinhard's curve maps to 1"),
        Param::real("threshold", 0.4).min(0).help("mapped luminance below this is dropped"),
        Param::integer("scale", scale)
            .min(1)
            .max(16)
            .help("the bright pass is 1/scale the image's size (box-averaged)"),
    };
}

BrightPass bright_from(NodeContext& ctx) {
    BrightPass b;
    b.average_luminance = ctx.real("luminance");
    b.middle_grey = ctx.real("grey");
    b.white = ctx.real("white");
    b.threshold = ctx.real("threshold");
    b.scale = int(ctx.integer("scale"));
    return b;
}

NodeOutputs image_out(Image image) { return NodeOutputs(std::make_shared<Image>(std::move(image))); }

void same_size_output(CheckContext& ctx, int scale = 1) {
    const ValueInfo* in = ctx.input(0);
    ctx.output().type = ValueType::image;
    ctx.output().layers.clear();
    if (in && in->width > 0) {
        ctx.output().width = (in->width + scale - 1) / scale;
        ctx.output().height = (in->height + scale - 1) / scale;
    }
}

}  // namespace

OROGEN_PLUGIN("render-bloom", "0.1.0", registry) {
    registry.add({
        .kind = "render",
        .name = "bright-pass",
        .summary = "bloom pass 1: keep what is bright (Reinhard-mapped luminance above a threshold)",
        .description = "Each pixel's luminance L, scaled by grey/luminance, is mapped by Reinhard's formula\n"
                       "Ld = L (1 + L / white²) / (1 + L); the pixel keeps max(Ld − threshold, 0)/Ld of its colour.",
        .inputs = {{"image", ValueType::image, Need::required, "the frame (linear)"}},
        .output = ValueType::image,
        .params = bright_params(1),
        .check = [](CheckContext& ctx) { same_size_output(ctx, int(ctx.integer("scale"))); },
        .run = [](NodeContext& ctx) { return image_out(bright_pass(*ctx.input(0).image(), bright_from(ctx))); },
    });
    registry.add({
        .kind = "render",
        .name = "blur",
        .summary = "bloom passes 2 and 3: one axis of a Gaussian blur (run axis=x then axis=y)",
        .description = "A Gaussian of sigma × the image width, taps out to 3 sigma, the image mirrored at its edges\n"
                       "(which keeps its mean). x then y equals the two-dimensional Gaussian.",
        .inputs = {{"image", ValueType::image, Need::required, "the image to blur"}},
        .output = ValueType::image,
        .params =
            {
                Param::choice("axis", {"x", "y"}, "x").help("the direction of this pass"),
                Param::real("sigma", 0.028 / 3.0)
                    .min(0)
                    .max(0.25)
                    .help("standard deviation, a fraction of the image width (the thesis: ±0.028 of the frame = 3 "
                          "sigma)"),
            },
        .check = [](CheckContext& ctx) { same_size_output(ctx); },
        .run =
            [](NodeContext& ctx) {
                const Image& in = *ctx.input(0).image();
                const double sigma = ctx.real("sigma") * in.width;
                if (std::ceil(3 * sigma) > 256)
                    throw BadInput("render:blur: sigma is " + std::to_string(sigma) +
                                   " pixels; at most 85 pixels are supported (bright-pass scale= shrinks the image)");
                return image_out(blur(in, ctx.text("axis") == "y" ? Axis::y : Axis::x, sigma));
            },
    });
    registry.add({
        .kind = "render",
        .name = "combine",
        .summary = "bloom pass 4: the original frame plus strength × the blurred bright pass",
        .inputs = {{"image", ValueType::image, Need::required, "the original frame"},
                   {"bloom", ValueType::image, Need::required, "the blurred bright pass (may be smaller)"}},
        .output = ValueType::image,
        .params = {Param::real("strength", 0.667).min(0).help("how much of the bloom is added")},
        .check = [](CheckContext& ctx) { same_size_output(ctx); },
        .run =
            [](NodeContext& ctx) {
                return image_out(combine(*ctx.input(0).image(), *ctx.input(1).image(), ctx.real("strength")));
            },
    });
    std::vector<Param> bloom_params = bright_params(4);
    bloom_params.push_back(Param::real("sigma", 0.028 / 3.0)
                               .min(0)
                               .max(0.25)
                               .help("blur standard deviation, a fraction of the image width (±3 sigma = the thesis's "
                                     "±0.028 of the frame)"));
    bloom_params.push_back(Param::real("strength", 0.667).min(0).help("how much of the blurred bright pass is added"));
    registry.add({
        .kind = "render",
        .name = "bloom",
        .summary = "the thesis's bloom: bright pass, blur x, blur y, combine (its defaults)",
        .description = "The four passes in one node, kept on the GL side between passes (faster than chaining\n"
                       "render:bright-pass, render:blur twice and render:combine, with the same result).",
        .inputs = {{"image", ValueType::image, Need::required, "the frame (linear HDR)"}},
        .output = ValueType::image,
        .params = bloom_params,
        .check = [](CheckContext& ctx) { same_size_output(ctx); },
        .run =
            [](NodeContext& ctx) {
                Bloom b;
                b.bright = bright_from(ctx);
                b.sigma = ctx.real("sigma");
                b.strength = ctx.real("strength");
                return image_out(bloom(*ctx.input(0).image(), b));
            },
    });
}
