// scene_impl.hpp — the inside of orogen-view's Scene (scene.hpp), shared by the files that implement it
// by subject: scene.cpp (content, keys, the public calls), scene_mesh.cpp (the terrain's mesh and its
// refinement on zoom, water), scene_layers.cpp (layers, colour textures, the hillshade),
// scene_time.cpp (the time series: plates, collisions, particles), scene_view.cpp (camera, status line,
// state and screenshots). colour_maps.hpp holds the colour maps.
#pragma once
#include "colour_maps.hpp"
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

inline constexpr double pi = 3.14159265358979323846;

/// The longest side of the mesh shown by default; bigger terrains keep every
/// k-th sample. The texture keeps every sample (up to `max_texture`) and
/// carries the shading too (a hillshade baked from the full-resolution
/// normals), so only silhouettes are coarser. llvmpipe's cost is per
/// triangle: 257² keeps a frame at 1280×800 near 100 ms of CPU.
inline constexpr int display_samples = 257;
inline constexpr int max_texture = 8192;

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
    void load_terrain();

    /// The kept sample indices along an axis of n samples: every `step`-th
    /// (the display decimation), but every `detail.step`-th within [lo, hi].
    std::vector<int> kept(int n, int lo, int hi) const;

    /// The terrain's mesh: the decimated grid, with the rows and columns of
    /// the detail region (if any) at its finer step. Rows and columns run
    /// through the whole grid, so there are no cracks where the detail ends.
    void build_mesh();

    static constexpr int moving_samples = 129;
    vtkNew<vtkPolyDataMapper> moving_mapper;
    bool has_moving_mesh = false, moving = false;

    void set_moving(bool on);

    /// The mesh's one chunk as VTK polygons with texture coordinates (and normals, for edges).
    static vtkSmartPointer<vtkPolyData> polydata(const mesh::TerrainMesh& mesh);

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
    bool refine();

    static constexpr double refine_pixels = 4.0;

    Detail detail_in_view(int width_px, int height_px) const;

    /// Water: triangles whose three corners hold more than 20 cm of water,
    /// raised to the water's surface (height + depth).
    void build_water(const mesh::TerrainMesh& mesh, const mesh::MeshChunk& chunk);

    /// The texture's size: every sample, up to `max_texture` a side.
    std::pair<int, int> texture_size() const;

    /// The terrain's texture: splat colours (the exporters' own bake) or a
    /// layer through its colour map, times the hillshade; from the cache when
    /// this layer was shown before with the same exaggeration.
    void apply_layer();

    static std::size_t texture_bytes(const CachedTexture& c) { return std::size_t(c.image->GetNumberOfPoints()) * 3; }

    /// Make the texture of one layer not yet kept, if the cache has room for
    /// it without dropping another: what the viewer does while idle, so the
    /// first switch to a layer finds its texture made. false if none was made.
    bool prefetch();

    const Colouring& colouring(std::size_t index);

    /// One layer's finished texture: colour × hillshade, RGB (no alpha: VTK
    /// would scan an RGBA texture for translucency on every upload).
    vtkSmartPointer<vtkImageData> colour_texture(std::size_t index);

    /// The hillshade light: from the north-west (−X, −Z), 45° above the horizon (unit vector).
    static constexpr double light[3] = {-0.5, 0.70710678, -0.5};

    /// The hillshade of the exaggerated terrain at each texel's nearest sample:
    /// 0.3 ambient + 0.99 · (n · light), so a flat tile shows its colour at
    /// full strength (0.3 + 0.99 · 0.707 ≈ 1). Textures multiply by it.
    void update_shade(int tw, int th);

    /// The particle attribute names of the particle series' first frame.
    std::vector<std::string> particle_attributes() const;

    template <typename Part>
    const Frame* frame_at(const Series* s, Part part) const;

    void apply_time();

    double extent() const;

    void apply_exaggeration();

    void update_status();

    /// The band at the window's bottom that the colour scale and the status line take, pixels: the bar's
    /// offset, its height (11 % of the window, at most 90 pixels) and a margin.
    static double legend_band(double window_height) { return bar_offset + std::min(0.11 * window_height, 90.0) + 8; }
    static constexpr double bar_offset = 48;

    void camera_from_angles();
};

}  // namespace orogen::view
