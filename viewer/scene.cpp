// scene.cpp — the VTK scene of orogen-view (see scene.hpp).
#include "scene.hpp"

#include <orogen/mesh/terrain_mesh.hpp>  // splat colours and mesh layout: one definition, shared with the exporters

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkColorTransferFunction.h>
#include <vtkCoordinate.h>
#include <vtkGLTFImporter.h>
#include <vtkImageData.h>
#include <vtkLight.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPointGaussianMapper.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderStepsPass.h>
#include <vtkTranslucentPass.h>
#include <vtkRenderer.h>
#include <vtkRendererCollection.h>
#include <vtkActorCollection.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTexture.h>
#include <vtkTypeInt32Array.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVariant.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <list>
#include <map>
#include <set>
#include <sstream>

namespace orogen::view {

namespace {

constexpr double pi = 3.14159265358979323846;

/// The longest side of the mesh shown by default; bigger terrains keep every
/// k-th sample. The texture keeps every sample (up to `max_texture`) and
/// carries the shading too (a hillshade baked from the full-resolution
/// normals), so only silhouettes are coarser. llvmpipe's cost is per
/// triangle: 257² keeps a frame at 1280×800 near 100 ms of CPU.
constexpr int display_samples = 257;
constexpr int max_texture = 8192;

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

/// A colour map with a control point at each of `colours` (RGB 0..255) spread over lo..hi, evenly in the
/// value or, with `log`, in its logarithm (lo > 0).
vtkSmartPointer<vtkLookupTable> ramp(std::initializer_list<std::array<int, 3>> colours, double lo, double hi,
                                     bool log = false) {
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

vtkSmartPointer<vtkLookupTable> categories(const std::vector<int>& ids, const std::map<int, std::string>& names = {},
                                           const std::map<int, std::array<unsigned char, 3>>& fixed = {}) {
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

}  // namespace

struct Scene::Impl {
    vtkRenderWindow* window;
    vtkNew<vtkRenderer> renderer;
    Content content;

    // terrain
    vtkNew<vtkActor> terrain;
    vtkNew<vtkPolyDataMapper> terrain_mapper;
    vtkNew<vtkTexture> texture;
    vtkNew<vtkActor> water;
    vtkNew<vtkPolyDataMapper> water_mapper;
    vtkNew<vtkScalarBarActor> bar;
    int step = 1;  // display decimation
    bool full = false;
    std::size_t layer = 0;
    double top = 0.0;  // highest terrain point, m
    std::vector<float> shade;  // per texel: ambient + diffuse · (normal · light), for `shade_for`
    double shade_for = -1.0;  // the exaggeration `shade` was computed with
    std::vector<std::uint8_t> splat;  // the baked splat texture (RGBA), kept for switching back

    /// How a layer's values become texel colours, worked out once per layer
    /// (range, 98th percentile, categories) and kept for the next switch.
    struct Colouring {
        vtkSmartPointer<vtkLookupTable> lut;  // for the scalar bar
        std::string title;
        bool categorical = false;
        double lo = 0.0, scale = 0.0;  // sequential/diverging: table index = (v − lo) · scale, clamped
        bool log = false;  // ... of log10(v) instead of v (lo is then log10 of the range's start)
        long lowest = 0;  // categorical: the colour of id k is table[k − lowest]
        std::vector<std::array<std::uint8_t, 3>> table;
    };
    std::map<std::size_t, Colouring> colourings;  // by layer index; cleared with the content
    /// Finished textures (colour × hillshade, RGB), most recently shown first:
    /// switching back to a layer uploads one and maps nothing. At most
    /// `texture_cache_bytes` are kept besides the one shown: every layer of a
    /// 1025² terrain (3 MB each), two of a 4097² one (50 MB each), so the
    /// 4097² terrain stays well within 2 GiB.
    struct CachedTexture {
        std::size_t layer;
        vtkSmartPointer<vtkImageData> image;
    };
    std::list<CachedTexture> textures;
    static constexpr std::size_t texture_cache_bytes = std::size_t(128) << 20;

    // time series
    vtkNew<vtkActor> plates, collisions, particles;
    vtkNew<vtkPolyDataMapper> plates_mapper, collisions_mapper;
    vtkNew<vtkPointGaussianMapper> particles_mapper;
    vtkNew<vtkPolyData> empty_lines;
    const Series* plate_series = nullptr;
    const Series* particle_series = nullptr;
    std::vector<double> times;
    std::size_t time_index = 0;
    bool playing = false;
    std::size_t particle_attribute = 0;

    std::vector<vtkSmartPointer<vtkActor>> gltf_actors;

    vtkSmartPointer<vtkTextActor> status = text_actor(14, 0.9, 0.9, 0.9);
    vtkSmartPointer<vtkTextActor> message = text_actor(15, 1.0, 0.45, 0.4);
    vtkSmartPointer<vtkTextActor> help = text_actor(15, 1.0, 1.0, 1.0);

    bool show_water = true, show_particles = true, show_plates = true, edges = false, top_view = false;
    double exaggeration = 1.0;
    CameraAngles angles;

    const Terrain* ground() const { return content.terrains.empty() ? nullptr : &content.terrains.front(); }

    std::vector<std::string> names() const {
        std::vector<std::string> n{"splat"};
        if (ground()) {
            n.push_back("height");
            for (const auto& l : ground()->layers) n.push_back(l.name);
        }
        return n;
    }

    const float* values(std::size_t index) const {
        if (!ground() || index == 0) return nullptr;
        return index == 1 ? ground()->heights->GetPointer(0) : ground()->layers[index - 2].values->GetPointer(0);
    }

    ConstGridView grid() const {
        const Terrain& t = *ground();
        return {t.heights->GetPointer(0), t.width, t.height, t.cell};
    }

    /// New terrain content: forget what was worked out for the last one, build its mesh and texture.
    void load_terrain() {
        shade_for = -1.0;
        splat.clear();
        colourings.clear();
        textures.clear();
        top = ground()->heights->GetValueRange()[1];
        detail = {};
        seen_valid = false;
        build_mesh();
        apply_layer();
    }

    /// The kept sample indices along an axis of n samples: every `step`-th
    /// (the display decimation), but every `detail.step`-th within [lo, hi].
    std::vector<int> kept(int n, int lo, int hi) const {
        std::vector<int> k;
        for (int i : terrain::kept_indices(n, step))
            if (i < lo || i > hi || detail.step == 0) k.push_back(i);
        if (detail.step > 0) {
            for (int i = lo; i < hi; i += detail.step) k.push_back(i);
            k.push_back(hi);
            std::sort(k.begin(), k.end());
            k.erase(std::unique(k.begin(), k.end()), k.end());
        }
        return k;
    }

    /// The terrain's mesh: the decimated grid, with the rows and columns of
    /// the detail region (if any) at its finer step. Rows and columns run
    /// through the whole grid, so there are no cracks where the detail ends.
    void build_mesh() {
        const Terrain& t = *ground();
        step = full ? 1 : std::max(1, int(std::ceil(double(std::max(t.width, t.height) - 1) / (display_samples - 1))));
        if (full) detail = {};
        terrain::TerrainMesh mesh = terrain::plan_mesh(grid(), step, 1, 1.0);
        if (detail.step > 0) {
            mesh.columns = kept(t.width, detail.x0, detail.x1);
            mesh.rows = kept(t.height, detail.y0, detail.y1);
            mesh.chunks = {{0, int(mesh.columns.size()) - 1, 0, int(mesh.rows.size()) - 1}};
        }
        terrain_mapper->SetInputData(polydata(mesh));
        terrain_mapper->ScalarVisibilityOff();
        // While the camera moves: at most 129 samples a side (a quarter of the
        // triangles, about 25 ms less a 1280×800 frame in llvmpipe); the still
        // frame after the drag is the full mesh again. Not when refined: the
        // refined view is cheap (its fine rows lie mostly off screen).
        const int moving_step =
            std::max(2 * step, int(std::ceil(double(std::max(t.width, t.height) - 1) / (moving_samples - 1))));
        has_moving_mesh = detail.step == 0 && moving_step < std::max(t.width, t.height) - 1;
        if (has_moving_mesh) moving_mapper->SetInputData(polydata(terrain::plan_mesh(grid(), moving_step, 1, 1.0)));
        moving_mapper->ScalarVisibilityOff();
        terrain->SetMapper(moving && has_moving_mesh ? moving_mapper.Get() : terrain_mapper.Get());
        terrain->SetTexture(texture);
        vtkProperty* p = terrain->GetProperty();
        p->SetLighting(false);  // the shading is in the texture
        terrain->ForceOpaqueOn();  // an RGB texture: nothing to blend, no translucency scan
        p->SetEdgeColor(0.1, 0.1, 0.1);
        build_water(mesh, mesh.chunks.at(0));
    }

    static constexpr int moving_samples = 129;
    vtkNew<vtkPolyDataMapper> moving_mapper;
    bool has_moving_mesh = false, moving = false;

    void set_moving(bool on) {
        moving = on;
        if (ground()) terrain->SetMapper(moving && has_moving_mesh ? moving_mapper.Get() : terrain_mapper.Get());
    }

    /// The mesh's one chunk as VTK polygons with texture coordinates (and normals, for edges).
    static vtkSmartPointer<vtkPolyData> polydata(const terrain::TerrainMesh& mesh) {
        const terrain::MeshChunk& chunk = mesh.chunks.at(0);
        const std::size_t n = chunk.vertex_count(), triangles = chunk.triangle_count();
        vtkNew<vtkFloatArray> xyz, normals, uv;
        xyz->SetNumberOfComponents(3);
        xyz->SetNumberOfTuples(vtkIdType(n));
        terrain::chunk_positions(mesh, chunk, {xyz->GetPointer(0), n * 3});
        normals->SetName("Normals");
        normals->SetNumberOfComponents(3);
        normals->SetNumberOfTuples(vtkIdType(n));
        terrain::chunk_normals(mesh, chunk, {normals->GetPointer(0), n * 3});
        uv->SetName("uv");
        uv->SetNumberOfComponents(2);
        uv->SetNumberOfTuples(vtkIdType(n));
        terrain::chunk_texcoords(mesh, chunk, std::span<float>{uv->GetPointer(0), n * 2});
        vtkNew<vtkTypeInt32Array> offsets, connectivity;
        offsets->SetNumberOfTuples(vtkIdType(triangles + 1));
        for (std::size_t i = 0; i <= triangles; ++i) offsets->SetValue(vtkIdType(i), std::int32_t(3 * i));
        connectivity->SetNumberOfTuples(vtkIdType(triangles * 3));
        terrain::chunk_indices(chunk, {reinterpret_cast<std::uint32_t*>(connectivity->GetPointer(0)), triangles * 3});
        vtkNew<vtkPoints> points;
        points->SetData(xyz);
        vtkNew<vtkCellArray> polys;
        polys->SetData(offsets, connectivity);
        auto poly = vtkSmartPointer<vtkPolyData>::New();
        poly->SetPoints(points);
        poly->SetPolys(polys);
        poly->GetPointData()->SetNormals(normals);
        poly->GetPointData()->SetTCoords(uv);
        return poly;
    }

    /// Where the mesh is finer than the display decimation: samples
    /// [x0, x1] × [y0, y1] every `step`-th; step 0 = nowhere.
    struct Detail {
        int x0 = 0, y0 = 0, x1 = 0, y1 = 0, step = 0;
        bool operator==(const Detail&) const = default;
    };
    Detail detail;
    bool refine_on_zoom = true;
    /// What the last look saw (camera, window size, exaggeration): the same
    /// view needs no new look. (Not the camera's MTime: every render's
    /// clipping-range update bumps it.) Cleared to look again.
    std::array<double, 15> seen_view{};
    bool seen_valid = false;

    /// Refinement on zoom. Projects the decimated grid's samples with the
    /// current camera; where its cells on screen (with a margin) lie is the
    /// region in view. When those cells are over `refine_pixels` wide, the
    /// region gets a finer step: the finest that keeps it within
    /// `display_samples` a side (so the mesh stays under (2·257)² = 264 k
    /// vertices and 527 k triangles: 17 MB of VTK arrays, about twice that
    /// with the driver's buffers) and no finer than 2 pixels a sample.
    /// true if the mesh changed.
    bool refine() {
        if (!ground() || full || step == 1 || !terrain->GetVisibility()) return false;
        vtkCamera* cam = renderer->GetActiveCamera();
        const int* size = window->GetSize();
        const double* p = cam->GetPosition();
        const double* f = cam->GetFocalPoint();
        const double* u = cam->GetViewUp();
        const std::array<double, 15> view{p[0],
                                          p[1],
                                          p[2],
                                          f[0],
                                          f[1],
                                          f[2],
                                          u[0],
                                          u[1],
                                          u[2],
                                          cam->GetViewAngle(),
                                          cam->GetParallelScale(),
                                          double(cam->GetParallelProjection()),
                                          double(size[0]),
                                          double(size[1]),
                                          exaggeration};
        if (seen_valid && view == seen_view) return false;
        seen_view = view;
        seen_valid = true;
        const Detail wanted = refine_on_zoom ? detail_in_view(size[0], size[1]) : Detail{};
        if (wanted == detail) return false;
        detail = wanted;
        build_mesh();
        update_status();
        return true;
    }

    static constexpr double refine_pixels = 4.0;

    Detail detail_in_view(int width_px, int height_px) const {
        const Terrain& t = *ground();
        const std::vector<int> cols = terrain::kept_indices(t.width, step),
                               rows = terrain::kept_indices(t.height, step);
        const std::size_t nc = cols.size(), nr = rows.size();
        // world (X east, Y up × exaggeration, Z south) → clip coordinates
        vtkMatrix4x4* m = renderer->GetActiveCamera()->GetCompositeProjectionTransformMatrix(
            double(width_px) / std::max(height_px, 1), -1, 1);
        struct Clip {
            double x, y, w;
        };
        std::vector<Clip> clip(nc * nr);
        const float* h = t.heights->GetPointer(0);
        parallel_for(0, std::int64_t(nr), 16, [&](std::int64_t j0, std::int64_t j1) {
            for (std::int64_t j = j0; j < j1; ++j)
                for (std::size_t i = 0; i < nc; ++i) {
                    const double p[3] = {cols[i] * t.cell,
                                         h[std::size_t(rows[std::size_t(j)]) * t.width + cols[i]] * exaggeration,
                                         rows[std::size_t(j)] * t.cell};
                    double q[3];
                    for (int r = 0; r < 3; ++r)
                        q[r] = m->GetElement(r == 2 ? 3 : r, 0) * p[0] + m->GetElement(r == 2 ? 3 : r, 1) * p[1] +
                            m->GetElement(r == 2 ? 3 : r, 2) * p[2] + m->GetElement(r == 2 ? 3 : r, 3);
                    clip[std::size_t(j) * nc + i] = {q[0], q[1], q[2]};
                }
        });
        // Cells in view: not wholly outside one side of the view (the window
        // grown by a tenth each side, so a small pan stays refined), tested on
        // the clip coordinates so corners behind the camera count right. A
        // cell reaching behind the camera that is in view counts as huge.
        constexpr double margin = 1.2;  // in normalised device coordinates the window is [-1, 1]
        int ci0 = int(nc), ci1 = -1, rj0 = int(nr), rj1 = -1;
        double widest = 0.0;  // pixels, the largest cell side on screen among cells in view
        for (std::size_t j = 0; j + 1 < nr; ++j)
            for (std::size_t i = 0; i + 1 < nc; ++i) {
                const Clip* c[4] = {&clip[j * nc + i], &clip[j * nc + i + 1], &clip[(j + 1) * nc + i],
                                    &clip[(j + 1) * nc + i + 1]};
                int out[5] = {0, 0, 0, 0, 0};  // corners beyond: right, left, top, bottom, behind
                for (const Clip* k : c) {
                    out[0] += k->x > margin * k->w;
                    out[1] += k->x < -margin * k->w;
                    out[2] += k->y > margin * k->w;
                    out[3] += k->y < -margin * k->w;
                    out[4] += k->w <= 1e-9;
                }
                if (std::any_of(out, out + 5, [](int n) { return n == 4; })) continue;
                ci0 = std::min(ci0, int(i)), ci1 = std::max(ci1, int(i)), rj0 = std::min(rj0, int(j)),
                rj1 = std::max(rj1, int(j));
                if (out[4] > 0) {
                    widest = 1e300;
                    continue;
                }
                auto side = [&](int a, int b) {
                    return std::hypot((c[a]->x / c[a]->w - c[b]->x / c[b]->w) * width_px / 2,
                                      (c[a]->y / c[a]->w - c[b]->y / c[b]->w) * height_px / 2);
                };
                widest = std::max({widest, side(0, 1), side(0, 2), side(1, 3), side(2, 3)});
            }
        if (ci1 < 0 || widest <= refine_pixels) return {};
        Detail d{cols[std::size_t(ci0)], rows[std::size_t(rj0)], cols[std::size_t(ci1) + 1], rows[std::size_t(rj1) + 1],
                 0};
        const int span = std::max(d.x1 - d.x0, d.y1 - d.y0);
        const int budget = (span + display_samples - 2) / (display_samples - 1);  // fits 257 a side
        const int sharp = widest > 1e299 ? 1 : int(std::ceil(2.0 * step / widest));  // ≥ 2 px a sample
        d.step = std::max({1, budget, sharp});
        if (2 * d.step > step) return {};  // not worth it: less than twice as fine
        return d;
    }

    /// Water: triangles whose three corners hold more than 20 cm of water,
    /// raised to the water's surface (height + depth).
    void build_water(const terrain::TerrainMesh& mesh, const terrain::MeshChunk& chunk) {
        const float* w = ground()->layer("water");
        water->SetVisibility(false);
        if (!w) return;
        const int width = ground()->width;
        const int cols = chunk.vertex_columns(), rows = chunk.vertex_rows();
        auto depth = [&](int i, int j) { return w[std::size_t(mesh.rows[j]) * width + mesh.columns[i]]; };
        vtkNew<vtkPoints> points;
        points->SetDataTypeToFloat();
        points->SetNumberOfPoints(vtkIdType(cols) * rows);
        for (int j = 0; j < rows; ++j)
            for (int i = 0; i < cols; ++i) {
                const auto p = terrain::position(mesh, mesh.columns[i], mesh.rows[j]);
                points->SetPoint(vtkIdType(j) * cols + i, p[0], p[1] + depth(i, j), p[2]);
            }
        vtkNew<vtkCellArray> polys;
        constexpr float wet = 0.2f;  // m: the pipe model leaves centimetres in every hollow; show lakes and rivers
        for (int j = 0; j + 1 < rows; ++j)
            for (int i = 0; i + 1 < cols; ++i) {
                const vtkIdType a = vtkIdType(j) * cols + i, b = a + 1, c = a + cols, d = c + 1;
                const bool wa = depth(i, j) > wet, wb = depth(i + 1, j) > wet, wc = depth(i, j + 1) > wet,
                           wd = depth(i + 1, j + 1) > wet;
                if (wa && wc && wb) {
                    const vtkIdType tri[3] = {a, c, b};
                    polys->InsertNextCell(3, tri);
                }
                if (wb && wc && wd) {
                    const vtkIdType tri[3] = {b, c, d};
                    polys->InsertNextCell(3, tri);
                }
            }
        if (polys->GetNumberOfCells() == 0) return;
        vtkNew<vtkPolyData> poly;
        poly->SetPoints(points);
        poly->SetPolys(polys);
        water_mapper->SetInputData(poly);
        water_mapper->ScalarVisibilityOff();
        // Shallow water lies within centimetres of the ground: draw it in front.
        water_mapper->SetRelativeCoincidentTopologyPolygonOffsetParameters(-2, -2);
        water_mapper->SetResolveCoincidentTopologyToPolygonOffset();
        water->SetMapper(water_mapper);
        water->GetProperty()->SetColor(0.16, 0.38, 0.68);
        water->GetProperty()->SetOpacity(0.75);
        water->GetProperty()->SetSpecular(0.3);
        water->SetVisibility(show_water);
    }

    /// The texture's size: every sample, up to `max_texture` a side.
    std::pair<int, int> texture_size() const {
        return {std::min(ground()->width, max_texture), std::min(ground()->height, max_texture)};
    }

    /// The terrain's texture: splat colours (the exporters' own bake) or a
    /// layer through its colour map, times the hillshade; from the cache when
    /// this layer was shown before with the same exaggeration.
    void apply_layer() {
        if (shade_for != exaggeration) textures.clear();  // the hillshade they carry is stale
        auto hit =
            std::find_if(textures.begin(), textures.end(), [&](const CachedTexture& c) { return c.layer == layer; });
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

    static std::size_t texture_bytes(const CachedTexture& c) { return std::size_t(c.image->GetNumberOfPoints()) * 3; }

    /// Make the texture of one layer not yet kept, if the cache has room for
    /// it without dropping another: what the viewer does while idle, so the
    /// first switch to a layer finds its texture made. false if none was made.
    bool prefetch() {
        if (!ground()) return false;
        if (shade_for != exaggeration) textures.clear();
        std::size_t bytes = 0;
        for (const auto& c : textures) bytes += texture_bytes(c);
        const auto [tw, th] = texture_size();
        if (bytes + std::size_t(tw) * th * 3 > texture_cache_bytes) return false;
        const std::size_t count = names().size();
        for (std::size_t k = 1; k <= count; ++k) {
            const std::size_t index = (layer + k) % count;  // the next layers first: where `l` goes
            if (std::none_of(textures.begin(), textures.end(),
                             [&](const CachedTexture& c) { return c.layer == index; })) {
                textures.push_back({index, colour_texture(index)});
                return true;
            }
        }
        return false;
    }

    const Colouring& colouring(std::size_t index) {
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
                    std::uint8_t(rgb[0] * 255 + 0.5), std::uint8_t(rgb[1] * 255 + 0.5),
                    std::uint8_t(rgb[2] * 255 + 0.5)};
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

    /// One layer's finished texture: colour × hillshade, RGB (no alpha: VTK
    /// would scan an RGBA texture for translucency on every upload).
    vtkSmartPointer<vtkImageData> colour_texture(std::size_t index) {
        const Terrain& t = *ground();
        const auto [tw, th] = texture_size();
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
            if (splat.size() != std::size_t(tw) * th * 4) splat = terrain::bake_splat_texture(grid(), tw, th);
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

    /// The hillshade light: from the north-west (−X, −Z), 45° above the horizon (unit vector).
    static constexpr double light[3] = {-0.5, 0.70710678, -0.5};

    /// The hillshade of the exaggerated terrain at each texel's nearest sample:
    /// 0.3 ambient + 0.99 · (n · light), so a flat tile shows its colour at
    /// full strength (0.3 + 0.99 · 0.707 ≈ 1). Textures multiply by it.
    void update_shade(int tw, int th) {
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
                    const auto n = terrain::surface_normal(g, x, y, e);
                    const double lit = n[0] * light[0] + n[1] * light[1] + n[2] * light[2];
                    shade[std::size_t(j) * tw + i] = float(0.3 + 0.99 * std::max(lit, 0.0));
                }
            }
        });
        shade_for = exaggeration;
    }

