// app.cpp — orogen-view: the command line, keys, spec runs and --watch.
//
//   orogen-view FILE...                 look at orogen outputs
//   orogen-view SPEC.orogen [--watch]   run the spec with the orogen CLI, show its outputs, re-run on save
//   ... --screenshot out.png            render offscreen, write the picture, exit
//
// Exit codes as orogen's: 0 fine, 2 bad input (file, option, spec, no display), 1 anything else.
#include "reader.hpp"
#include "scene.hpp"

#include <orogen/error.hpp>
#include <orogen/session.hpp>

#include <X11/Xlib.h>
#include <vtkCallbackCommand.h>
#include <vtkInteractorEventRecorder.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace orogen::view {
namespace {

const char* const usage =
    "usage: orogen-view FILE... [options]\n"
    "       orogen-view SPEC.orogen [--watch] [--out DIR] [options]\n"
    "\n"
    "FILE: .vti / .vtp terrain (every layer), .glb / .gltf, .pvd series (plates, particles),\n"
    "      16-bit .png or .r16 / .r32 (+ .json sidecar) heightmaps.\n"
    "SPEC: run with the orogen CLI (into --out DIR, else a temporary folder) and show its outputs;\n"
    "      --watch re-runs it whenever the file changes, keeping the camera.\n"
    "\n"
    "options:\n"
    "  --screenshot OUT.png   render offscreen, write the picture and exit\n"
    "  --size WxH             window / picture size in pixels (default 1280x800)\n"
    "  --camera AZ,EL[,DIST]  camera bearing and elevation in degrees, distance in metres\n"
    "  --top                  top-down hillshade map (orthographic)\n"
    "  --layer NAME           colour by this layer (splat, height, water, flow, plate, ...)\n"
    "  --time T               show the series frame at or before time T\n"
    "  --exaggeration E       vertical exaggeration (default 1)\n"
    "  --full                 full mesh resolution for terrains over 257 samples a side\n"
    "  --no-refine            keep the decimated mesh however close the camera (default: finer in view when zoomed)\n"
    "  --no-water             start with the water surface hidden (key w)\n"
    "  --orogen PATH          the orogen CLI to run specs with (default: beside orogen-view)\n"
    "  --timing               print the time to the first frame and to switch to each layer\n"
    "  -h, --help             this text; in the window, press h for the keys\n";

/// VTK's own warnings and errors go here instead of a stderr dump (or a
/// window); the viewer reports problems in its own words. Set
/// OROGEN_VIEW_VTK_LOG=1 to see them.
class QuietOutputWindow : public vtkOutputWindow {
public:
    static QuietOutputWindow* New();
    vtkTypeMacro(QuietOutputWindow, vtkOutputWindow);
    void DisplayText(const char* text) override {
        if (std::getenv("OROGEN_VIEW_VTK_LOG")) std::cerr << "[vtk] " << text;
    }
};
vtkStandardNewMacro(QuietOutputWindow);

struct Options {
    std::vector<fs::path> files;
    std::optional<fs::path> spec;
    std::string screenshot;
    int width = 1280, height = 800;
    std::optional<CameraAngles> camera;
    bool top = false;
    std::string layer;
    std::optional<double> time;
    double exaggeration = 1.0;
    bool full = false;
    bool refine = true;
    bool no_water = false;
    bool watch = false;
    fs::path out;
    fs::path orogen;
    bool timing = false;
    // For tests: replay a VTK event log, print the settings, exit after N (re)loads.
    std::string events;
    bool print_state = false;
    int exit_after_reloads = 0;
};

double number(const std::string& option, const std::string& text) {
    try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size() && std::isfinite(v)) return v;
    } catch (const std::exception&) {}
    throw BadInput(option + " expects a number, got '" + text + "'");
}

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw BadInput(a + " needs a value; see orogen-view --help");
            return argv[++i];
        };
        if (a == "-h" || a == "--help") {
            std::cout << usage;
            std::exit(0);
        } else if (a == "--screenshot") {
            o.screenshot = value();
        } else if (a == "--size") {
            const std::string v = value();
            const auto x = v.find('x');
            if (x == std::string::npos)
                throw BadInput("--size expects WIDTHxHEIGHT in pixels, e.g. 1280x800; got '" + v + "'");
            const double w = number("--size", v.substr(0, x)), h = number("--size", v.substr(x + 1));
            if (w < 16 || h < 16 || w > 8192 || h > 8192 || w != std::floor(w) || h != std::floor(h))
                throw BadInput("--size: width and height must be whole numbers from 16 to 8192, got '" + v + "'");
            o.width = int(w);
            o.height = int(h);
        } else if (a == "--camera") {
            std::stringstream v(value());
            std::vector<double> parts;
            for (std::string p; std::getline(v, p, ',');) parts.push_back(number("--camera", p));
            if (parts.size() < 2 || parts.size() > 3)
                throw BadInput("--camera expects AZIMUTH,ELEVATION[,DISTANCE] (degrees, degrees, metres)");
            o.camera = CameraAngles{parts[0], parts[1], parts.size() == 3 ? parts[2] : 0.0};
        } else if (a == "--top") {
            o.top = true;
        } else if (a == "--layer") {
            o.layer = value();
        } else if (a == "--time") {
            o.time = number("--time", value());
        } else if (a == "--exaggeration") {
            o.exaggeration = number("--exaggeration", value());
            if (!(o.exaggeration > 0)) throw BadInput("--exaggeration must be above 0");
        } else if (a == "--no-water") {
            o.no_water = true;
        } else if (a == "--full") {
            o.full = true;
        } else if (a == "--no-refine") {
            o.refine = false;
        } else if (a == "--watch") {
            o.watch = true;
        } else if (a == "--out") {
            o.out = value();
        } else if (a == "--orogen") {
            o.orogen = value();
        } else if (a == "--timing") {
            o.timing = true;
        } else if (a == "--events") {
            o.events = value();
        } else if (a == "--print-state") {
            o.print_state = true;
        } else if (a == "--exit-after-reloads") {
            o.exit_after_reloads = int(number(a, value()));
        } else if (a.size() > 1 && a[0] == '-') {
            throw BadInput("unknown option '" + a + "'; see orogen-view --help");
        } else if (fs::path(a).extension() == ".orogen") {
            if (o.spec) throw BadInput("give one spec at a time (got '" + o.spec->string() + "' and '" + a + "')");
            o.spec = a;
        } else {
            o.files.emplace_back(a);
        }
    }
    if (o.files.empty() && !o.spec) throw BadInput("nothing to show: give a file or a spec; see orogen-view --help");
    if (o.spec && !o.files.empty()) throw BadInput("give either a spec or files, not both");
    if (o.watch && !o.spec) throw BadInput("--watch re-runs a spec: give a .orogen file");
    if (!o.out.empty() && !o.spec) throw BadInput("--out is where a spec's outputs go: give a .orogen file");
    return o;
}

