#include <orogen/error.hpp>
#include <orogen/values.hpp>

#include <algorithm>

namespace orogen {

std::string_view to_string(ValueType type) {
    switch (type) {
        case ValueType::none: return "nothing";
        case ValueType::heightmap: return "heightmap";
        case ValueType::image: return "image";
        case ValueType::particles: return "particles";
        case ValueType::plates: return "plates";
        case ValueType::series: return "series";
    }
    return "?";
}

Heightmap::Heightmap(int width, int height, double cell, float elevation)
    : width_(width), height_(height), cell_(cell), heights_(std::size_t(width) * std::size_t(height), elevation) {}

Heightmap::Heightmap(int width, int height, double cell, std::vector<float> heights)
    : width_(width), height_(height), cell_(cell), heights_(std::move(heights)) {
    if (width < 0 || height < 0 || heights_.size() != size())
        throw Error("internal error: a " + std::to_string(width) + " x " + std::to_string(height) +
                    " heightmap given " + std::to_string(heights_.size()) + " heights");
}

bool Heightmap::has_layer(std::string_view name) const { return layers_.find(name) != layers_.end(); }

GridView Heightmap::layer(std::string_view name, float fill) {
    auto it = layers_.find(name);
    if (it == layers_.end()) it = layers_.emplace(std::string(name), std::vector<float>(size(), fill)).first;
    return {it->second.data(), width_, height_, cell_};
}

void Heightmap::set_layer(std::string_view name, std::vector<float> values) {
    if (values.size() != size())
        throw Error("internal error: layer '" + std::string(name) + "' of " + std::to_string(values.size()) +
                    " values for a heightmap of " + std::to_string(size()) + " vertices");
    auto it = layers_.find(name);
    if (it == layers_.end()) layers_.emplace(std::string(name), std::move(values));
    else it->second = std::move(values);
}

ConstGridView Heightmap::layer(std::string_view name) const {
    auto it = layers_.find(name);
    if (it == layers_.end()) {
        std::string known;
        for (const auto& [n, _] : layers_) known += (known.empty() ? "" : ", ") + n;
        throw BadInput("the heightmap has no layer '" + std::string(name) + "' (it has " +
                       (known.empty() ? std::string("no layers") : known) + ")");
    }
    return {it->second.data(), width_, height_, cell_};
}

void Heightmap::remove_layer(std::string_view name) {
    auto it = layers_.find(name);
    if (it != layers_.end()) layers_.erase(it);
}

std::vector<std::string> Heightmap::layer_names() const {
    std::vector<std::string> names;
    for (const auto& [n, _] : layers_) names.push_back(n);
    return names;
}

std::size_t ParticleFrame::count() const {
    auto it = attributes.find("position");
    return it == attributes.end() ? 0 : it->second.data.size() / 3;
}

namespace {
[[noreturn]] void wrong_type(ValueType want, ValueType have) {
    throw Error("internal error: expected a " + std::string(to_string(want)) + " value, got " +
                std::string(to_string(have)));
}
}  // namespace

const std::shared_ptr<const Heightmap>& Value::heightmap() const {
    if (type() != ValueType::heightmap) wrong_type(ValueType::heightmap, type());
    return std::get<1>(v_);
}
const std::shared_ptr<const Image>& Value::image() const {
    if (type() != ValueType::image) wrong_type(ValueType::image, type());
    return std::get<2>(v_);
}
const std::shared_ptr<const ParticleSeries>& Value::particles() const {
    if (type() != ValueType::particles) wrong_type(ValueType::particles, type());
    return std::get<3>(v_);
}
const std::shared_ptr<const PlateHistory>& Value::plates() const {
    if (type() != ValueType::plates) wrong_type(ValueType::plates, type());
    return std::get<4>(v_);
}
const std::shared_ptr<const Series>& Value::series() const {
    if (type() != ValueType::series) wrong_type(ValueType::series, type());
    return std::get<5>(v_);
}

Value Series::at(std::size_t i) const {
    if (i >= size())
        throw Error("internal error: series entry " + std::to_string(i) + " asked of a series of " +
                    std::to_string(size()));
    if (!make) throw Error("internal error: a series without a way to make its entries");
    Value v = make(i);
    if (v.type() != element)
        throw Error("internal error: entry " + std::to_string(i) + " of a series of " +
                    std::string(to_string(element)) + "s is a " + std::string(to_string(v.type())));
    return v;
}

std::shared_ptr<Series> series_of(ValueType element, std::vector<double> times, std::vector<Value> entries) {
    if (times.size() != entries.size())
        throw Error("internal error: a series of " + std::to_string(entries.size()) + " entries with " +
                    std::to_string(times.size()) + " times");
    auto s = std::make_shared<Series>();
    s->element = element;
    s->times = std::move(times);
    auto held = std::make_shared<const std::vector<Value>>(std::move(entries));
    s->make = [held](std::size_t i) { return (*held)[i]; };
    return s;
}

}  // namespace orogen
