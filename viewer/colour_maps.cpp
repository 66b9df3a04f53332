// colour_maps.cpp — orogen-view's colour maps (colour_maps.hpp).
#include "colour_maps.hpp"

#include <orogen/parallel.hpp>

#include <vtkColorTransferFunction.h>
#include <vtkNew.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <set>

namespace orogen::view {

namespace {

struct LayerStyle {
    std::string unit;
    enum Kind { sequential, diverging, categorical } kind = sequential;
};

LayerStyle style_of(const std::string& name, float lo, float hi) {
    if (name == "plate") return {"id", LayerStyle::categorical};
    if (name == "boundary") return {"1 convergent, 2 divergent, 3 transform", LayerStyle::categorical};
    if (name == "eroded") return {"m", LayerStyle::diverging};
    // The units the nodes write (orogen help NODE): drainage is an area; flow_direction a D8 code.
    const char* unit = name == "flow" ? "m/s"
        : name == "hardness"          ? "0..1"
        : name == "drainage"          ? "m²"
        : name == "flow_direction"    ? "D8 code"
                                      : "m";
    return {unit, lo < 0 && hi > 0 ? LayerStyle::diverging : LayerStyle::sequential};
}

/// Qualitative colours (ColorBrewer Set1/Set3 family) for ids.
const unsigned char categorical_colours[][3] = {{228, 26, 28},   {55, 126, 184},  {77, 175, 74},   {152, 78, 163},
                                                {255, 127, 0},   {255, 255, 51},  {166, 86, 40},   {247, 129, 191},
                                                {141, 211, 199}, {190, 186, 218}, {128, 177, 211}, {179, 222, 105},
                                                {252, 205, 229}, {188, 128, 189}, {204, 235, 197}, {255, 237, 111}};

/// The lowest and highest of n values, over a few blocks in parallel.
std::pair<float, float> value_range(const float* v, std::size_t n) {
    const std::int64_t blocks = std::clamp<std::int64_t>(std::int64_t(n >> 16), 1, 16);
    std::vector<std::pair<float, float>> part(std::size_t(blocks), {v[0], v[0]});
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) {
            auto& [lo, hi] = part[std::size_t(b)];
            for (std::size_t i = n * std::size_t(b) / std::size_t(blocks);
                 i < n * std::size_t(b + 1) / std::size_t(blocks); ++i)
                lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
        }
    });
    auto range = part.front();
    for (const auto& [lo, hi] : part) range = {std::min(range.first, lo), std::max(range.second, hi)};
    return range;
}

/// The k-th smallest of |v| (k from 0): exactly what nth_element over a copy
/// gives, without sorting a copy of every value (15 ms at 1025²). The bits of
/// a non-negative float order like its value, so a histogram of their top 16
/// bits (per block, in parallel) finds the bucket holding the k-th, and only
/// that bucket's values are selected among.
float kth_magnitude(const float* v, std::size_t n, std::size_t k) {
    auto bits = [](float x) {
        std::uint32_t b;
        const float m = std::fabs(x);
        std::memcpy(&b, &m, 4);
        return b;
    };
    constexpr std::size_t buckets = std::size_t(1) << 16;
    const std::int64_t blocks = std::clamp<std::int64_t>(std::int64_t(n >> 16), 1, 8);
    std::vector<std::uint32_t> count(std::size_t(blocks) * buckets, 0);
    parallel_for(0, blocks, 1, [&](std::int64_t b0, std::int64_t b1) {
        for (std::int64_t b = b0; b < b1; ++b) {
            std::uint32_t* c = &count[std::size_t(b) * buckets];
            for (std::size_t i = n * std::size_t(b) / std::size_t(blocks);
                 i < n * std::size_t(b + 1) / std::size_t(blocks); ++i)
                ++c[bits(v[i]) >> 16];
        }
    });
    std::size_t below = 0, bucket = 0;
    for (;; ++bucket) {
        std::size_t c = 0;
        for (std::int64_t b = 0; b < blocks; ++b) c += count[std::size_t(b) * buckets + bucket];
        if (below + c > k) break;
        below += c;
    }
    std::vector<float> in;
    for (std::size_t i = 0; i < n; ++i)
        if ((bits(v[i]) >> 16) == bucket) in.push_back(std::fabs(v[i]));
    std::nth_element(in.begin(), in.begin() + std::ptrdiff_t(k - below), in.end());
    return in[k - below];
}

}  // namespace

