// scene_layers.cpp — orogen-view's scene: layers, their colour textures and the hillshade (scene_impl.hpp).
#include "scene_impl.hpp"

namespace orogen::view {

void Scene::Impl::apply_layer() {
    if (shade_for != exaggeration) textures.clear();  // the hillshade they carry is stale
    auto hit = std::find_if(textures.begin(), textures.end(), [&](const CachedTexture& c) { return c.layer == layer; });
    if (hit != textures.end()) {
        textures.splice(textures.begin(), textures, hit);
    } else {
        textures.push_front({layer, colour_texture(layer)});
        std::size_t bytes = 0;
        for (auto it = textures.begin(); it != textures.end();) {
            bytes += texture_bytes(*it);
            it = it != textures.begin() && bytes > texture_cache_bytes ? textures.erase(it) : std::next(it);
        }
    }
    const bool categorical = layer > 0 && colouring(layer).categorical;
    texture->SetInterpolate(!categorical);  // categories stay crisp
    texture->SetInputData(textures.front().image);
    texture->SetColorModeToDirectScalars();
    bar->SetVisibility(layer > 0);
    if (layer > 0) {
        const Colouring& c = colouring(layer);
        bar->SetLookupTable(c.lut);
        bar->SetTitle(c.title.c_str());
    }
}

bool Scene::Impl::prefetch() {
    if (!ground()) return false;
    if (shade_for != exaggeration) textures.clear();
    std::size_t bytes = 0;
    for (const auto& c : textures) bytes += texture_bytes(c);
    const auto [tw, th] = texture_size();
    if (bytes + std::size_t(tw) * th * 3 > texture_cache_bytes) return false;
    const std::size_t count = names().size();
    for (std::size_t k = 1; k <= count; ++k) {
        const std::size_t index = (layer + k) % count;  // the next layers first: where `l` goes
        if (std::none_of(textures.begin(), textures.end(), [&](const CachedTexture& c) { return c.layer == index; })) {
            textures.push_back({index, colour_texture(index)});
            return true;
        }
    }
    return false;
}

const Scene::Impl::Colouring& Scene::Impl::colouring(std::size_t index) {
    auto it = colourings.find(index);
    if (it != colourings.end()) return it->second;
    Colouring c;
    const Terrain& t = *ground();
    c.lut = lut_for(names()[index], values(index), std::size_t(t.width) * t.height, &c.title);
    if (c.lut->GetIndexedLookup()) {
        // Ids are whole numbers stored as floats: a table indexed by id − lowest id.
        c.categorical = true;
        const int count = c.lut->GetNumberOfAnnotatedValues();
        long highest = 0;
        for (int i = 0; i < count; ++i) {
            const long id = c.lut->GetAnnotatedValue(i).ToInt();
            c.lowest = i ? std::min(c.lowest, id) : id;
            highest = i ? std::max(highest, id) : id;
        }
        c.table.assign(std::size_t(highest - c.lowest + 1), {0, 0, 0});
        for (int i = 0; i < count; ++i) {
            const double* rgb = c.lut->GetTableValue(i);
            c.table[std::size_t(c.lut->GetAnnotatedValue(i).ToInt() - c.lowest)] = {
                std::uint8_t(rgb[0] * 255 + 0.5), std::uint8_t(rgb[1] * 255 + 0.5), std::uint8_t(rgb[2] * 255 + 0.5)};
        }
    } else {
        // The lookup table's own colours and index rule (vtkLookupTable: index
        // = (v − lo) · colours / (hi − lo), clamped), so the texture is what
        // MapScalarsThroughTable would give, in one parallel pass.
        const double* range = c.lut->GetRange();
        const vtkIdType count = c.lut->GetNumberOfTableValues();
        c.log = c.lut->GetScale() == VTK_SCALE_LOG10;
        c.lo = c.log ? std::log10(range[0]) : range[0];
        c.scale = double(count) / std::max(c.log ? std::log10(range[1]) - c.lo : range[1] - range[0], 1e-300);
        const unsigned char* rgba = c.lut->GetPointer(0);
        for (vtkIdType k = 0; k < count; ++k) c.table.push_back({rgba[4 * k], rgba[4 * k + 1], rgba[4 * k + 2]});
    }
    return colourings.emplace(index, std::move(c)).first->second;
}

vtkSmartPointer<vtkImageData> Scene::Impl::colour_texture(std::size_t index) {
    const Terrain& t = *ground();
    // Plain ints, not a structured binding: the lambdas below capture them (clang 14 cannot capture a binding).
    const std::pair<int, int> size = texture_size();
    const int tw = size.first, th = size.second;
    update_shade(tw, th);
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(tw, th, 1);
    vtkNew<vtkUnsignedCharArray> rgb;
    rgb->SetNumberOfComponents(3);
    rgb->SetNumberOfTuples(vtkIdType(tw) * th);
    std::uint8_t* const out = rgb->GetPointer(0);
    const float* const shade_of = shade.data();
    // colour c (3 bytes) times the texel's hillshade, rounded, into texel i
    auto lit = [out, shade_of](std::int64_t i, const std::uint8_t* c) {
        const float s = shade_of[i];
        std::uint8_t* o = out + 3 * i;
        o[0] = std::uint8_t(std::min(255.0f, float(c[0]) * s + 0.5f));
        o[1] = std::uint8_t(std::min(255.0f, float(c[1]) * s + 0.5f));
        o[2] = std::uint8_t(std::min(255.0f, float(c[2]) * s + 0.5f));
    };
    constexpr std::int64_t grain = 1 << 16;
    if (index == 0) {
        if (splat.size() != std::size_t(tw) * th * 4) splat = mesh::bake_splat_texture(grid(), tw, th);
        const std::uint8_t* sp = splat.data();
        parallel_for(0, std::int64_t(tw) * th, grain, [&](std::int64_t a, std::int64_t b) {
            for (std::int64_t i = a; i < b; ++i) lit(i, sp + 4 * i);
        });
    } else {
        const Colouring& c = colouring(index);
        const float* v = values(index);
        std::vector<float> sampled;
        if (tw != t.width || th != t.height) {  // over max_texture: nearest sample per texel
            sampled.resize(std::size_t(tw) * th);
            parallel_for(0, th, 16, [&](std::int64_t j0, std::int64_t j1) {
                for (std::int64_t j = j0; j < j1; ++j)
                    for (int i = 0; i < tw; ++i)
                        sampled[std::size_t(j) * tw + i] =
                            v[std::size_t(std::lround(double(j) * (t.height - 1) / (th - 1))) * t.width +
                              std::size_t(std::lround(double(i) * (t.width - 1) / (tw - 1)))];
            });
            v = sampled.data();
        }
        const auto* table = c.table.data();
        const long last = long(c.table.size()) - 1;
        if (c.categorical) {
            const long lowest = c.lowest;
            parallel_for(0, std::int64_t(tw) * th, grain, [&](std::int64_t a, std::int64_t b) {
                for (std::int64_t i = a; i < b; ++i) {
                    const long k = long(std::nearbyint(v[i])) - lowest;  // ids are whole numbers
                    lit(i, table[k >= 0 && k <= last ? k : 0].data());
                }
            });
        } else {
            const double lo = c.lo, scale = c.scale;
            const bool log = c.log;
            parallel_for(0, std::int64_t(tw) * th, grain, [&](std::int64_t a, std::int64_t b) {
                for (std::int64_t i = a; i < b; ++i) {
                    // (a value ≤ 0 on a log scale: log10 gives -inf or NaN, the first colour either way)
                    const double d = ((log ? std::log10(double(v[i])) : double(v[i])) - lo) * scale;
                    lit(i, table[d > 0 ? std::min(long(d), last) : 0].data());
                }
            });
        }
    }
    image->GetPointData()->SetScalars(rgb);
    return image;
}

void Scene::Impl::update_shade(int tw, int th) {
    const Terrain& t = *ground();
    if (shade_for == exaggeration && shade.size() == std::size_t(tw) * th) return;
    shade.resize(std::size_t(tw) * th);
    const ConstGridView g = grid();
    const double e = exaggeration;
    parallel_for(0, th, 16, [&](std::int64_t j0, std::int64_t j1) {
        for (std::int64_t j = j0; j < j1; ++j) {
            const int y = int(std::lround(double(j) * (t.height - 1) / std::max(th - 1, 1)));
            for (int i = 0; i < tw; ++i) {
                const int x = int(std::lround(double(i) * (t.width - 1) / std::max(tw - 1, 1)));
                const auto n = mesh::surface_normal(g, x, y, e);
                const double lit = n[0] * light[0] + n[1] * light[1] + n[2] * light[2];
                shade[std::size_t(j) * tw + i] = float(0.3 + 0.99 * std::max(lit, 0.0));
            }
        }
    });
    shade_for = exaggeration;
}

}  // namespace orogen::view
