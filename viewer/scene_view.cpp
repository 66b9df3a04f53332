// scene_view.cpp — orogen-view's scene: the camera, the status line, the state printout and screenshots (scene_impl.hpp).
#include "scene_impl.hpp"

namespace orogen::view {

double Scene::Impl::extent() const {
    if (const Terrain* t = ground()) return std::max(t->width - 1, t->height - 1) * t->cell;
    double b[6];
    renderer->ComputeVisiblePropBounds(b);
    return b[0] <= b[1] ? std::max({b[1] - b[0], b[3] - b[2], b[5] - b[4], 1.0}) : 1.0;
}

void Scene::Impl::apply_exaggeration() {
    for (vtkActor* a : {terrain.Get(), water.Get(), particles.Get()}) a->SetScale(1, exaggeration, 1);
    for (auto& a : gltf_actors) a->SetScale(1, exaggeration, 1);
    apply_time();
}

void Scene::Impl::update_status() {
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

void Scene::Impl::camera_from_angles() {
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
        cam->SetParallelScale(cam->GetParallelScale() / 1.35);  // ResetCamera fits the bounding sphere: fit the square
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
        cam->SetPosition(f[0] - d[0] * angles.distance, f[1] - d[1] * angles.distance, f[2] - d[2] * angles.distance);
    } else cam->Dolly(1.3);
    renderer->ResetCameraClippingRange();
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