/// Closes the X connection after the render window that used it is gone.
struct CloseDisplay {
    void operator()(Display* d) const { XCloseDisplay(d); }
};
using DisplayPtr = std::unique_ptr<Display, CloseDisplay>;

/// The X connection VTK renders through (VTK opens an X window even
/// offscreen). Opened here, not by VTK: VTK aborts the process when its own
/// XOpenDisplay fails, and under a busy Xvfb a connection is now and then
/// refused (about 1 in 150 runs of the tests on a loaded machine): a few
/// retries 50 ms apart, then one clear error.
DisplayPtr open_display() {
    const char* name = std::getenv("DISPLAY");
    const std::string hint =
        "; orogen-view renders through X: on a machine without a screen, run it under a virtual display, "
        "e.g. xvfb-run -a orogen-view FILE --screenshot out.png";
    if (!name || !*name) throw BadInput(std::string("no X display (DISPLAY is not set)") + hint);
    for (int attempt = 0; attempt < 10; ++attempt) {
        if (Display* d = XOpenDisplay(nullptr)) return DisplayPtr(d);
        usleep(50000);
    }
    throw BadInput("cannot connect to the X display '" + std::string(name) + "'" + hint);
}

fs::path self_dir() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path() : exe.parent_path();
}

/// A run of `orogen run SPEC --out DIR`, stdout and stderr into a log file. The spec is checked first in
/// this process, through the kernel's Session (App::check_spec); the run itself is a child process: the
/// render passes draw through OSMesa's GL, whose gl* symbols would resolve to VTK's X GL in this process,
/// and a run that fails hard must not take the viewer, and the last good terrain, with it.
class SpecRun {
public:
    SpecRun(const fs::path& orogen, const fs::path& spec, const fs::path& out) : log_(out / ".orogen-view.log") {
        fs::create_directories(out);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
        std::vector<std::string> args{orogen.string(), "run", spec.string(), "--out", out.string(), "--quiet"};
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        const int err = posix_spawnp(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        if (err != 0)
            throw BadInput("cannot run the orogen CLI '" + orogen.string() + "': " + std::strerror(err) +
                           " (give its path with --orogen)");
    }
    /// The exit code once finished (nullopt while running); `wait` blocks.
    std::optional<int> finished(bool wait) {
        int status = 0;
        const pid_t r = waitpid(pid_, &status, wait ? 0 : WNOHANG);
        if (r == 0) return std::nullopt;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
    }
    std::string log() const {
        std::ifstream in(log_);
        std::stringstream s;
        s << in.rdbuf();
        return s.str();
    }

private:
    pid_t pid_ = 0;
    fs::path log_;
};

class App;

/// Trackball camera, with VTK's own one-letter keys (w wireframe, e exit, ...) replaced by ours.
class KeyStyle : public vtkInteractorStyleTrackballCamera {
public:
    static KeyStyle* New();
    vtkTypeMacro(KeyStyle, vtkInteractorStyleTrackballCamera);
    std::function<void(const std::string&)> on_key;
    void OnChar() override {}
    void OnKeyPress() override {
        if (on_key && Interactor->GetKeySym()) on_key(Interactor->GetKeySym());
    }
};
vtkStandardNewMacro(KeyStyle);

class App {
public:
    explicit App(Options o) : o_(std::move(o)) {}

