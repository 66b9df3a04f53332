// scene.cpp — the VTK scene of orogen-view (see scene.hpp).
#include "scene.hpp"

#include "terrain_mesh.hpp"  // splat colours and mesh layout: one definition, shared with the exporters

#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/parallel.hpp>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkColorTransferFunction.h>
#include <vtkGLTFImporter.h>
#include <vtkImageData.h>
#include <vtkLight.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPointGaussianMapper.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
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
#include <cmath>
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
    const char* unit = name == "flow" ? "m/s" : name == "hardness" ? "0..1" : "m";
    return {unit, lo < 0 && hi > 0 ? LayerStyle::diverging : LayerStyle::sequential};
}

/// Qualitative colours (ColorBrewer Set1/Set3 family) for ids.
const unsigned char categorical_colours[][3] = {
    {228, 26, 28},  {55, 126, 184}, {77, 175, 74},   {152, 78, 163}, {255, 127, 0},  {255, 255, 51},
    {166, 86, 40},  {247, 129, 191}, {141, 211, 199}, {190, 186, 218}, {128, 177, 211}, {179, 222, 105},
    {252, 205, 229}, {188, 128, 189}, {204, 235, 197}, {255, 237, 111}};

/// A colour map with a control point at each of `colours` (RGB 0..255) spread over lo..hi.
vtkSmartPointer<vtkLookupTable> ramp(std::initializer_list<std::array<int, 3>> colours, double lo, double hi) {
    vtkNew<vtkColorTransferFunction> ctf;
    ctf->SetColorSpaceToLab();
    const int n = int(colours.size());
    int i = 0;
    for (const auto& c : colours) ctf->AddRGBPoint(lo + (hi - lo) * i++ / (n - 1), c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    auto lut = vtkSmartPointer<vtkLookupTable>::New();
    lut->SetNumberOfTableValues(256);
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

/// The colour map for a layer, by its name and values.
vtkSmartPointer<vtkLookupTable> lut_for(const std::string& name, const float* v, std::size_t n, std::string* title) {
    float lo = v[0], hi = v[0];
    for (std::size_t i = 0; i < n; ++i) lo = std::min(lo, v[i]), hi = std::max(hi, v[i]);
    const LayerStyle style = style_of(name, lo, hi);
    *title = name + " (" + style.unit + ")";
    if (style.kind == LayerStyle::categorical) {
        std::set<int> ids;
        for (std::size_t i = 0; i < n; ++i) ids.insert(int(std::lround(v[i])));
        return name == "boundary" ? categories({ids.begin(), ids.end()}, boundary_names, boundary_colours)
                                  : categories({ids.begin(), ids.end()});
    }
    // Heavy tails (a few fast cells of flow, a few deep gullies) would wash
    // the map out: the range ends at the 98th percentile of magnitudes.
    std::vector<float> mags(v, v + n);
    for (float& m : mags) m = std::fabs(m);
    const std::size_t k = std::min(n - 1, std::size_t(double(n) * 0.98));
    std::nth_element(mags.begin(), mags.begin() + std::ptrdiff_t(k), mags.end());
    const double top = std::max(double(mags[k]), 1e-9);
    if (style.kind == LayerStyle::diverging)  // blue below zero, white at zero, red above (cool to warm)
        return ramp({{59, 76, 192}, {221, 221, 221}, {180, 4, 38}}, -top, top);
    if (name == "height")  // hypsometric: lowlands green to rock brown to snow
        return ramp({{38, 115, 77}, {140, 180, 100}, {210, 190, 130}, {140, 100, 70}, {245, 245, 245}}, lo, hi);
    if (name == "water") return ramp({{247, 251, 255}, {107, 174, 214}, {8, 48, 107}}, std::max(lo, 0.f), top);
    if (name == "sediment") return ramp({{255, 247, 188}, {254, 153, 41}, {102, 37, 6}}, std::max(lo, 0.f), top);
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
    std::vector<float> shade;     // per texel: ambient + diffuse · (normal · light), for `shade_for`
    double shade_for = -1.0;      // the exaggeration `shade` was computed with
    std::vector<std::uint8_t> splat;  // the baked splat texture (RGBA), kept for switching back

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

    void build_terrain() {
        const Terrain& t = *ground();
        step = full ? 1 : std::max(1, int(std::ceil(double(std::max(t.width, t.height) - 1) / (display_samples - 1))));
        const terrain::TerrainMesh mesh = terrain::plan_mesh(grid(), step, 1, 1.0);
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
        vtkNew<vtkPolyData> poly;
        poly->SetPoints(points);
        poly->SetPolys(polys);
        poly->GetPointData()->SetNormals(normals);
        poly->GetPointData()->SetTCoords(uv);
        terrain_mapper->SetInputData(poly);
        terrain_mapper->ScalarVisibilityOff();
        terrain->SetMapper(terrain_mapper);
        terrain->SetTexture(texture);
        vtkProperty* p = terrain->GetProperty();
        p->SetLighting(false);  // the shading is in the texture
        p->SetEdgeColor(0.1, 0.1, 0.1);
        shade_for = -1.0;
        splat.clear();
        top = t.heights->GetValueRange()[1];
        build_water(mesh, chunk);
        apply_layer();
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

    /// The terrain's texture: splat colours (the exporters' own bake) or a layer through its colour map.
    void apply_layer() {
        const Terrain& t = *ground();
        const int tw = std::min(t.width, max_texture), th = std::min(t.height, max_texture);
        vtkNew<vtkImageData> image;
        image->SetDimensions(tw, th, 1);
        vtkNew<vtkUnsignedCharArray> rgba;
        rgba->SetNumberOfComponents(4);
        rgba->SetNumberOfTuples(vtkIdType(tw) * th);
        texture->InterpolateOn();
        bar->SetVisibility(false);
        if (layer == 0) {
            if (splat.size() != std::size_t(tw) * th * 4) splat = terrain::bake_splat_texture(grid(), tw, th);
            std::copy(splat.begin(), splat.end(), rgba->GetPointer(0));
        } else {
            const float* v = values(layer);
            std::string title;
            const std::size_t n = std::size_t(t.width) * t.height;
            auto lut = lut_for(names()[layer], v, n, &title);
            std::vector<float> sampled;
            if (tw != t.width || th != t.height) {  // over max_texture: nearest sample per texel
                sampled.resize(std::size_t(tw) * th);
                for (int j = 0; j < th; ++j)
                    for (int i = 0; i < tw; ++i)
                        sampled[std::size_t(j) * tw + i] =
                            v[std::size_t(std::lround(double(j) * (t.height - 1) / (th - 1))) * t.width +
                              std::size_t(std::lround(double(i) * (t.width - 1) / (tw - 1)))];
                v = sampled.data();
            }
            const std::size_t texels = std::size_t(tw) * th;
            if (lut->GetIndexedLookup()) {
                // Categories: each id its table colour (ids are whole numbers stored as floats),
                // looked up in a table indexed by id − lowest id.
                const int count = lut->GetNumberOfAnnotatedValues();
                int lowest = 0, highest = 0;
                for (int i = 0; i < count; ++i) {
                    const int id = lut->GetAnnotatedValue(i).ToInt();
                    lowest = i ? std::min(lowest, id) : id;
                    highest = i ? std::max(highest, id) : id;
                }
                std::vector<std::array<std::uint8_t, 4>> colour(std::size_t(highest - lowest + 1), {0, 0, 0, 255});
                for (int i = 0; i < count; ++i) {
                    const double* c = lut->GetTableValue(i);
                    colour[std::size_t(lut->GetAnnotatedValue(i).ToInt() - lowest)] = {
                        std::uint8_t(c[0] * 255 + 0.5), std::uint8_t(c[1] * 255 + 0.5), std::uint8_t(c[2] * 255 + 0.5), 255};
                }
                std::uint8_t* out = rgba->GetPointer(0);
                parallel_for(0, std::int64_t(texels), 1 << 16, [&](std::int64_t a, std::int64_t b) {
                    for (std::int64_t i = a; i < b; ++i) {
                        const long id = std::lround(v[i]) - lowest;
                        const auto& c = id >= 0 && id < long(colour.size()) ? colour[std::size_t(id)] : colour.front();
                        std::copy(c.begin(), c.end(), out + 4 * i);
                    }
                });
                texture->InterpolateOff();  // categories stay crisp
            } else {
                lut->MapScalarsThroughTable2(const_cast<float*>(v), rgba->GetPointer(0), VTK_FLOAT, int(texels), 1,
                                             VTK_RGBA);
            }
            bar->SetLookupTable(lut);
            bar->SetTitle(title.c_str());
            bar->SetVisibility(true);
        }
        apply_shade(tw, th, rgba->GetPointer(0));
        image->GetPointData()->SetScalars(rgba);
        texture->SetInputData(image);
        texture->SetColorModeToDirectScalars();
    }

    /// The hillshade light: from the north-west (−X, −Z), 45° above the horizon (unit vector).
    static constexpr double light[3] = {-0.5, 0.70710678, -0.5};

    /// Multiply the texture by the hillshade of the exaggerated terrain at
    /// each texel's nearest sample: 0.3 ambient + 0.99 · (n · light), so a
    /// flat tile shows its colour at full strength (0.3 + 0.99 · 0.707 ≈ 1).
    void apply_shade(int tw, int th, std::uint8_t* rgba) {
        const Terrain& t = *ground();
        if (shade_for != exaggeration || shade.size() != std::size_t(tw) * th) {
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
        parallel_for(0, std::int64_t(shade.size()), 1 << 16, [&](std::int64_t a, std::int64_t b) {
            for (std::int64_t i = a; i < b; ++i)
                for (int c = 0; c < 3; ++c)
                    rgba[4 * i + c] = std::uint8_t(std::min(255.0f, rgba[4 * i + c] * shade[std::size_t(i)] + 0.5f));
        });
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
            if (step > 1) s << "  (shown 1:" << step << ", f: full resolution)";
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

    void camera_from_angles() {
        vtkCamera* cam = renderer->GetActiveCamera();
        double b[6];
        renderer->ComputeVisiblePropBounds(b);
        if (b[0] > b[1]) return;
        renderer->ComputeAspect();  // before the first render too: the fit depends on the window's shape
        const double centre[3] = {(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2};
        const double el = (top_view ? 90.0 : std::clamp(angles.elevation, -89.0, 90.0)) * pi / 180,
                     az = angles.azimuth * pi / 180;
        const double dir[3] = {std::cos(el) * std::sin(az), std::sin(el), -std::cos(el) * std::cos(az)};
        cam->SetFocalPoint(centre);
        cam->SetPosition(centre[0] + dir[0], centre[1] + dir[1], centre[2] + dir[2]);
        if (top_view)
            cam->SetViewUp(0, 0, -1);  // a map: north up
        else if (el > 89.9 * pi / 180)
            cam->SetViewUp(-std::sin(az), 0, std::cos(az));  // looking down from a bearing: that side at the bottom
        else
            cam->SetViewUp(0, 1, 0);
        cam->SetParallelProjection(top_view);
        renderer->ResetCamera(b);
        if (top_view)
            cam->SetParallelScale(cam->GetParallelScale() / 1.35);  // ResetCamera fits the bounding sphere: fit the square
        else if (angles.distance > 0)
            cam->SetDistance(angles.distance);
        else
            cam->Dolly(1.3);
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
        "if (dist > 1.0) { discard; } else { float scale = 1.0 - dist; ambientColor *= scale; diffuseColor *= scale; }\n");
    m.bar->SetNumberOfLabels(5);
    m.bar->SetOrientationToHorizontal();  // bottom right, clear of long titles
    m.bar->SetPosition(0.6, 0.05);
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
        m.build_terrain();
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

bool Scene::empty() const {
    return !impl_->ground() && impl_->content.series.empty() && impl_->gltf_actors.empty();
}

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

void Scene::set_full_resolution(bool full) {
    Impl& m = *impl_;
    if (m.full == full) return;
    m.full = full;
    if (m.ground()) m.build_terrain();
    m.update_status();
}
bool Scene::full_resolution() const { return impl_->full; }

double Scene::exaggeration() const { return impl_->exaggeration; }
void Scene::set_exaggeration(double e) {
    impl_->exaggeration = std::clamp(e, 0.01, 100.0);
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
    if (error)
        impl_->message->GetTextProperty()->SetColor(1.0, 0.45, 0.4);
    else
        impl_->message->GetTextProperty()->SetColor(0.9, 0.95, 1.0);
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
      << "time_index=" << m.time_index << "\n"
      << "playing=" << (m.playing ? "on" : "off") << "\n"
      << "particle_attribute=" << m.particle_attribute << "\n";
    const double* p = cam->GetPosition();
    s << "camera=" << p[0] << "," << p[1] << "," << p[2] << "\n";
    return s.str();
}

void Scene::render() { impl_->window->Render(); }

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
