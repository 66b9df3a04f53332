#include <orogen/error.hpp>
#include <orogen/timelapse.hpp>

#include <orogen/io.hpp>  // human_bytes

#include <algorithm>

#include <unistd.h>

namespace orogen {

Param timelapse_param() {
    return Param::integer("timelapse_every", 0)
        .min(0)
        .help(
            "record the heightmap every this many steps into the side value NAME.timelapse (a series "
            "render:terrain maps over and export:video encodes); 0 = no time-lapse");
}

SideOutput timelapse_output() {
    return {"timelapse", ValueType::heightmap,
            "the heightmap before the first step, every timelapse_every steps and after the last", true};
}

void check_timelapse(CheckContext& ctx, std::int64_t steps) {
    const std::int64_t every = ctx.integer("timelapse_every");
    ValueInfo* side = ctx.side_output("timelapse");
    if (every <= 0) {
        if (side) side->empty = true;  // nothing is recorded: a consumer can say so before the run
        return;
    }
    const ValueInfo* in = ctx.input(0);
    const double w = in && in->width > 0 ? in->width : ctx.grid().width;
    const double h = in && in->height > 0 ? in->height : ctx.grid().height;
    // Step 0, every multiple of `every`, and the last step if it is not one.
    const double frames = double(steps / every) + 1.0 + (steps % every != 0 ? 1.0 : 0.0);
    if (side) {
        side->count = std::size_t(frames);
        side->width = int(w);
        side->height = int(h);
        if (in && in->cell > 0) side->cell = in->cell;
    }
    const double bytes = frames * w * h * 4.0 * 2.0;  // heights + water
    const double memory = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGE_SIZE));
    if (bytes > memory / 2)
        ctx.error("timelapse_every",
                  "a time-lapse of " + std::to_string(std::int64_t(frames)) + " snapshots of " +
                      std::to_string(int(w)) + "×" + std::to_string(int(h)) + " needs " + human_bytes(bytes) +
                      ", more than half of this machine's " + human_bytes(memory) + "; record less often");
}

Timelapse::Timelapse(std::int64_t every, double seconds_per_step)
    : every_(every), seconds_per_step_(seconds_per_step) {}

Timelapse::Timelapse(std::int64_t every, double seconds_per_step, Tiling& tiles)
    : every_(every), tiles_(&tiles), seconds_per_step_(seconds_per_step) {}

namespace {
const float* water_of(const Heightmap& terrain) {
    return terrain.has_layer("water") ? terrain.layer("water").data : nullptr;
}
}  // namespace

void Timelapse::record(std::int64_t step, const Heightmap& terrain) { record(step, terrain.view(), water_of(terrain)); }

void Timelapse::record(std::int64_t step, ConstGridView heights, const float* water) {
    if (due(step)) take(step, heights, water);
}

void Timelapse::record(std::int64_t step, ConstGridView held, const float* water, int x0, int y0) {
    if (due(step)) take(step, held, water, x0, y0);
}

void Timelapse::finish(std::int64_t step, const Heightmap& terrain) {
    if (enabled() && step != last_) take(step, terrain.view(), water_of(terrain));
}

void Timelapse::take(std::int64_t step, ConstGridView heights, const float* water, int x0, int y0) {
    last_ = step;
    if (tiles_) {  // the tile's part of `heights` (and `water`), gathered into a whole-grid frame on rank 0
        const TileRect own = tiles_->owned();
        const bool root = tiles_->rank() == 0;
        const TileRect want = root ? TileRect{0, 0, tiles_->grid_width(), tiles_->grid_height()} : TileRect{};
        std::vector<float> mine(std::size_t(own.width) * std::size_t(own.height));
        auto gather = [&](const float* held) {
            for (int y = 0; y < own.height; ++y)
                std::copy_n(held + std::size_t(y + y0) * std::size_t(heights.width) + std::size_t(x0), own.width,
                            mine.begin() + std::ptrdiff_t(std::size_t(y) * std::size_t(own.width)));
            return tiles_->fetch(mine.data(), want);
        };
        std::vector<float> whole_heights = gather(heights.data), whole_water;
        if (water) whole_water = gather(water);  // every rank has the layer or none does (the same node)
        if (!root) return;
        auto frame = std::make_shared<Heightmap>(want.width, want.height, heights.cell);
        frame->heights() = std::move(whole_heights);
        if (water) frame->set_layer("water", std::move(whole_water));
        times_.push_back(double(step) * seconds_per_step_);
        frames_.push_back(Value(std::move(frame)));
        return;
    }
    auto frame = std::make_shared<Heightmap>(heights.width, heights.height, heights.cell);
    const std::size_t n = frame->size();
    std::copy(heights.data, heights.data + n, frame->heights().begin());
    if (water) std::copy(water, water + n, frame->layer("water").data);
    times_.push_back(double(step) * seconds_per_step_);
    frames_.push_back(Value(std::move(frame)));
}

std::shared_ptr<Series> Timelapse::series() const { return series_of(ValueType::heightmap, times_, frames_); }

}  // namespace orogen