    int run() {
        Content first;
        if (!o_.spec) first = read_files(o_.files);  // bad files are reported before any window opens
        else if (!fs::exists(*o_.spec)) throw BadInput("cannot open '" + o_.spec->string() + "': no such file");
        display_ = open_display();
        window_->SetDisplayId(display_.get());
        window_->SetSize(o_.width, o_.height);
        window_->SetWindowName("orogen-view");
        window_->SetMultiSamples(0);
        const bool offscreen = !o_.screenshot.empty() && !o_.watch && o_.events.empty();
        window_->SetOffScreenRendering(offscreen);
        scene_ = std::make_unique<Scene>(window_);

        if (o_.spec) {
            out_ = o_.out;
            if (out_.empty()) {
                std::string tmpl = (fs::temp_directory_path() / "orogen-view-XXXXXX").string();
                if (!mkdtemp(tmpl.data())) throw Error("cannot create a temporary folder for the spec's outputs");
                out_ = tmpl;
                temporary_out_ = true;
            }
            orogen_ = o_.orogen.empty() ? self_dir() / "orogen" : o_.orogen;
            if (o_.orogen.empty() && !fs::exists(orogen_)) orogen_ = "orogen";
            if (!o_.watch) {
                if (const std::string problems = check_spec(); !problems.empty()) {
                    std::cerr << problems;
                    return 2;
                }
                SpecRun run(orogen_, *o_.spec, out_);
                const int code = *run.finished(true);
                if (code != 0) {
                    std::cerr << run.log();
                    return code;
                }
                first = outputs();
            }
        }
        if (!o_.watch) {
            show(std::move(first), false);
            apply_options();
        } else {
            scene_->set_message("running " + o_.spec->filename().string() + " ...", false);
            start_run();
        }
        if (!o_.screenshot.empty() && !o_.watch && o_.events.empty()) {
            scene_->screenshot(o_.screenshot);  // renders once
            if (o_.timing) timing_report();
            return 0;
        }
        scene_->render();
        if (o_.timing) timing_report();
        interactor_->SetRenderWindow(window_);
        style_->on_key = [this](const std::string& k) { key(k); };
        interactor_->SetInteractorStyle(style_);
        // After a drag or a wheel step, refine the mesh for the new view once
        // the camera has been still for a moment (not on every wheel click).
        vtkNew<vtkCallbackCommand> moved;
        moved->SetClientData(this);
        moved->SetCallback([](vtkObject*, unsigned long, void* app, void*) {
            static_cast<App*>(app)->last_interaction_ = Clock::now();
            static_cast<App*>(app)->refine_pending_ = true;
        });
        style_->AddObserver(vtkCommand::EndInteractionEvent, moved);
        // A coarser mesh while the camera moves, the full one for the still frame.
        vtkNew<vtkCallbackCommand> start, end;
        start->SetClientData(this);
        start->SetCallback(
            [](vtkObject*, unsigned long, void* app, void*) { static_cast<App*>(app)->scene_->set_moving(true); });
        end->SetClientData(this);
        end->SetCallback(
            [](vtkObject*, unsigned long, void* app, void*) { static_cast<App*>(app)->scene_->set_moving(false); });
        style_->AddObserver(vtkCommand::StartInteractionEvent, start);
        style_->AddObserver(vtkCommand::EndInteractionEvent, end);
        interactor_->Initialize();
        if (!o_.events.empty()) return replay();
        vtkNew<vtkCallbackCommand> tick;
        tick->SetClientData(this);
        tick->SetCallback([](vtkObject*, unsigned long, void* app, void*) { static_cast<App*>(app)->tick(); });
        interactor_->AddObserver(vtkCommand::TimerEvent, tick);
        interactor_->CreateRepeatingTimer(100);
        interactor_->Start();
        return exit_code_;
    }

