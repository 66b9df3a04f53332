// scene_time.cpp — orogen-view's scene: the time series: plates, collisions and particles at the time shown (scene_impl.hpp).
#include "scene_impl.hpp"

namespace orogen::view {

std::vector<std::string> Scene::Impl::particle_attributes() const {
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
const Frame* Scene::Impl::frame_at(const Series* s, Part part) const {
    if (!s || times.empty()) return nullptr;
    const double t = times[time_index];
    const Frame* best = nullptr;
    for (const auto& f : s->frames)
        if ((f.*part) && (f.time <= t || !best)) best = &f;
    return best;
}

void Scene::Impl::apply_time() {
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

}  // namespace orogen::view