    /// The particle attribute names of the particle series' first frame.
    std::vector<std::string> particle_attributes() const {
        std::vector<std::string> n;
        if (!particle_series) return n;
        for (const auto& f : particle_series->frames)
            if (f.particles) {
                vtkPointData* pd = f.particles->GetPointData();
                for (int i = 0; i < pd->GetNumberOfArrays(); ++i)
                    if (pd->GetArrayName(i)) n.push_back(pd->GetArrayName(i));
                break;
            }
        return n;
    }

    template <typename Part>
    const Frame* frame_at(const Series* s, Part part) const {
        if (!s || times.empty()) return nullptr;
        const double t = times[time_index];
        const Frame* best = nullptr;
        for (const auto& f : s->frames)
            if ((f.*part) && (f.time <= t || !best)) best = &f;
        return best;
    }

    void apply_time() {
        const double lift = (top + 0.01 * extent()) * exaggeration;  // plates drawn just above the highest peak
        if (const Frame* f = frame_at(plate_series, &Frame::plates)) {
            plates_mapper->SetInputData(f->plates);
            plates->SetPosition(0, lift, 0);
        }
        plates->SetVisibility(show_plates && frame_at(plate_series, &Frame::plates));
        if (const Frame* f = frame_at(plate_series, &Frame::collisions)) {
            // Collisions since the previous snapshot: only those of this instant.
            collisions_mapper->SetInputData(f->time == times[time_index] ? f->collisions.Get() : empty_lines.Get());
            collisions->SetPosition(0, lift * 1.001 + 0.001 * extent(), 0);
        }
        collisions->SetVisibility(show_plates && frame_at(plate_series, &Frame::collisions));
        if (const Frame* f = frame_at(particle_series, &Frame::particles)) {
            particles_mapper->SetInputData(f->particles);
            particles_mapper->SetScaleFactor(0.006 * extent());  // sphere radius, m
            const auto attrs = particle_attributes();
            if (!attrs.empty()) {
                const std::string& name = attrs[particle_attribute % attrs.size()];
                vtkDataArray* a = f->particles->GetPointData()->GetArray(name.c_str());
                particles_mapper->SetScalarModeToUsePointFieldData();
                particles_mapper->SelectColorArray(name.c_str());
                particles_mapper->ScalarVisibilityOn();
                auto lut = ramp({{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}, 0, 1);
                if (a) {
                    double r[2];
                    a->GetRange(r, a->GetNumberOfComponents() > 1 ? -1 : 0);  // -1: vector magnitude
                    lut->SetRange(r[0], std::max(r[1], r[0] + 1e-9));
                    lut->SetVectorModeToMagnitude();
                }
                particles_mapper->SetLookupTable(lut);
                particles_mapper->UseLookupTableScalarRangeOn();
            }
        }
        particles->SetVisibility(show_particles && frame_at(particle_series, &Frame::particles));
    }

    double extent() const {
        if (const Terrain* t = ground()) return std::max(t->width - 1, t->height - 1) * t->cell;
        double b[6];
        renderer->ComputeVisiblePropBounds(b);
        return b[0] <= b[1] ? std::max({b[1] - b[0], b[3] - b[2], b[5] - b[4], 1.0}) : 1.0;
    }

    void apply_exaggeration() {
        for (vtkActor* a : {terrain.Get(), water.Get(), particles.Get()}) a->SetScale(1, exaggeration, 1);
        for (auto& a : gltf_actors) a->SetScale(1, exaggeration, 1);
        apply_time();
    }

    void update_status() {
        std::ostringstream s;
        if (const Terrain* t = ground()) {
            s << t->file.filename().string() << "  " << t->width << "x" << t->height << "  layer: " << names()[layer];
            if (step > 1) {
                s << "  (shown 1:" << step;
                if (detail.step > 0) s << ", 1:" << detail.step << " in view";
                s << ", f: full resolution)";
            }
        } else if (!content.gltf.empty()) {
            s << content.gltf.front().filename().string();
        }
        s << "  exaggeration " << exaggeration;
        if (!times.empty())
            s << "  t = " << times[time_index] << " (" << time_index + 1 << "/" << times.size() << ")"
              << (playing ? " playing" : "");
        s << "   h: help";
        status->SetInput(s.str().c_str());
    }

    /// The band at the window's bottom that the colour scale and the status line take, pixels: the bar's
    /// offset, its height (11 % of the window, at most 90 pixels) and a margin.
    static double legend_band(double window_height) { return bar_offset + std::min(0.11 * window_height, 90.0) + 8; }
    static constexpr double bar_offset = 48;

    void camera_from_angles() {
        vtkCamera* cam = renderer->GetActiveCamera();
        double b[6];
        renderer->ComputeVisiblePropBounds(b);
        if (b[0] > b[1]) return;
        if (const Terrain* t = ground(); t && terrain->GetVisibility()) {
            // The full-resolution height range, not the decimated mesh's: the
            // same camera whatever the mesh's level of detail (--full, refined).
            const double* h = t->heights->GetRange();
            b[2] = std::min(b[2], h[0] * exaggeration);
            b[3] = std::max(b[3], h[1] * exaggeration);
        }
        renderer->ComputeAspect();  // before the first render too: the fit depends on the window's shape
        const double centre[3] = {(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2};
        const double el = (top_view ? 90.0 : std::clamp(angles.elevation, -89.0, 90.0)) * pi / 180,
                     az = angles.azimuth * pi / 180;
        const double dir[3] = {std::cos(el) * std::sin(az), std::sin(el), -std::cos(el) * std::cos(az)};
        cam->SetFocalPoint(centre);
        cam->SetPosition(centre[0] + dir[0], centre[1] + dir[1], centre[2] + dir[2]);
        if (top_view) cam->SetViewUp(0, 0, -1);  // a map: north up
        else if (el > 89.9 * pi / 180)
            cam->SetViewUp(-std::sin(az), 0, std::cos(az));  // looking down from a bearing: that side at the bottom
        else cam->SetViewUp(0, 1, 0);
        cam->SetParallelProjection(top_view);
        renderer->ResetCamera(b);
        if (top_view) {
            cam->SetParallelScale(cam->GetParallelScale() /
                                  1.35);  // ResetCamera fits the bounding sphere: fit the square
            // A map keeps clear of the colour scale and the status line at the window's bottom: it is fitted
            // into the window above them (smaller by that band, and moved up by half of it).
            const double window_height = renderer->GetSize()[1];
            const double band = legend_band(window_height);
            if (window_height > 2 * band) {
                const double scale = cam->GetParallelScale() * window_height / (window_height - band);
                const double shift = band / 2 * (2 * scale / window_height);  // pixels × metres per pixel
                cam->SetParallelScale(scale);
                const double* f = cam->GetFocalPoint();
                const double* p = cam->GetPosition();
                // Screen down is +Z (north up): moving the camera that way moves the map up.
                cam->SetFocalPoint(f[0], f[1], f[2] + shift);
                cam->SetPosition(p[0], p[1], p[2] + shift);
            }
        } else if (angles.distance > 0) {
            // vtkCamera::SetDistance would move the focal point; the camera moves instead.
            const double* f = cam->GetFocalPoint();
            const double* d = cam->GetDirectionOfProjection();
            cam->SetPosition(f[0] - d[0] * angles.distance, f[1] - d[1] * angles.distance,
                             f[2] - d[2] * angles.distance);
        } else cam->Dolly(1.3);
        renderer->ResetCameraClippingRange();
    }
};

Scene::Scene(vtkRenderWindow* window) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    m.window = window;
    window->AddRenderer(m.renderer);
    m.renderer->SetBackground(0.55, 0.65, 0.78);
    m.renderer->SetBackground2(0.16, 0.2, 0.28);
    m.renderer->GradientBackgroundOn();
    // Translucent surfaces (water, plates) with plain alpha blending. Without
    // a pass of its own, VTK 9.1 draws them with order-independent
    // transparency: float render targets and a full-window composite that cost
    // llvmpipe 35 ms of CPU a 1280×800 frame, a third of it. One translucent
    // layer over opaque ground blends the same either way (pixel for pixel in
    // the screenshots compared).
    vtkNew<vtkRenderStepsPass> steps;
    vtkNew<vtkTranslucentPass> blend;
    steps->SetTranslucentPass(blend);
    m.renderer->SetPass(steps);
    // The hillshade light: from the north-west (−X, −Z), 45° above the horizon.
    m.renderer->AutomaticLightCreationOff();
    vtkNew<vtkLight> sun;
    sun->SetLightTypeToSceneLight();
    sun->SetPositional(false);
    sun->SetPosition(-0.5, std::sqrt(0.5), -0.5);
    sun->SetFocalPoint(0, 0, 0);
    sun->SetIntensity(1.0);
    m.renderer->AddLight(sun);
    for (vtkActor* a : {m.terrain.Get(), m.water.Get(), m.plates.Get(), m.collisions.Get(), m.particles.Get()}) {
        a->SetVisibility(false);
        m.renderer->AddActor(a);
    }
    m.plates->SetMapper(m.plates_mapper);
    m.plates->GetProperty()->SetOpacity(0.3);
    m.plates->GetProperty()->EdgeVisibilityOn();
    m.plates->GetProperty()->SetLineWidth(2);
    m.plates->GetProperty()->SetLighting(false);
    m.collisions->SetMapper(m.collisions_mapper);
    m.collisions->GetProperty()->SetLineWidth(4);
    m.collisions->GetProperty()->SetLighting(false);
    m.collisions_mapper->SetScalarModeToUseCellFieldData();
    m.collisions_mapper->SelectColorArray("kind");
    m.collisions_mapper->SetLookupTable(categories({1, 2, 3}, boundary_names, boundary_colours));
    m.collisions_mapper->UseLookupTableScalarRangeOn();
    m.particles->SetMapper(m.particles_mapper);
    m.particles_mapper->EmissiveOff();
    // Shaded spheres instead of Gaussian blobs (VTK's own example shader for this mapper).
    m.particles_mapper->SetSplatShaderCode(
        "//VTK::Color::Impl\n"
        "float dist = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);\n"
        "if (dist > 1.0) { discard; } else { float scale = 1.0 - dist; ambientColor *= scale; diffuseColor *= scale; "
        "}\n");
    m.bar->SetNumberOfLabels(5);
    m.bar->SetOrientationToHorizontal();  // bottom right, clear of long titles
    // 48 pixels above the window's bottom whatever its size: the status line
    // (about 24 pixels) stays clear of the bar and of the category names a
    // categorical bar writes below its swatches.
    vtkNew<vtkCoordinate> bar_anchor;
    bar_anchor->SetCoordinateSystemToNormalizedViewport();
    bar_anchor->SetValue(0.6, 0.0);
    m.bar->GetPositionCoordinate()->SetCoordinateSystemToDisplay();
    m.bar->GetPositionCoordinate()->SetReferenceCoordinate(bar_anchor);
    m.bar->GetPositionCoordinate()->SetValue(0, Impl::bar_offset);
    m.bar->SetWidth(0.38);
    m.bar->SetHeight(0.11);
    m.bar->SetMaximumHeightInPixels(90);
    m.bar->SetLabelFormat("%-#6.3g");
    m.bar->SetVisibility(false);
    m.renderer->AddActor2D(m.bar);
    m.status->SetDisplayPosition(8, 6);
    m.message->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    m.message->GetTextProperty()->SetVerticalJustificationToTop();
    m.message->SetPosition(0.01, 0.98);
    m.help->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    m.help->GetTextProperty()->SetJustificationToLeft();  // a table: the columns line up
    m.help->GetTextProperty()->SetVerticalJustificationToCentered();
    m.help->SetPosition(0.22, 0.5);
    m.help->SetInput(help_text().c_str());
    m.help->SetVisibility(false);
    m.message->SetVisibility(false);
    for (vtkTextActor* t : {m.status.Get(), m.message.Get(), m.help.Get()}) m.renderer->AddActor2D(t);
}

Scene::~Scene() = default;

std::string Scene::help_text() {
    return "orogen-view keys\n"
           "\n"
           "  l / L      next / previous layer colouring\n"
           "  w          water on/off\n"
           "  p          particles on/off\n"
           "  a          colour particles by the next attribute\n"
           "  m          plates and collisions on/off\n"
           "  e          mesh edges on/off\n"
           "  v          top-down (hillshade map) / perspective\n"
           "  r          reset the camera\n"
           "  + / -      vertical exaggeration up / down (x1.25)\n"
           "  space      play / pause the time series\n"
           "  . / ,      next / previous time step (or Right / Left)\n"
           "  f          full resolution on/off (big terrains)\n"
           "  s          screenshot: orogen-view-N.png\n"
           "  h          this help\n"
           "  q          quit\n"
           "\n"
           "  mouse: left rotate, middle/shift-left pan, wheel/right zoom";
}

void Scene::show(Content content, bool keep_camera) {
    Impl& m = *impl_;
    const std::string previous_layer = m.names()[std::min(m.layer, m.names().size() - 1)];
    for (auto& a : m.gltf_actors) m.renderer->RemoveActor(a);
    m.gltf_actors.clear();
    m.content = std::move(content);
    m.terrain->SetVisibility(false);
    m.water->SetVisibility(false);
    m.top = 0.0;
    if (m.ground()) {
        const auto n = m.names();
        const auto it = std::find(n.begin(), n.end(), previous_layer);
        m.layer = it == n.end() ? 0 : std::size_t(it - n.begin());
        m.load_terrain();
        m.terrain->SetVisibility(true);
    }
    for (const auto& file : m.content.gltf) {
        // The importer adds its actors (and may add lights) to our renderer: keep the actors, drop the rest.
        std::set<vtkActor*> before;
        vtkActorCollection* actors = m.renderer->GetActors();
        actors->InitTraversal();
        while (vtkActor* a = actors->GetNextActor()) before.insert(a);
        vtkNew<vtkGLTFImporter> importer;
        importer->SetFileName(file.c_str());
        importer->SetRenderWindow(m.window);
        importer->Update();
        actors = m.renderer->GetActors();  // rebuilt from the renderer's props on each call
        actors->InitTraversal();
        while (vtkActor* a = actors->GetNextActor())
            if (!before.count(a)) {
                m.gltf_actors.emplace_back(a);
                double b[6];
                a->GetBounds(b);
                m.top = std::max(m.top, b[3]);
            }
        if (m.gltf_actors.empty())
            throw BadInput("cannot read '" + file.string() + "': not a valid glTF file, or it holds no mesh");
    }
    m.plate_series = m.particle_series = nullptr;
    std::set<double> times;
    int plate_score = 0;  // the series with plates and collisions, else plates, else collisions (a folder
        // holding export:paraview-state's split series besides export:vtk-plates' own)
    for (const auto& s : m.content.series) {
        bool plates = false, collisions = false;
        for (const auto& f : s.frames) {
            times.insert(f.time);
            plates = plates || f.plates;
            collisions = collisions || f.collisions;
            if (f.particles && !m.particle_series) m.particle_series = &s;
        }
        const int score = 2 * plates + collisions;
        if (score > plate_score) m.plate_series = &s, plate_score = score;
    }
    if (m.plate_series) {  // one colour per plate id, the same at every time
        std::set<int> ids;
        for (const auto& f : m.plate_series->frames)
            if (f.plates)
                if (vtkDataArray* a = f.plates->GetCellData()->GetArray("plate"))
                    for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i) ids.insert(int(a->GetTuple1(i)));
        m.plates_mapper->SetLookupTable(categories({ids.begin(), ids.end()}));
        m.plates_mapper->SetScalarModeToUseCellFieldData();
        m.plates_mapper->SelectColorArray("plate");
        m.plates_mapper->UseLookupTableScalarRangeOn();
    }
    const double previous_time = m.times.empty() ? 0.0 : m.times[m.time_index];
    m.times.assign(times.begin(), times.end());
    m.time_index = 0;
    if (keep_camera && !m.times.empty()) set_time(previous_time);
    if (!m.particle_series) m.particles->SetVisibility(false);
    m.apply_exaggeration();
    m.terrain->GetProperty()->SetEdgeVisibility(m.edges);
    m.update_status();
    if (!keep_camera) m.camera_from_angles();
    m.renderer->ResetCameraClippingRange();
}

bool Scene::empty() const { return !impl_->ground() && impl_->content.series.empty() && impl_->gltf_actors.empty(); }

std::vector<std::string> Scene::layer_names() const { return impl_->names(); }
std::string Scene::layer() const { return impl_->names()[impl_->layer]; }

void Scene::cycle_layer(int step) {
    Impl& m = *impl_;
    if (!m.ground()) return;
    const int n = int(m.names().size());
    m.layer = std::size_t(((int(m.layer) + step) % n + n) % n);
    m.apply_layer();
    m.update_status();
}

bool Scene::set_layer(const std::string& name) {
    Impl& m = *impl_;
    const auto n = m.names();
    const auto it = std::find(n.begin(), n.end(), name);
    if (it == n.end() || !m.ground()) return false;
    m.layer = std::size_t(it - n.begin());
    m.apply_layer();
    m.update_status();
    return true;
}

void Scene::toggle_water() {
    impl_->show_water = !impl_->show_water;
    impl_->water->SetVisibility(impl_->show_water && impl_->water_mapper->GetInput() && impl_->ground() &&
                                impl_->ground()->layer("water"));
}
void Scene::toggle_particles() {
    impl_->show_particles = !impl_->show_particles;
    impl_->apply_time();
}
void Scene::toggle_plates() {
    impl_->show_plates = !impl_->show_plates;
    impl_->apply_time();
}
void Scene::toggle_edges() {
    impl_->edges = !impl_->edges;
    impl_->terrain->GetProperty()->SetEdgeVisibility(impl_->edges);
}
void Scene::toggle_help() { impl_->help->SetVisibility(!impl_->help->GetVisibility()); }
void Scene::cycle_particle_attribute() {
    ++impl_->particle_attribute;
    impl_->apply_time();
}

bool Scene::prefetch() { return impl_->prefetch(); }

void Scene::set_full_resolution(bool full) {
    Impl& m = *impl_;
    if (m.full == full) return;
    m.full = full;
    if (m.ground()) {
        m.build_mesh();
        m.seen_valid = false;
    }
    m.update_status();
}
bool Scene::full_resolution() const { return impl_->full; }

double Scene::exaggeration() const { return impl_->exaggeration; }
void Scene::set_exaggeration(double e) {
    impl_->exaggeration = std::clamp(e, 0.01, 100.0);
    impl_->seen_valid = false;  // the refinement looks again: heights on screen moved
    impl_->apply_exaggeration();
    if (impl_->ground()) impl_->apply_layer();  // the baked shading follows the exaggerated slopes
    impl_->update_status();
    impl_->renderer->ResetCameraClippingRange();
}

void Scene::set_camera(const CameraAngles& angles) {
    impl_->angles = angles;
    impl_->camera_from_angles();
}
void Scene::reset_camera() { impl_->camera_from_angles(); }
void Scene::toggle_top_view() {
    impl_->top_view = !impl_->top_view;
    impl_->camera_from_angles();
}

const std::vector<double>& Scene::times() const { return impl_->times; }
std::size_t Scene::time_index() const { return impl_->time_index; }
void Scene::set_time_index(std::size_t i) {
    Impl& m = *impl_;
    if (m.times.empty()) return;
    m.time_index = std::min(i, m.times.size() - 1);
    m.apply_time();
    m.update_status();
}
void Scene::set_time(double t) {
    const auto& ts = impl_->times;
    std::size_t i = 0;
    while (i + 1 < ts.size() && ts[i + 1] <= t) ++i;
    set_time_index(i);
}
void Scene::set_playing(bool playing) {
    impl_->playing = playing && impl_->times.size() > 1;
    impl_->update_status();
}
bool Scene::playing() const { return impl_->playing; }

void Scene::set_message(const std::string& text, bool error) {
    impl_->message->SetInput(text.c_str());
    if (error) impl_->message->GetTextProperty()->SetColor(1.0, 0.45, 0.4);
    else impl_->message->GetTextProperty()->SetColor(0.9, 0.95, 1.0);
    impl_->message->SetVisibility(!text.empty());
}

std::string Scene::state() const {
    const Impl& m = *impl_;
    vtkCamera* cam = m.renderer->GetActiveCamera();
    std::ostringstream s;
    s << "layer=" << layer() << "\n"
      << "water=" << (m.show_water ? "on" : "off") << "\n"
      << "particles=" << (m.show_particles ? "on" : "off") << "\n"
      << "plates=" << (m.show_plates ? "on" : "off") << "\n"
      << "edges=" << (m.edges ? "on" : "off") << "\n"
      << "help=" << (m.help->GetVisibility() ? "on" : "off") << "\n"
      << "view=" << (m.top_view ? "top" : "perspective") << "\n"
      << "exaggeration=" << m.exaggeration << "\n"
      << "full_resolution=" << (m.full ? "on" : "off") << "\n"
      << "mesh_step=" << m.step << "\n"
      << "moving=" << (m.moving ? "on" : "off") << "\n"
      << "detail=";
    if (m.detail.step > 0)
        s << m.detail.x0 << "," << m.detail.y0 << "," << m.detail.x1 << "," << m.detail.y1 << " step " << m.detail.step;
    else s << "none";
    s << "\n"
      << "time_index=" << m.time_index << "\n"
      << "playing=" << (m.playing ? "on" : "off") << "\n"
      << "particle_attribute=" << m.particle_attribute << "\n";
    const double* p = cam->GetPosition();
    s << "camera=" << p[0] << "," << p[1] << "," << p[2] << "\n";
    // Where the terrain and the colour scale are in the window (pixels, x0,y0,x1,y1 from the bottom left), so
    // that a test can see the two apart.
    s << "legend=" << (m.bar->GetVisibility() ? m.bar->GetTitle() : "none") << "\n";
    if (m.terrain->GetVisibility() && m.ground()) {
        double b[6];
        m.terrain->GetBounds(b);
        double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
        for (int c = 0; c < 8; ++c) {
            m.renderer->SetWorldPoint(b[c & 1], b[2 + ((c >> 1) & 1)], b[4 + ((c >> 2) & 1)], 1.0);
            m.renderer->WorldToDisplay();
            const double* d = m.renderer->GetDisplayPoint();
            for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], d[k]), hi[k] = std::max(hi[k], d[k]);
        }
        s << "map_box=" << std::lround(lo[0]) << "," << std::lround(lo[1]) << "," << std::lround(hi[0]) << ","
          << std::lround(hi[1]) << "\n";
    }
    if (m.bar->GetVisibility()) {
        const int* at = m.bar->GetPositionCoordinate()->GetComputedDisplayValue(m.renderer);
        const int* to = m.bar->GetPosition2Coordinate()->GetComputedDisplayValue(m.renderer);
        const int height = std::min(to[1] - at[1], m.bar->GetMaximumHeightInPixels());
        s << "legend_box=" << at[0] << "," << at[1] << "," << to[0] << "," << at[1] + height << "\n";
    }
    return s.str();
}