    ~App() {
        if (temporary_out_) {
            std::error_code ec;
            fs::remove_all(out_, ec);
        }
    }

private:
    Options o_;
    DisplayPtr display_;  // before window_: closed after it
    vtkNew<vtkRenderWindow> window_;
    vtkNew<vtkRenderWindowInteractor> interactor_;
    vtkNew<KeyStyle> style_;
    std::unique_ptr<Scene> scene_;
    fs::path out_, orogen_;
    bool temporary_out_ = false;
    std::unique_ptr<SpecRun> running_;
    std::unique_ptr<Session> session_;  // the kernel, to check the spec before each run (check_spec)
    fs::file_time_type spec_time_{};
    std::uintmax_t spec_size_ = 0;
    int reloads_ = 0;
    bool loaded_ = false;
    bool options_applied_ = false;
    int exit_code_ = 0;
    Clock::time_point last_step_ = Clock::now();
    Clock::time_point last_interaction_ = Clock::now();
    bool refine_pending_ = false;

    /// Whether the command line names a run's outputs as a whole (a spec, or an output folder).
    bool opened_outputs() const {
        if (o_.spec) return true;
        std::error_code ec;
        return std::any_of(o_.files.begin(), o_.files.end(),
                           [&](const fs::path& f) { return fs::is_directory(f, ec); });
    }

    Content outputs() {
        const auto files = pick_outputs(out_);
        if (files.empty())
            throw BadInput("'" + o_.spec->string() + "' wrote nothing orogen-view can show; add an export, e.g. " +
                           "export:vtk(terrain, path=\"terrain.vti\")");
        return read_files(files);
    }

