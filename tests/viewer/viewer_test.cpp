// orogen-view, run as users run it: a subprocess under Xvfb (tests/viewer/xvfb-run.sh),
// on files written by the real exporters; its pictures are read back and sampled.
#include <orogen/mesh/terrain_mesh.hpp>
#include <orogen/formats/raw.hpp>
#include <orogen/vtk/vtk_writer.hpp>

#include <orogen/io.hpp>
#include <orogen/values.hpp>

#include <gtest/gtest.h>
#include "../support/test_picture.hpp"
#include <png.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
#include <sys/wait.h>

namespace fs = std::filesystem;
using namespace orogen;
using orogen::test::differing_pixels;
using orogen::test::Picture;
using orogen::test::read_picture;

namespace {

struct Result {
    int code = -1;
    std::string out, err;
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

class Viewer : public ::testing::Test {
protected:
    fs::path dir;

    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir = fs::temp_directory_path() /
            ("orogen_view_test_" + std::string(info->name()) + "_" + std::to_string(getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }

    /// Run `orogen-view args` (a shell command line) in `dir`; `prefix` goes before the program (e.g. "env -u DISPLAY").
    Result view(const std::string& args, const std::string& prefix = "") {
        const std::string cmd = "cd '" + dir.string() + "' && " + prefix + " '" OROGEN_VIEW "' " + args + " >'" +
            (dir / "stdout").string() + "' 2>'" + (dir / "stderr").string() + "'";
        const int status = std::system(cmd.c_str());
        Result r;
        r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        r.out = slurp(dir / "stdout");
        r.err = slurp(dir / "stderr");
        return r;
    }

    /// A width × height terrain, cell 10 m, with layers.
    void write_vti(const fs::path& file, const std::vector<float>& h, int w, int hgt,
                   const std::vector<std::pair<std::string, std::vector<float>>>& layers = {}) {
        std::vector<vtk::NamedGrid> named;
        for (const auto& [name, v] : layers) named.push_back({name, ConstGridView(v.data(), w, hgt, 10.0)});
        vtk::write_heightmap(ConstGridView(h.data(), w, hgt, 10.0), named, file);
    }
};

/// Mean colour of a 9 × 9 patch.
std::array<double, 3> patch(const Picture& p, int cx, int cy) {
    std::array<double, 3> m{};
    for (int y = cy - 4; y <= cy + 4; ++y)
        for (int x = cx - 4; x <= cx + 4; ++x)
            for (int c = 0; c < 3; ++c) m[c] += p.at(x, y)[c] / 81.0;
    return m;
}

double distance(const std::array<double, 3>& a, const std::array<std::uint8_t, 3>& b) {
    return std::sqrt(std::pow(a[0] - b[0], 2) + std::pow(a[1] - b[1], 2) + std::pow(a[2] - b[2], 2));
}
double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::sqrt(std::pow(a[0] - b[0], 2) + std::pow(a[1] - b[1], 2) + std::pow(a[2] - b[2], 2));
}

/// A 65 × 65 terrain: a flat plain at 0 m (west), a slope, a flat plateau at 100 m (east).
std::vector<float> plain_and_plateau(int n = 65) {
    std::vector<float> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) h[std::size_t(y) * n + x] = x < 28 ? 0.f : x > 36 ? 100.f : float(x - 28) * 12.5f;
    return h;
}

const std::string top_view = "--top --camera 0,90 --size 320x320";

// ------------------------------------------------------------------ pictures

TEST_F(Viewer, ScreenshotShowsTheSplatColoursWhereExpected) {
    write_vti(dir / "t.vti", plain_and_plateau(), 65, 65);
    const Result r = view("t.vti --screenshot shot.png " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const Picture p = read_picture(dir / "shot.png");
    ASSERT_EQ(p.width, 320);
    ASSERT_EQ(p.height, 320);
    // Looking down, north up: the plain (lowest band: sand) on the left, the
    // plateau (highest band: snow) on the right, the steep slope rock.
    const auto west = patch(p, 70, 160), east = patch(p, 250, 160);
    EXPECT_LT(distance(west, mesh::sand_colour), 30) << west[0] << " " << west[1] << " " << west[2];
    EXPECT_LT(distance(east, mesh::snow_colour), 30) << east[0] << " " << east[1] << " " << east[2];
    for (const auto& other : {mesh::grass_colour, mesh::rock_colour, mesh::snow_colour})
        EXPECT_GT(distance(west, other), 45);
    // Not an empty picture: the terrain covers the middle, the background the corners differ from it.
    EXPECT_GT(distance(patch(p, 160, 160), patch(p, 6, 6)), 20);
}

TEST_F(Viewer, ColouringByALayerChangesThePixelsAndUsesItsColourMap) {
    const int n = 65;
    std::vector<float> flow(n * n), plate(n * n), eroded(n * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            flow[y * n + x] = float(x) / n;
            plate[y * n + x] = float((x < n / 2 ? 0 : 1) + (y < n / 2 ? 0 : 2) + 3);  // ids 3..6 in quadrants
            eroded[y * n + x] = x < n / 2 ? -2.f : 2.f;  // deposits west, erosion east
        }
    write_vti(dir / "t.vti", plain_and_plateau(), n, n, {{"flow", flow}, {"plate", plate}, {"eroded", eroded}});
    ASSERT_EQ(view("t.vti --screenshot splat.png " + top_view).code, 0);
    const Result r = view("t.vti --screenshot flow.png --layer flow " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(view("t.vti --screenshot plate.png --layer plate " + top_view).code, 0);
    ASSERT_EQ(view("t.vti --screenshot eroded.png --layer eroded " + top_view).code, 0);
    const Picture splat = read_picture(dir / "splat.png"), fl = read_picture(dir / "flow.png"),
                  pl = read_picture(dir / "plate.png"), er = read_picture(dir / "eroded.png");
    EXPECT_GT(differing_pixels(splat, fl), 20000u);
    // Flow rises west to east: the colour map's ends differ.
    EXPECT_GT(distance(patch(fl, 70, 160), patch(fl, 250, 160)), 80);
    // One colour per plate: the four quadrants' colours are all different.
    // (The map is fitted above the colour scale's band: 229 pixels square, its top at the window's.)
    const std::array<std::array<double, 3>, 4> q{patch(pl, 100, 55), patch(pl, 220, 55), patch(pl, 100, 170),
                                                 patch(pl, 220, 170)};
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) EXPECT_GT(distance(q[i], q[j]), 40) << "quadrants " << i << " and " << j;
    // Diverging map: negative (west) blue, positive (east) red.
    const auto west = patch(er, 70, 160), east = patch(er, 250, 160);
    EXPECT_GT(west[2], west[0] + 40);
    EXPECT_GT(east[0], east[2] + 40);
}

TEST_F(Viewer, AnUnknownLayerNamesTheLayersThereAre) {
    std::vector<float> flow(65 * 65, 1.f);
    write_vti(dir / "t.vti", plain_and_plateau(), 65, 65, {{"flow", flow}});
    const Result r = view("t.vti --screenshot s.png --layer flw");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, "orogen-view: error: no layer 'flw' to colour by; this terrain has: splat, height, flow\n");
}

TEST_F(Viewer, VtpRawAndPngTerrainsShowTheSameSplat) {
    const auto h = plain_and_plateau();
    write_vti(dir / "t.vti", h, 65, 65);
    vtk::write_heightmap(ConstGridView(h.data(), 65, 65, 10.0), {}, dir / "t.vtp");
    formats::raw::write_raw(ConstGridView(h.data(), 65, 65, 10.0), dir / "t.r16");
    {  // a 16-bit PNG heightmap: no units, but the same bands (flat plain and plateau)
        std::vector<std::uint16_t> grey(h.size());
        for (std::size_t i = 0; i < h.size(); ++i) grey[i] = std::uint16_t(std::lround(h[i] / 100.0 * 65535));
        AtomicFile png(dir / "t.png");
        write_gray_png(png.stream(), 65, 65, 16, grey);
        png.commit();
    }
    ASSERT_EQ(view("t.vti --screenshot a.png " + top_view).code, 0);
    Result r = view("t.vtp --screenshot b.png " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    r = view("t.r16 --screenshot c.png " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    r = view("t.png --screenshot d.png " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    const Picture a = read_picture(dir / "a.png"), b = read_picture(dir / "b.png"), c = read_picture(dir / "c.png"),
                  d = read_picture(dir / "d.png");
    for (const Picture* p : {&b, &c, &d}) {
        EXPECT_LT(distance(patch(a, 70, 160), patch(*p, 70, 160)), 10);
        EXPECT_LT(distance(patch(a, 250, 160), patch(*p, 250, 160)), 10);
    }
}

// --------------------------------------------------------------------- time

PlateHistory moving_plates() {
    PlateHistory h;
    h.width = h.height = 640;
    for (int s = 0; s < 3; ++s) {
        PlateSnapshot snap;
        snap.step = s * 10;
        snap.time = s;
        const float shift = 150.f * s;
        snap.plates.push_back({1, {{0, 0}, {200 + shift, 0}, {200 + shift, 640}, {0, 640}}, {1, 0}, 1.0});
        snap.plates.push_back({2, {{200 + shift, 0}, {640, 0}, {640, 640}, {200 + shift, 640}}, {-1, 0}, 1.0});
        h.snapshots.push_back(snap);
        h.collisions.push_back({snap.step, 1, 2, {200 + shift, 0}, {200 + shift, 640}, BoundaryKind::convergent, 5.0});
    }
    return h;
}

TEST_F(Viewer, PlatesSeriesFramesDifferOverTime) {
    write_vti(dir / "t.vti", plain_and_plateau(), 65, 65);
    fs::create_directories(dir / "plates");
    vtk::write_plates(moving_plates(), dir / "plates" / "plates.pvd");
    for (int t = 0; t < 3; ++t) {
        const Result r = view("t.vti plates/plates.pvd --screenshot p" + std::to_string(t) + ".png --time " +
                              std::to_string(t) + " " + top_view);
        ASSERT_EQ(r.code, 0) << r.err;
    }
    ASSERT_EQ(view(". --screenshot folder.png --time 0 " + top_view).code, 0);
    const Picture p0 = read_picture(dir / "p0.png"), p1 = read_picture(dir / "p1.png"),
                  p2 = read_picture(dir / "p2.png");
    EXPECT_GT(differing_pixels(p0, p1), 1000u);
    EXPECT_GT(differing_pixels(p1, p2), 1000u);
    // The plates tint the terrain: without them (m toggles, here: no .pvd) the picture differs.
    ASSERT_EQ(view("t.vti --screenshot bare.png " + top_view).code, 0);
    const Picture bare = read_picture(dir / "bare.png");
    EXPECT_GT(differing_pixels(bare, p0), 20000u);
    // A folder (a run's whole output) opens on its terrain, the plates loaded but hidden until `m`.
    EXPECT_LT(differing_pixels(bare, read_picture(dir / "folder.png")), 50u);
}

TEST_F(Viewer, ParticleSeriesFramesShowMovingColouredParticles) {
    ParticleSeries s;
    for (int f = 0; f < 2; ++f) {
        ParticleFrame frame;
        frame.time = f * 0.5;
        frame.step = f;
        ParticleAttribute pos{3, {}}, density{1, {}};
        for (int i = 0; i < 200; ++i) {
            pos.data.insert(pos.data.end(), {float(i % 20) * 30 + 20 + f * 40, 120.f, float(i / 20) * 60 + 20});
            density.data.push_back(float(i));
        }
        frame.attributes["position"] = pos;
        frame.attributes["density"] = density;
        s.frames.push_back(frame);
    }
    write_vti(dir / "t.vti", plain_and_plateau(), 65, 65);
    vtk::write_particles(s, dir / "p.pvd");
    ASSERT_EQ(view("t.vti p.pvd --screenshot a.png --time 0 " + top_view).code, 0);
    ASSERT_EQ(view("t.vti p.pvd --screenshot b.png --time 0.5 " + top_view).code, 0);
    ASSERT_EQ(view("t.vti --screenshot c.png " + top_view).code, 0);
    const Picture a = read_picture(dir / "a.png"), b = read_picture(dir / "b.png"), c = read_picture(dir / "c.png");
    EXPECT_GT(differing_pixels(a, c), 500u);  // particles drawn
    EXPECT_GT(differing_pixels(a, b), 500u);  // and they moved
}

// export:vtk writes Z up by default (ParaView's frame) and Y up on request
// (glTF's); orogen-view turns either into its own frame, so the pictures match.
TEST_F(Viewer, ZUpAndYUpFilesShowTheSamePicture) {
    const auto h = plain_and_plateau();
    std::vector<float> ramp(h.size());
    for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = float(i / 65);  // rises to the south: shows a flip
    const std::vector<vtk::NamedGrid> layers = {{"ramp", ConstGridView(ramp.data(), 65, 65, 10.0)}};
    ParticleSeries particles;
    particles.frames.emplace_back();
    ParticleAttribute pos{3, {}}, density{1, {}};
    for (int i = 0; i < 100; ++i) {
        pos.data.insert(pos.data.end(), {float(i % 10) * 20 + 20, 120.f, float(i / 10) * 30 + 300});
        density.data.push_back(float(i));
    }
    particles.frames[0].attributes = {{"position", pos}, {"density", density}};
    for (const auto up : {vtk::Up::z, vtk::Up::y}) {
        const std::string tag = up == vtk::Up::z ? "z" : "y";
        vtk::Options o;
        o.up = up;
        fs::create_directories(dir / tag);
        vtk::write_heightmap(ConstGridView(h.data(), 65, 65, 10.0), layers, dir / tag / "t.vti", o);
        vtk::write_heightmap(ConstGridView(h.data(), 65, 65, 10.0), layers, dir / tag / "m.vtp", o);
        vtk::write_plates(moving_plates(), dir / tag / "plates.pvd", o);
        vtk::write_particles(particles, dir / tag / "p.vtp", o);
        for (const char* input : {"t.vti", "m.vtp"}) {
            const Result r =
                view(tag + "/" + input + " " + tag + "/plates.pvd " + tag + "/p.vtp --layer ramp --time 1 " +
                     "--screenshot " + tag + "_" + input + ".png " + top_view);
            ASSERT_EQ(r.code, 0) << r.err;
        }
    }
    for (const char* input : {"t.vti", "m.vtp"}) {
        const Picture z = read_picture(dir / (std::string("z_") + input + ".png")),
                      y = read_picture(dir / (std::string("y_") + input + ".png"));
        EXPECT_LT(differing_pixels(z, y), 50u) << input;
    }
    // The layer is not mirrored: the top of the picture (north) is low on the ramp, the bottom high.
    const Picture z = read_picture(dir / "z_t.vti.png");
    EXPECT_GT(distance(patch(z, 160, 20), patch(z, 160, 210)), 30.0);
}

// ---------------------------------------------------------------------- keys

/// A VTK event log (vtkInteractorEventRecorder's format) pressing `keys` in order.
std::string key_events(const std::vector<std::pair<std::string, char>>& keys) {
    std::string s = "# StreamVersion 1\n";
    for (const auto& [sym, code] : keys) {
        const int c = static_cast<unsigned char>(code);
        s += "KeyPressEvent 10 10 0 0 " + std::to_string(c) + " 1 " + sym + "\n";
        s += "CharEvent 10 10 0 0 " + std::to_string(c) + " 1 " + sym + "\n";
        s += "KeyReleaseEvent 10 10 0 0 " + std::to_string(c) + " 1 " + sym + "\n";
    }
    return s;
}

std::string state_value(const std::string& state, const std::string& key) {
    std::istringstream in(state);
    for (std::string line; std::getline(in, line);)
        if (line.rfind(key + "=", 0) == 0) return line.substr(key.size() + 1);
    return "?";
}

TEST_F(Viewer, EachKeyDoesWhatTheHelpSays) {
    const int n = 65;
    std::vector<float> water(n * n), flow(n * n, 1.f);
    for (int i = 0; i < n * n; ++i) water[i] = (i % n) < 20 ? 0.5f : 0.f;
    write_vti(dir / "t.vti", plain_and_plateau(), n, n, {{"water", water}, {"flow", flow}});
    vtk::write_plates(moving_plates(), dir / "plates.pvd");
    auto replay = [&](const std::vector<std::pair<std::string, char>>& keys) {
        std::ofstream(dir / "events.log") << key_events(keys);
        const Result r = view("t.vti plates.pvd --events events.log --print-state --size 320x240");
        EXPECT_EQ(r.code, 0) << r.err;
        return r.out;
    };
    const std::string before = replay({});
    EXPECT_EQ(state_value(before, "layer"), "splat");
    // Every toggle at once (each changes its own setting), then the keys that go back.
    const std::string all = replay({{"l", 'l'},
                                    {"w", 'w'},
                                    {"p", 'p'},
                                    {"m", 'm'},
                                    {"e", 'e'},
                                    {"h", 'h'},
                                    {"v", 'v'},
                                    {"plus", '+'},
                                    {"period", '.'},
                                    {"space", ' '},
                                    {"a", 'a'},
                                    {"f", 'f'}});
    const std::vector<std::pair<std::string, std::string>> expected{{"layer", "height"},
                                                                    {"water", "off"},
                                                                    {"particles", "off"},
                                                                    {"plates", "off"},
                                                                    {"edges", "on"},
                                                                    {"help", "on"},
                                                                    {"view", "top"},
                                                                    {"exaggeration", "1.25"},
                                                                    {"time_index", "1"},
                                                                    {"playing", "on"},
                                                                    {"particle_attribute", "1"},
                                                                    {"full_resolution", "on"}};
    for (const auto& [key, value] : expected) {
        EXPECT_EQ(state_value(all, key), value) << key;
        EXPECT_NE(state_value(before, key), value) << key;
    }
    const std::string back = replay({{"L", 'L'}, {"minus", '-'}, {"comma", ','}});
    EXPECT_EQ(state_value(back, "layer"), "flow");  // before splat: the last layer
    EXPECT_EQ(state_value(back, "exaggeration"), "0.8");
    EXPECT_EQ(state_value(back, "time_index"), "0");  // stays at the first time
    // r puts the camera back where it started after a drag.
    std::ofstream(dir / "events.log") << "# StreamVersion 1\n"
                                         "LeftButtonPressEvent 160 120 0 0 0 0 0\n"
                                         "MouseMoveEvent 200 150 0 0 0 0 0\n"
                                         "MouseMoveEvent 260 170 0 0 0 0 0\n"
                                         "LeftButtonReleaseEvent 260 170 0 0 0 0 0\n";
    const std::string dragged = view("t.vti plates.pvd --events events.log --print-state --size 320x240").out;
    EXPECT_NE(state_value(dragged, "camera"), state_value(before, "camera"));
    std::ofstream(dir / "events.log", std::ios::app)
        << key_events({{"r", 'r'}}).substr(std::string("# StreamVersion 1\n").size());
    const std::string reset = view("t.vti plates.pvd --events events.log --print-state --size 320x240").out;
    EXPECT_EQ(state_value(reset, "camera"), state_value(before, "camera"));
    // s writes a screenshot into the working folder.
    std::ofstream(dir / "events.log") << key_events({{"s", 's'}});
    ASSERT_EQ(view("t.vti --events events.log --size 320x240").code, 0);
    EXPECT_TRUE(fs::exists(dir / "orogen-view-1.png"));
}

// ------------------------------------------------- texture cache, refinement

/// The picture without its bottom `rows` (the status line, which names the mesh's decimation).
Picture above_status_line(Picture p, int rows = 26) {
    p.height -= rows;
    p.rgb.resize(std::size_t(p.width) * std::size_t(p.height) * 3);
    return p;
}

TEST_F(Viewer, SwitchingBackToALayerShowsWhatAFreshStartShows) {
    // Textures are kept per layer and per exaggeration: a switch back must show
    // the same pixels as a fresh start, also after the exaggeration changed
    // (the kept textures carry the old hillshade and must not be reused).
    const int n = 65;
    std::vector<float> flow(n * n);
    for (int i = 0; i < n * n; ++i) flow[i] = float(i % n) / n;
    write_vti(dir / "t.vti", plain_and_plateau(), n, n, {{"flow", flow}});
    ASSERT_EQ(view("t.vti --screenshot fresh.png --size 320x240").code, 0);
    ASSERT_EQ(view("t.vti --screenshot fresh125.png --size 320x240 --exaggeration 1.25").code, 0);
    auto after = [&](const std::vector<std::pair<std::string, char>>& keys, const std::string& shot) {
        std::ofstream(dir / "events.log") << key_events(keys);
        const Result r = view("t.vti --events events.log --size 320x240 --screenshot " + shot);
        EXPECT_EQ(r.code, 0) << r.err;
        return read_picture(dir / shot);
    };
    const Picture fresh = read_picture(dir / "fresh.png"), fresh125 = read_picture(dir / "fresh125.png");
    ASSERT_GT(differing_pixels(fresh, fresh125), 100u);  // the exaggeration changes the shading
    // splat → height → flow → splat (kept) → height → splat (kept)
    EXPECT_EQ(
        differing_pixels(after({{"l", 'l'}, {"l", 'l'}, {"l", 'l'}, {"L", 'L'}, {"L", 'L'}, {"L", 'L'}}, "back.png"),
                         fresh, 0),
        0u);
    // splat → height, exaggerate, → splat: coloured again with the new hillshade
    EXPECT_EQ(differing_pixels(after({{"l", 'l'}, {"plus", '+'}, {"L", 'L'}}, "exaggerated.png"), fresh125, 0), 0u);
}

/// A 513 × 513 terrain (10 m cells) of short, steep waves: decimated 1:2 by
/// default, and every second sample missing shows.
std::vector<float> rippled(int n) {
    std::vector<float> h(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            h[std::size_t(y) * n + x] = float(25.0 * std::sin(0.9 * x) * std::sin(0.7 * y) + 0.4 * x + 0.2 * y);
    return h;
}

TEST_F(Viewer, ZoomingInRefinesTheMeshInViewToFullResolution) {
    const int n = 513;
    write_vti(dir / "t.vti", rippled(n), n, n);
    const std::string close = "--camera 200,60,500 --size 320x200 ";
    auto state_of = [&](const std::string& args) {
        const Result r = view("t.vti --events /dev/null --print-state " + args);
        EXPECT_EQ(r.code, 0) << r.err;
        return r.out;
    };
    // Zoomed out the decimated mesh is all there is; close up, the rows and
    // columns in view are every sample's.
    const std::string far = state_of("--size 320x200");
    EXPECT_EQ(state_value(far, "mesh_step"), "2");
    EXPECT_EQ(state_value(far, "detail"), "none");
    const std::string near = state_of(close);
    EXPECT_EQ(state_value(near, "mesh_step"), "2");
    EXPECT_NE(state_value(near, "detail").find("step 1"), std::string::npos) << state_value(near, "detail");
    EXPECT_EQ(state_value(state_of(close + "--no-refine"), "detail"), "none");
    // The picture: unlike the decimated one, the same as --full's (the status lines differ).
    ASSERT_EQ(view("t.vti --screenshot auto.png " + close).code, 0);
    ASSERT_EQ(view("t.vti --screenshot coarse.png --no-refine " + close).code, 0);
    ASSERT_EQ(view("t.vti --screenshot full.png --full " + close).code, 0);
    const Picture autop = above_status_line(read_picture(dir / "auto.png")),
                  coarse = above_status_line(read_picture(dir / "coarse.png")),
                  full = above_status_line(read_picture(dir / "full.png"));
    EXPECT_GT(differing_pixels(full, coarse),
              std::size_t(full.width * full.height / 20));  // the test can see decimation
    EXPECT_LE(differing_pixels(autop, full), std::size_t(full.width * full.height / 1000));
    // Zooming with the mouse wheel refines too (when the camera comes to rest).
    std::string wheel = "# StreamVersion 1\n";
    for (int i = 0; i < 25; ++i) wheel += "MouseWheelForwardEvent 160 100 0 0 0 0 0\n";
    std::ofstream(dir / "wheel.log") << wheel;
    const Result r = view("t.vti --events wheel.log --print-state --size 320x200");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(state_value(r.out, "detail"), "none");
}

TEST_F(Viewer, ADragDrawsACoarserMeshAndTheStillFrameAfterItTheFullOne) {
    const int n = 513;
    write_vti(dir / "t.vti", rippled(n), n, n);
    const std::string drag =
        "# StreamVersion 1\n"
        "LeftButtonPressEvent 160 100 0 0 0 0 0\n"
        "MouseMoveEvent 170 104 0 0 0 0 0\n"
        "MouseMoveEvent 180 108 0 0 0 0 0\n";
    // Still dragging (no release yet): the coarser mesh.
    std::ofstream(dir / "dragging.log") << drag;
    const Result dragging = view("t.vti --events dragging.log --print-state --size 320x200 --screenshot dragging.png");
    ASSERT_EQ(dragging.code, 0) << dragging.err;
    EXPECT_EQ(state_value(dragging.out, "moving"), "on");
    // Released where the last move ended: the same camera, the full mesh.
    std::ofstream(dir / "dragged.log") << drag << "LeftButtonReleaseEvent 180 108 0 0 0 0 0\n";
    const Result dragged = view("t.vti --events dragged.log --print-state --size 320x200 --screenshot dragged.png");
    ASSERT_EQ(dragged.code, 0) << dragged.err;
    EXPECT_EQ(state_value(dragged.out, "moving"), "off");
    EXPECT_EQ(state_value(dragged.out, "camera"), state_value(dragging.out, "camera"));
    const Picture coarse = above_status_line(read_picture(dir / "dragging.png")),
                  still = above_status_line(read_picture(dir / "dragged.png"));
    EXPECT_GT(differing_pixels(coarse, still), std::size_t(still.width * still.height / 50));
    // ... and after r, exactly what a fresh start shows.
    std::ofstream(dir / "dragged.log", std::ios::app)
        << key_events({{"r", 'r'}}).substr(std::string("# StreamVersion 1\n").size());
    ASSERT_EQ(view("t.vti --events dragged.log --size 320x200 --screenshot reset.png").code, 0);
    ASSERT_EQ(view("t.vti --size 320x200 --screenshot fresh.png").code, 0);
    EXPECT_EQ(differing_pixels(read_picture(dir / "reset.png"), read_picture(dir / "fresh.png"), 0), 0u);
}

// --------------------------------------------------------------------- watch

TEST_F(Viewer, WatchReRunsTheSpecShowsErrorsKeepsTheLastGoodTerrainAndRecovers) {
    const fs::path spec = dir / "w.orogen";
    auto write_spec = [&](const std::string& body) {
        std::ofstream(dir / "tmp.orogen") << "orogen 1\nseed 3\ngrid 65 cell=10\n" << body;
        fs::rename(dir / "tmp.orogen", spec);  // as editors save: a new file in one step
    };
    const std::string good1 =
        "t = generate:diamond-square(roughness=0.5, amplitude=50)\nexport:vtk(t, path=\"t.vti\")\n";
    const std::string good2 =
        "t = generate:diamond-square(roughness=0.5, amplitude=400)\nexport:vtk(t, path=\"t.vti\")\n";
    const std::string bad = "t = generate:diamond-square(roughness=0.5, amplitude=400\nexport:vtk(t, path=\"t.vti\")\n";
    write_spec(good1);
    const std::string cmd = "cd '" + dir.string() +
        "' && '" OROGEN_VIEW
        "' w.orogen --watch --exit-after-reloads 4 "
        "--orogen '" OROGEN_CLI "' --out out --screenshot shot.png --size 320x240 >stdout 2>stderr";
    int status = -1;
    std::thread viewer([&] { status = std::system(cmd.c_str()); });
    auto wait_for = [&](const std::string& text) {
        for (int i = 0; i < 600; ++i) {
            if (slurp(dir / "stdout").find(text) != std::string::npos) return true;
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        return false;
    };
    const bool first = wait_for("reload 1: ok");
    if (first) write_spec(good2);
    const bool second = first && wait_for("reload 2: ok");
    if (second) write_spec(bad);
    const bool third = second && wait_for("reload 3: error");
    if (third) write_spec(good1);
    const bool fourth = third && wait_for("reload 4: ok");
    viewer.join();
    ASSERT_TRUE(fourth) << slurp(dir / "stdout") << slurp(dir / "stderr");
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;  // exits cleanly after the 4th load
    const std::string out = slurp(dir / "stdout");
    EXPECT_NE(out.find("w.orogen:4:"), std::string::npos) << out;  // file:line:col of the syntax error
    const Picture p1 = read_picture(dir / "shot-1.png"), p2 = read_picture(dir / "shot-2.png"),
                  p3 = read_picture(dir / "shot-3.png"), p4 = read_picture(dir / "shot-4.png");
    EXPECT_GT(differing_pixels(p1, p2), 2000u);  // the parameter change shows
    EXPECT_GT(differing_pixels(p2, p3), 200u);  // the error text shows
    // ... over the last good terrain: the lower right quarter is unchanged.
    std::size_t same = 0, total = 0;
    for (int y = 140; y < 220; ++y)
        for (int x = 170; x < 300; ++x, ++total) same += p2.at(x, y) == p3.at(x, y);
    EXPECT_GT(same, total * 95 / 100);
    EXPECT_LT(differing_pixels(p1, p4), 200u);  // recovered: the first terrain again, no error text
}

// ----------------------------------------------------------------- bad input

TEST_F(Viewer, BadInputGivesOneClearErrorAndExit2) {
    auto expect = [&](const std::string& args, const std::string& message, const std::string& prefix = "") {
        const Result r = view(args, prefix);
        EXPECT_EQ(r.code, 2) << args;
        EXPECT_EQ(r.err, "orogen-view: error: " + message + "\n") << args;
        EXPECT_EQ(r.out, "") << args;
    };
    expect("missing.vti", "cannot open 'missing.vti': no such file");
    std::ofstream(dir / "notes.txt") << "hello";
    expect("notes.txt",
           "cannot open 'notes.txt': unknown file type '.txt'; orogen-view opens .vti, .vtp, .pvd, .glb, .gltf, .png "
           "(16-bit heightmap), .r16, .r32 (with their .json sidecar), .tif/.tiff (GeoTIFF), .vrt and the .json index "
           "of export:tiles, and .orogen specs");
    fs::create_directories(dir / "empty");
    expect("empty",
           std::string("cannot open 'empty': the folder holds nothing orogen-view shows (") +
               ".vti, .vtp, .pvd, .glb, .gltf, .png (16-bit heightmap), .r16, .r32 (with their .json sidecar), "
               ".tif/.tiff (GeoTIFF), .vrt and the .json index of export:tiles, and .orogen specs)");
    const auto h = plain_and_plateau();
    formats::raw::write_raw(ConstGridView(h.data(), 65, 65, 10.0), dir / "t.r16");
    fs::remove(dir / "t.r16.json");
    expect("t.r16",
           "cannot show 't.r16': its sidecar 't.r16.json' is missing (a RAW file has no size or height range; "
           "export:raw writes both files: copy the .json along)");
    vtk::write_plates(moving_plates(), dir / "plates.pvd");
    fs::remove(dir / "plates_plates_000001.vtp");
    fs::remove(dir / "plates_collisions_000002.vtp");
    expect("plates.pvd",
           "'plates.pvd' lists 2 of its 6 frame files that are missing, the first 'plates_plates_000001.vtp'; copy the "
           "series' .vtp files along with the .pvd");
    // A truncated .vti: VTK's reader complains loudly; the user sees one line.
    write_vti(dir / "t.vti", h, 65, 65);
    fs::resize_file(dir / "t.vti", fs::file_size(dir / "t.vti") / 2);
    expect("t.vti", "cannot read 't.vti': the file is damaged (truncated?)");
    std::ofstream(dir / "locked.vti") << "x";
    fs::permissions(dir / "locked.vti", fs::perms::none);
    if (geteuid() != 0)  // root reads anything
        expect("locked.vti", "cannot read 'locked.vti': permission denied or unreadable (check its permissions)");
    write_vti(dir / "good.vti", h, 65, 65);
    const std::string hint =
        "; orogen-view renders through X: on a machine without a screen, run it under a virtual display, e.g. "
        "xvfb-run -a orogen-view FILE --screenshot out.png";
    expect("good.vti", "no X display (DISPLAY is not set)" + hint, "env -u DISPLAY");
    expect("good.vti", "cannot connect to the X display ':987'" + hint, "env DISPLAY=:987");
}

TEST_F(Viewer, GltfFromTheExporterOpens) {
    const std::string spec =
        "orogen 1\nseed 1\ngrid 65 cell=10\nt = generate:diamond-square(amplitude=100)\n"
        "export:gltf(t, path=\"t.glb\")\n";
    std::ofstream(dir / "g.orogen") << spec;
    const std::string run = "'" OROGEN_CLI "' run '" + (dir / "g.orogen").string() + "' --out '" + dir.string() +
        "' --quiet >/dev/null 2>&1";
    ASSERT_EQ(std::system(run.c_str()), 0);
    const Result r = view("t.glb --screenshot g.png " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    const Picture p = read_picture(dir / "g.png");
    EXPECT_GT(distance(patch(p, 160, 160), patch(p, 6, 6)), 20);
    std::ofstream(dir / "bad.glb") << "not a glb";
    const Result bad = view("bad.glb --screenshot b.png");
    EXPECT_EQ(bad.code, 2);
    EXPECT_EQ(bad.err, "orogen-view: error: cannot read 'bad.glb': not a valid glTF file, or it holds no mesh\n");
}

}  // namespace

// ------------------------------------------------- legends and GIS files (issue 32, item 9)

namespace {

/// "x0,y0,x1,y1" of a state line as four numbers (pixels from the bottom left).
std::array<int, 4> box(const std::string& text) {
    std::array<int, 4> b{};
    std::sscanf(text.c_str(), "%d,%d,%d,%d", &b[0], &b[1], &b[2], &b[3]);
    return b;
}

}  // namespace

TEST_F(Viewer, DrainageIsInSquareMetresOnALogColourScale) {
    // Drainage area from one 30 m cell (900 m²) to 9·10⁷ m², ten times more every eighth of the way east.
    const int n = 65;
    std::vector<float> drainage(std::size_t(n) * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) drainage[std::size_t(y) * n + x] = float(900.0 * std::pow(10.0, 5.0 * x / (n - 1)));
    write_vti(dir / "t.vti", plain_and_plateau(), n, n, {{"drainage", drainage}});
    const Result r = view("t.vti --events /dev/null --print-state --layer drainage --screenshot d.png " + top_view);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(state_value(r.out, "legend"), "drainage (m², log scale)");
    // On a log scale each decade gets its share of the colours: a fifth of the map apart, colours differ
    // (a linear map puts everything below a tenth of the top, four fifths of this map, in one colour).
    const auto map = box(state_value(r.out, "map_box"));
    const Picture p = read_picture(dir / "d.png");
    const int row = p.height - (map[1] + map[3]) / 2;
    auto at = [&](double f) { return patch(p, int(map[0] + f * (map[2] - map[0])), row); };
    EXPECT_GT(distance(at(0.2), at(0.4)), 40);
    EXPECT_GT(distance(at(0.4), at(0.6)), 40);
    EXPECT_GT(distance(at(0.6), at(0.8)), 40);
}

TEST_F(Viewer, TheColourScaleStaysClearOfTheMapInTopView) {
    std::vector<float> flow(65 * 65);
    for (std::size_t i = 0; i < flow.size(); ++i) flow[i] = float(i % 65);
    write_vti(dir / "t.vti", plain_and_plateau(), 65, 65, {{"flow", flow}});
    for (const char* size : {"320x320", "640x400", "400x640", "1280x800"}) {
        const Result r = view(std::string("t.vti --events /dev/null --print-state --layer flow --top --size ") + size);
        ASSERT_EQ(r.code, 0) << r.err;
        ASSERT_EQ(state_value(r.out, "legend"), "flow (m/s)");
        const auto map = box(state_value(r.out, "map_box")), legend = box(state_value(r.out, "legend_box"));
        const bool apart = legend[3] <= map[1] || legend[0] >= map[2] || legend[2] <= map[0];
        EXPECT_TRUE(apart) << size << ": map " << state_value(r.out, "map_box") << ", legend "
                           << state_value(r.out, "legend_box");
        EXPECT_GT(map[3] - map[1], 100) << size;  // and the map is still a map
    }
}

TEST_F(Viewer, OpensTheGeoTiffAndTheTilesOfARunAsItsVti) {
    std::ofstream(dir / "gis.orogen") << "orogen 1\nseed 5\ngrid 65 cell=10\n"
                                         "t = generate:diamond-square(roughness=0.6, amplitude=200)\n"
                                         "w = erode:thermal(t, iterations=3)\n"
                                         "export:vtk(w, path=\"t.vti\")\n"
                                         "export:geotiff(w, path=\"t.tif\", layers=all)\n"
                                         "export:tiles(w, path=\"tiles/t.json\", tile_size=33)\n";
    const std::string run =
        "cd '" + dir.string() + "' && OROGEN_NO_CACHE=1 '" OROGEN_CLI "' run gis.orogen --out . --quiet";
    ASSERT_EQ(std::system(run.c_str()), 0);
    for (const char* input : {"t.vti", "t.tif", "tiles/t.vrt", "tiles/t.json"}) {
        const Result r =
            view(std::string(input) + " --screenshot " + fs::path(input).filename().string() + ".png " + top_view);
        ASSERT_EQ(r.code, 0) << input << ": " << r.err;
    }
    // The map (above the status line, which names the file): compared pixel by pixel.
    auto map_of = [](Picture p) {
        p.height -= 100;
        return p;
    };
    const Picture vti = map_of(read_picture(dir / "t.vti.png"));
    EXPECT_EQ(differing_pixels(vti, map_of(read_picture(dir / "t.tif.png")), 0), 0u);  // the same floats
    // 16-bit tiles: heights within a 65535th of the range, the same picture but for rounding.
    EXPECT_LT(differing_pixels(vti, map_of(read_picture(dir / "t.vrt.png"))), 200u);
    EXPECT_EQ(differing_pixels(map_of(read_picture(dir / "t.vrt.png")), map_of(read_picture(dir / "t.json.png")), 0),
              0u);
    // The GeoTIFF's bands are the layers, by name.
    const Result layer = view("t.tif --events /dev/null --print-state --layer eroded --top --size 200x200");
    ASSERT_EQ(layer.code, 0) << layer.err;
    EXPECT_EQ(state_value(layer.out, "legend"), "eroded (m)");
    // A folder holding only a GeoTIFF shows it.
    fs::create_directories(dir / "only");
    fs::copy_file(dir / "t.tif", dir / "only/t.tif");
    EXPECT_EQ(view("only --screenshot only.png " + top_view).code, 0);
    EXPECT_EQ(differing_pixels(vti, map_of(read_picture(dir / "only.png")), 0), 0u);
}
