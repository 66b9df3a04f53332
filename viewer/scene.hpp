// scene.hpp — what orogen-view draws: the terrain (splat-coloured or coloured
// by a layer, through a texture so switching layers re-uploads no geometry),
// its water, plates and collisions, particles, and the text overlays.
//
// Frame: the exporters' — X east, Y up, Z south, metres. Vertical
// exaggeration scales Y of every 3D actor (VTK transforms the normals too,
// so the lighting follows). The light is a hillshade's: from the north-west,
// 45° above the horizon.
#pragma once

#include "reader.hpp"

#include <vtkSmartPointer.h>

#include <memory>
#include <string>
#include <vector>

class vtkRenderWindow;
class vtkRenderer;

namespace orogen::view {

/// Where the camera stands, seen from the terrain's centre: compass bearing
/// (degrees, 0 = north, 90 = east), elevation above the horizon (degrees) and
/// distance (metres; 0 = fit the whole scene).
struct CameraAngles {
    double azimuth = 200.0, elevation = 40.0, distance = 0.0;
};

class Scene {
public:
    explicit Scene(vtkRenderWindow* window);
    ~Scene();

    /// Replace what is shown (the camera stays where it is if `keep_camera`).
    void show(Content content, bool keep_camera);
    bool empty() const;

    // Colour: index 0 is the splat colours, 1 height, then each layer.
    std::vector<std::string> layer_names() const;
    std::string layer() const;
    void cycle_layer(int step);
    /// false if the terrain has no such layer.
    bool set_layer(const std::string& name);

    void toggle_water();
    void toggle_particles();
    void toggle_plates();
    void set_plates(bool on);
    /// A terrain (a .vti or .vtp heightfield) is shown.
    bool has_terrain() const;
    void toggle_edges();
    void toggle_help();
    void cycle_particle_attribute();
    /// While idle: colour one layer not yet shown into the texture cache (so
    /// switching to it only uploads). false when there is nothing left to do.
    bool prefetch();

    /// Full resolution instead of the display decimation of big terrains.
    void set_full_resolution(bool full);
    bool full_resolution() const;

    double exaggeration() const;
    void set_exaggeration(double e);

    void set_camera(const CameraAngles& angles);
    void reset_camera();
    void toggle_top_view();

    // Time over every .pvd series: the union of their frame times.
    const std::vector<double>& times() const;
    std::size_t time_index() const;
    void set_time_index(std::size_t i);
    /// The frame at or just before `t`.
    void set_time(double t);
    void set_playing(bool playing);
    bool playing() const;

    /// A message over the scene (e.g. a spec error); "" hides it.
    void set_message(const std::string& text, bool error);
    /// The keys and what they do, as the help overlay shows them.
    static std::string help_text();

    /// One line per setting, "name=value", for tests and --print-state.
    std::string state() const;

    /// Write the current frame as PNG.
    void screenshot(const std::string& file);
    /// Draw a still frame: refine the mesh for the camera first (see refine).
    void render();
    /// Refinement on zoom: when the camera is close enough that the
    /// decimated mesh's cells in view span more than a few pixels, those
    /// rows and columns are rebuilt at a finer step (bounded: at most 257
    /// finer samples a side); zoomed out again, the mesh is the decimated one.
    /// Cheap when the camera has not moved. true if the mesh changed.
    bool refine();
    void set_refine_on_zoom(bool on);
    /// While the camera moves (a drag), a coarser terrain mesh (at most 129
    /// samples a side) is drawn; the still frame after it is the full one.
    void set_moving(bool moving);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace orogen::view