    void show(Content c, bool keep_camera) {
        const bool first = !loaded_;
        scene_->show(std::move(c), keep_camera);
        // A run's whole output (a folder, a spec) opens on its terrain, the plates a key away ('m'); plates
        // named on the command line are what was asked to see.
        if (first && opened_outputs() && scene_->has_terrain()) scene_->set_plates(false);
        loaded_ = true;
    }

    void apply_options() {
        if (!o_.layer.empty() && !scene_->set_layer(o_.layer)) {
            std::string names;
            for (const auto& n : scene_->layer_names()) names += (names.empty() ? "" : ", ") + n;
            throw BadInput("no layer '" + o_.layer + "' to colour by; this terrain has: " + names);
        }
        if (o_.time) {
            if (scene_->times().empty()) throw BadInput("--time: nothing shown is a time series (.pvd)");
            scene_->set_time(*o_.time);
        }
        if (o_.full) scene_->set_full_resolution(true);
        if (!o_.refine) scene_->set_refine_on_zoom(false);
        if (o_.no_water) scene_->toggle_water();
        if (o_.exaggeration != 1.0) scene_->set_exaggeration(o_.exaggeration);
        if (o_.camera || o_.top) {
            if (o_.camera) scene_->set_camera(*o_.camera);
            if (o_.top) scene_->toggle_top_view();
        }
    }

    /// Wall and CPU (all threads, llvmpipe's too) milliseconds: on a shared
    /// machine the CPU time is the figure that does not depend on the load.
    void timing_report() {
        std::cout << "first frame: " << ms_since_process_start() << " ms wall, " << cpu_ms() << " ms CPU\n";
        auto ms = [](Clock::time_point a, Clock::time_point b) {
            return std::chrono::duration<double, std::milli>(b - a).count();
        };
        // Twice round: the first switch to a layer maps its colours, a switch back uploads the kept texture.
        for (const char* round : {"", " (again)"}) {
            std::vector<double> walls, cpus;
            for (const auto& name : scene_->layer_names()) {
                const auto t0 = Clock::now();
                const double c0 = cpu_ms();
                scene_->set_layer(name);
                const auto t1 = Clock::now();
                const double c1 = cpu_ms();
                scene_->render();
                const auto t2 = Clock::now();
                const double c2 = cpu_ms();
                std::cout << "layer " << name << round << ": " << ms(t0, t2) << " ms wall, " << c2 - c0
                          << " ms CPU (colour " << ms(t0, t1) << " ms wall " << c1 - c0 << " ms CPU, render "
                          << ms(t1, t2) << " ms wall " << c2 - c1 << " ms CPU)\n";
                walls.push_back(ms(t0, t2));
                cpus.push_back(c2 - c0);
            }
            auto median = [](std::vector<double> v) {
                std::sort(v.begin(), v.end());
                return v[v.size() / 2];
            };
            std::cout << "layer switch" << (*round ? round : " (first time)") << ": median " << median(walls)
                      << " ms wall, " << median(cpus) << " ms CPU; min "
                      << *std::min_element(walls.begin(), walls.end()) << " ms wall, "
                      << *std::min_element(cpus.begin(), cpus.end()) << " ms CPU\n";
        }
        scene_->set_layer(o_.layer.empty() ? "splat" : o_.layer);
        scene_->render();
        double best_wall = 1e9, best_cpu = 1e9;
        for (int r = 0; r < 5; ++r) {
            const auto t0 = Clock::now();
            const double c0 = cpu_ms();
            scene_->render();
            best_wall = std::min(best_wall, ms(t0, Clock::now()));
            best_cpu = std::min(best_cpu, cpu_ms() - c0);
        }
        std::cout << "render, nothing changed (min of 5): " << best_wall << " ms wall, " << best_cpu << " ms CPU\n";
    }

