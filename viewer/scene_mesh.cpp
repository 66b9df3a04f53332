// scene_mesh.cpp — orogen-view's scene: the terrain's mesh, its refinement on zoom, and the water (scene_impl.hpp).
#include "scene_impl.hpp"

namespace orogen::view {

void Scene::Impl::load_terrain() {
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

std::vector<int> Scene::Impl::kept(int n, int lo, int hi) const {
    std::vector<int> k;
    for (int i : mesh::kept_indices(n, step))
        if (i < lo || i > hi || detail.step == 0) k.push_back(i);
    if (detail.step > 0) {
        for (int i = lo; i < hi; i += detail.step) k.push_back(i);
        k.push_back(hi);
        std::sort(k.begin(), k.end());
        k.erase(std::unique(k.begin(), k.end()), k.end());
    }
    return k;
}

void Scene::Impl::build_mesh() {
    const Terrain& t = *ground();
    step = full ? 1 : std::max(1, int(std::ceil(double(std::max(t.width, t.height) - 1) / (display_samples - 1))));
    if (full) detail = {};
    mesh::TerrainMesh mesh = mesh::plan_mesh(grid(), step, 1, 1.0);
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
    if (has_moving_mesh) moving_mapper->SetInputData(polydata(mesh::plan_mesh(grid(), moving_step, 1, 1.0)));
    moving_mapper->ScalarVisibilityOff();
    terrain->SetMapper(moving && has_moving_mesh ? moving_mapper.Get() : terrain_mapper.Get());
    terrain->SetTexture(texture);
    vtkProperty* p = terrain->GetProperty();
    p->SetLighting(false);  // the shading is in the texture
    terrain->ForceOpaqueOn();  // an RGB texture: nothing to blend, no translucency scan
    p->SetEdgeColor(0.1, 0.1, 0.1);
    build_water(mesh, mesh.chunks.at(0));
}

void Scene::Impl::set_moving(bool on) {
    moving = on;
    if (ground()) terrain->SetMapper(moving && has_moving_mesh ? moving_mapper.Get() : terrain_mapper.Get());
}

vtkSmartPointer<vtkPolyData> Scene::Impl::polydata(const mesh::TerrainMesh& mesh) {
    const mesh::MeshChunk& chunk = mesh.chunks.at(0);
    const std::size_t n = chunk.vertex_count(), triangles = chunk.triangle_count();
    vtkNew<vtkFloatArray> xyz, normals, uv;
    xyz->SetNumberOfComponents(3);
    xyz->SetNumberOfTuples(vtkIdType(n));
    mesh::chunk_positions(mesh, chunk, {xyz->GetPointer(0), n * 3});
    normals->SetName("Normals");
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(vtkIdType(n));
    mesh::chunk_normals(mesh, chunk, {normals->GetPointer(0), n * 3});
    uv->SetName("uv");
    uv->SetNumberOfComponents(2);
    uv->SetNumberOfTuples(vtkIdType(n));
    mesh::chunk_texcoords(mesh, chunk, std::span<float>{uv->GetPointer(0), n * 2});
    vtkNew<vtkTypeInt32Array> offsets, connectivity;
    offsets->SetNumberOfTuples(vtkIdType(triangles + 1));
    for (std::size_t i = 0; i <= triangles; ++i) offsets->SetValue(vtkIdType(i), std::int32_t(3 * i));
    connectivity->SetNumberOfTuples(vtkIdType(triangles * 3));
    mesh::chunk_indices(chunk, {reinterpret_cast<std::uint32_t*>(connectivity->GetPointer(0)), triangles * 3});
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

bool Scene::Impl::refine() {
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

Scene::Impl::Detail Scene::Impl::detail_in_view(int width_px, int height_px) const {
    const Terrain& t = *ground();
    const std::vector<int> cols = mesh::kept_indices(t.width, step), rows = mesh::kept_indices(t.height, step);
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
    Detail d{cols[std::size_t(ci0)], rows[std::size_t(rj0)], cols[std::size_t(ci1) + 1], rows[std::size_t(rj1) + 1], 0};
    const int span = std::max(d.x1 - d.x0, d.y1 - d.y0);
    const int budget = (span + display_samples - 2) / (display_samples - 1);  // fits 257 a side
    const int sharp = widest > 1e299 ? 1 : int(std::ceil(2.0 * step / widest));  // ≥ 2 px a sample
    d.step = std::max({1, budget, sharp});
    if (2 * d.step > step) return {};  // not worth it: less than twice as fine
    return d;
}

void Scene::Impl::build_water(const mesh::TerrainMesh& mesh, const mesh::MeshChunk& chunk) {
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
            const auto p = mesh::position(mesh, mesh.columns[i], mesh.rows[j]);
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

std::pair<int, int> Scene::Impl::texture_size() const {
    return {std::min(ground()->width, max_texture), std::min(ground()->height, max_texture)};
}

}  // namespace orogen::view