/// A colour map with a control point at each of `colours` (RGB 0..255) spread over lo..hi, evenly in the
/// value or, with `log`, in its logarithm (lo > 0).
vtkSmartPointer<vtkLookupTable> ramp(std::initializer_list<std::array<int, 3>> colours, double lo, double hi,
                                     bool log) {
    vtkNew<vtkColorTransferFunction> ctf;
    ctf->SetColorSpaceToLab();
    const int n = int(colours.size());
    int i = 0;
    for (const auto& c : colours)
        ctf->AddRGBPoint(lo + (hi - lo) * i++ / (n - 1), c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    auto lut = vtkSmartPointer<vtkLookupTable>::New();
    lut->SetNumberOfTableValues(256);
    lut->SetScale(log ? VTK_SCALE_LOG10 : VTK_SCALE_LINEAR);
    lut->SetRange(lo, hi);
    lut->Build();
    for (int k = 0; k < 256; ++k) {
        double rgb[3];
        ctf->GetColor(lo + (hi - lo) * k / 255.0, rgb);
        lut->SetTableValue(k, rgb[0], rgb[1], rgb[2], 1.0);
    }
    return lut;
}

vtkSmartPointer<vtkLookupTable> categories(const std::vector<int>& ids, const std::map<int, std::string>& names,
                                           const std::map<int, std::array<unsigned char, 3>>& fixed) {
    auto lut = vtkSmartPointer<vtkLookupTable>::New();
    lut->IndexedLookupOn();
    lut->SetNumberOfTableValues(vtkIdType(std::max<std::size_t>(ids.size(), 1)));
    for (std::size_t i = 0; i < ids.size(); ++i) {
        const auto it = fixed.find(ids[i]);
        const unsigned char* c = it != fixed.end() ? it->second.data() : categorical_colours[i % 16];
        lut->SetTableValue(vtkIdType(i), c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, 1.0);
        const auto n = names.find(ids[i]);
        lut->SetAnnotation(vtkVariant(ids[i]), n != names.end() ? n->second : std::to_string(ids[i]));
    }
    return lut;
}

const std::map<int, std::string> boundary_names{{0, "none"}, {1, "convergent"}, {2, "divergent"}, {3, "transform"}};
const std::map<int, std::array<unsigned char, 3>> boundary_colours{
    {0, {200, 200, 200}}, {1, {215, 48, 39}}, {2, {69, 117, 180}}, {3, {26, 152, 80}}};

/// The colour map for a layer, by its name and values.
vtkSmartPointer<vtkLookupTable> lut_for(const std::string& name, const float* v, std::size_t n, std::string* title) {
    const auto [lo, hi] = value_range(v, n);
    const LayerStyle style = style_of(name, lo, hi);
    *title = name + " (" + style.unit + ")";
    if (style.kind == LayerStyle::categorical) {
        // Ids are small whole numbers: mark them in a table over lo..hi (a set
        // insert per texel cost 50-90 ms at 1025²); a wide range falls back to a set.
        const long first = std::lround(lo), last = std::lround(hi);
        std::vector<int> ids;
        if (last - first < (1 << 20)) {
            std::vector<char> seen(std::size_t(last - first + 1), 0);
            for (std::size_t i = 0; i < n; ++i) seen[std::size_t(std::lround(v[i]) - first)] = 1;
            for (std::size_t k = 0; k < seen.size(); ++k)
                if (seen[k]) ids.push_back(int(first + long(k)));
        } else {
            std::set<int> s;
            for (std::size_t i = 0; i < n; ++i) s.insert(int(std::lround(v[i])));
            ids.assign(s.begin(), s.end());
        }
        return name == "boundary" ? categories(ids, boundary_names, boundary_colours) : categories(ids);
    }
    // Heavy tails (a few fast cells of flow, a few deep gullies) would wash
    // the map out: the range ends at the 98th percentile of magnitudes.
    const double top = std::max(double(kth_magnitude(v, n, std::min(n - 1, std::size_t(double(n) * 0.98)))), 1e-9);
    if (style.kind == LayerStyle::diverging)  // blue below zero, white at zero, red above (cool to warm)
        return ramp({{59, 76, 192}, {221, 221, 221}, {180, 4, 38}}, -top, top);
    if (name == "height")  // hypsometric: lowlands green to rock brown to snow
        return ramp({{38, 115, 77}, {140, 180, 100}, {210, 190, 130}, {140, 100, 70}, {245, 245, 245}}, lo, hi);
    if (name == "water") return ramp({{247, 251, 255}, {107, 174, 214}, {8, 48, 107}}, std::max(lo, 0.f), top);
    if (name == "sediment") return ramp({{255, 247, 188}, {254, 153, 41}, {102, 37, 6}}, std::max(lo, 0.f), top);
    // Values that span three or more orders of magnitude (drainage area: from one cell to the whole map) would
    // be one colour on a linear map: a log scale over the whole range, where the largest values (the rivers)
    // are the point.
    if (lo > 0 && double(hi) / double(lo) >= 1e3) {
        *title = name + " (" + style.unit + ", log scale)";
        return ramp({{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}, lo, hi, true);
    }
    // viridis, sampled
    return ramp({{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}, lo,
                lo >= 0 ? std::max(top, double(lo) + 1e-9) : double(hi));
}

vtkSmartPointer<vtkTextActor> text_actor(int size, double r, double g, double b) {
    auto t = vtkSmartPointer<vtkTextActor>::New();
    vtkTextProperty* p = t->GetTextProperty();
    p->SetFontFamilyToCourier();
    p->SetFontSize(size);
    p->SetColor(r, g, b);
    p->SetBackgroundColor(0.05, 0.05, 0.08);
    p->SetBackgroundOpacity(0.75);
    p->SetFrame(false);
    return t;
}

}  // namespace orogen::view