void Scene::render() {
    impl_->refine();
    impl_->window->Render();
}

bool Scene::refine() { return impl_->refine(); }

void Scene::set_moving(bool moving) { impl_->set_moving(moving); }

void Scene::set_refine_on_zoom(bool on) {
    impl_->refine_on_zoom = on;
    impl_->seen_valid = false;
}

void Scene::screenshot(const std::string& file) {
    render();
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(impl_->window);
    grab->SetInputBufferTypeToRGBA();
    grab->ReadFrontBufferOff();
    grab->ShouldRerenderOff();  // just rendered
    grab->Update();
    vtkImageData* image = grab->GetOutput();
    int dims[3];
    image->GetDimensions(dims);
    const auto* px = static_cast<const std::uint8_t*>(image->GetScalarPointer());
    // VTK's rows run bottom to top; PNG's top to bottom.
    std::vector<std::uint8_t> rgba(std::size_t(dims[0]) * dims[1] * 4);
    const std::size_t row = std::size_t(dims[0]) * 4;
    for (int y = 0; y < dims[1]; ++y)
        std::copy_n(px + std::size_t(dims[1] - 1 - y) * row, row, rgba.begin() + std::ptrdiff_t(std::size_t(y) * row));
    for (std::size_t i = 3; i < rgba.size(); i += 4) rgba[i] = 255;
    AtomicFile out(file);
    write_rgba_png(out.stream(), dims[0], dims[1], rgba);
    out.commit();
}

}  // namespace orogen::view