    static double cpu_ms() {
        timespec t{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
        return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
    }

    static double ms_since_process_start() {
        std::ifstream stat("/proc/self/stat");
        std::string s((std::istreambuf_iterator<char>(stat)), {});
        std::istringstream fields(s.substr(s.rfind(')') + 2));
        std::string f;
        for (int i = 3; i <= 22; ++i) fields >> f;  // field 22: start time in clock ticks after boot
        const double start = std::stod(f) / double(sysconf(_SC_CLK_TCK));
        std::ifstream up("/proc/uptime");
        double uptime = 0;
        up >> uptime;
        return (uptime - start) * 1000.0;
    }

    /// The spec's mistakes, every one at once with file:line:col and the count line, as `orogen run` would
    /// report them into out_ ("" if there are none), from the kernel's Session: a spec that cannot run is
    /// not run. The plugins are loaded once, from the folder of the orogen the runs use.
    std::string check_spec() {
        if (!session_) {
            std::error_code ec;
            session_ = std::make_unique<Session>(fs::exists(orogen_, ec) ? orogen_ : self_dir() / "orogen-view");
        }
        CheckSettings settings;
        settings.out_dir = out_;
        const Checked checked = session_->check(SpecText::read(*o_.spec), settings);
        return checked.ok() ? std::string() : checked.report().text_with_count();
    }

    void start_run() {
        std::error_code ec;
        spec_time_ = fs::last_write_time(*o_.spec, ec);
        spec_size_ = fs::file_size(*o_.spec, ec);
        std::string problems;
        try {
            problems = check_spec();
        } catch (const std::exception& e) { problems = std::string(e.what()) + "\n"; }  // unreadable mid-save
        if (!problems.empty()) return finish_run(2, problems);  // shown at once, over the last good terrain
        running_ = std::make_unique<SpecRun>(orogen_, *o_.spec, out_);
    }

    void tick() {
        if (scene_->playing() && Clock::now() - last_step_ > std::chrono::milliseconds(250)) {
            last_step_ = Clock::now();
            step_time(1, true);
        }
        const bool still =
            style_->GetState() == VTKIS_NONE && Clock::now() - last_interaction_ > std::chrono::milliseconds(200);
        if (still && refine_pending_) {
            refine_pending_ = false;
            if (scene_->refine()) scene_->render();
        } else if (still && !scene_->playing()) {
            scene_->prefetch();  // idle: colour the next layer before it is asked for (~15 ms at 1025²)
        }
        if (!o_.watch) return;
        if (running_) {
            const auto code = running_->finished(false);
            if (!code) return;
            const std::string log = running_->log();
            running_.reset();
            finish_run(*code, log);
            return;
        }
        std::error_code ec;
        const auto t = fs::last_write_time(*o_.spec, ec);
        const auto size = fs::file_size(*o_.spec, ec);
        if (!ec && (t != spec_time_ || size != spec_size_)) {
            scene_->set_message("running " + o_.spec->filename().string() + " ...", false);
            scene_->render();
            start_run();
        }
    }

    void finish_run(int code, const std::string& log) {
        ++reloads_;
        std::string error;
        if (code == 0) {
            try {
                show(outputs(), loaded_);
                if (!options_applied_) apply_options();
                options_applied_ = true;
            } catch (const std::exception& e) { error = e.what(); }
        } else {
            error = log.empty() ? "orogen exited with code " + std::to_string(code) : log;
        }
        // Errors stay on screen over the last good terrain until a run succeeds.
        scene_->set_message(
            error.empty() ? "" : trim_lines(error, 14) + (loaded_ ? "\n(showing the last good run)" : ""), true);
        scene_->render();
        std::cout << "reload " << reloads_ << ": " << (error.empty() ? "ok" : "error") << "\n";
        if (!error.empty()) std::cout << error << (error.back() == '\n' ? "" : "\n");
        std::cout.flush();
        if (!o_.screenshot.empty()) {
            const fs::path s = o_.screenshot;
            scene_->screenshot(
                (s.parent_path() / (s.stem().string() + "-" + std::to_string(reloads_) + ".png")).string());
        }
        if (o_.exit_after_reloads > 0 && reloads_ >= o_.exit_after_reloads)
            interactor_->SetDone(true);  // not TerminateApp(): in VTK 9.1 it crashes the X event loop from a callback
    }

    static std::string trim_lines(const std::string& text, int max) {
        std::istringstream in(text);
        std::string line, out;
        int n = 0;
        while (std::getline(in, line) && n < max) out += (n++ ? "\n" : "") + line;
        return out;
    }

    void step_time(int by, bool wrap) {
        const auto& ts = scene_->times();
        if (ts.empty()) return;
        long i = long(scene_->time_index()) + by;
        if (wrap) i = (i % long(ts.size()) + long(ts.size())) % long(ts.size());
        scene_->set_time_index(std::size_t(std::clamp(i, 0L, long(ts.size()) - 1)));
        scene_->render();
    }

    void key(const std::string& k) {
        if (k == "h" || k == "question") scene_->toggle_help();
        else if (k == "l") scene_->cycle_layer(1);
        else if (k == "L") scene_->cycle_layer(-1);
        else if (k == "w") scene_->toggle_water();
        else if (k == "p") scene_->toggle_particles();
        else if (k == "a") scene_->cycle_particle_attribute();
        else if (k == "m") scene_->toggle_plates();
        else if (k == "e") scene_->toggle_edges();
        else if (k == "v") scene_->toggle_top_view();
        else if (k == "r") scene_->reset_camera();
        else if (k == "f") scene_->set_full_resolution(!scene_->full_resolution());
        else if (k == "plus" || k == "equal" || k == "KP_Add") scene_->set_exaggeration(scene_->exaggeration() * 1.25);
        else if (k == "minus" || k == "KP_Subtract") scene_->set_exaggeration(scene_->exaggeration() / 1.25);
        else if (k == "space") scene_->set_playing(!scene_->playing());
        else if (k == "period" || k == "Right") step_time(1, false);
        else if (k == "comma" || k == "Left") step_time(-1, false);
        else if (k == "s") {
            int n = 1;
            while (fs::exists("orogen-view-" + std::to_string(n) + ".png")) ++n;
            const std::string file = "orogen-view-" + std::to_string(n) + ".png";
            scene_->screenshot(file);
            scene_->set_message("saved " + file, false);
        } else if (k == "q" || k == "Escape") {
            interactor_->SetDone(true);  // not TerminateApp(): in VTK 9.1 it crashes the X event loop from a callback
            return;
        } else {
            return;
        }
        scene_->render();
    }

    int replay() {
        std::ifstream in(o_.events);
        if (!in) throw BadInput("cannot read the event log '" + o_.events + "'");
        std::stringstream s;
        s << in.rdbuf();
        vtkNew<vtkInteractorEventRecorder> recorder;
        recorder->SetInteractor(interactor_);
        recorder->ReadFromInputStringOn();
        recorder->SetInputString(s.str().c_str());
        recorder->Play();
        scene_->render();
        if (o_.print_state) std::cout << scene_->state();
        if (!o_.screenshot.empty()) scene_->screenshot(o_.screenshot);
        return 0;
    }
};

}  // namespace
}  // namespace orogen::view

int main(int argc, char** argv) {
    vtkNew<orogen::view::QuietOutputWindow> quiet;
    vtkOutputWindow::SetInstance(quiet);
    // VTK 9 also logs errors through loguru straight to stderr.
    if (!std::getenv("OROGEN_VIEW_VTK_LOG")) vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    try {
        orogen::view::App app(orogen::view::parse(argc, argv));
        return app.run();
    } catch (const orogen::Error& e) {
        std::cerr << "orogen-view: error: " << e.what() << "\n";
        return e.kind() == orogen::Error::Kind::bad_input ? 2 : 1;
    } catch (const std::exception& e) {
        std::cerr << "orogen-view: error: " << e.what() << "\n";
        return 1;
    }
}
