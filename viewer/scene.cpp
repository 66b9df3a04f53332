// scene.cpp — the VTK scene of orogen-view (see scene.hpp): its content, the public calls and keys. The rest
// is by subject in scene_mesh.cpp, scene_layers.cpp, scene_time.cpp and scene_view.cpp (scene_impl.hpp).
#include "scene_impl.hpp"

namespace orogen::view {

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
void Scene::toggle_plates() { set_plates(!impl_->show_plates); }
void Scene::set_plates(bool on) {
    impl_->show_plates = on;
    impl_->apply_time();
}
bool Scene::has_terrain() const { return impl_->ground(); }
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

}  // namespace orogen::view
