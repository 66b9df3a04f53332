// orogen._orogen — the kernel driven from Python (pybind11): the same loader, checker and runner as the
// `orogen` command (kernel/cli/main.cpp), values handed back as numpy arrays. See docs/python.md.
//
//   run(spec, seed=None, set={}, threads=None, out=None, progress=False, values=None, outputs=True) -> {name: value}
//   nodes() -> [{"name", "kind", "summary"}];  help(name) -> {...}
//   _run_node(spec, inputs, threads) -> {name: value}: orogen.node() (orogen/__init__.py) runs the spec it
//   writes with its inputs bound by name (orogen/session.hpp BoundValues): no file, one copy of an array at most.
//
// Bad input (a spec error, a parameter out of range, a file refused at check time) raises ValueError with
// the CLI's message; a failed run RuntimeError naming the node; Ctrl-C stops the node as on the command
// line and raises KeyboardInterrupt. The run itself happens on a thread of its own with the GIL released.
#include <orogen/error.hpp>
#include <orogen/io.hpp>
#include <orogen/session.hpp>
#include <orogen/landscape/loop.hpp>
#include <orogen/landscape/uplift.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <future>
#include <sstream>
#include <thread>

#include <dlfcn.h>
#include <unistd.h>

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace orogen;

namespace {

/// The plugins, loaded once from the build or install tree (found from this module's own file) and
/// OROGEN_PLUGIN_PATH; never unloaded (values may hold code of theirs until the interpreter ends).
const Session& plugins() {
    static const Session* set = [] {
        Dl_info info{};
        fs::path here = ::dladdr(reinterpret_cast<void*>(&plugins), &info) && info.dli_fname
            ? fs::absolute(info.dli_fname)
            : fs::current_path() / "orogen";
        // The loader searches <bin>/../lib/orogen/plugins for the binary's path it is given: from the build
        // tree's <build>/python/orogen/_orogen.so that is <build>/bin/orogen, from an installed
        // <prefix>/lib/python3.X/dist-packages/orogen/_orogen.so <prefix>/bin/orogen (and the kernel's own
        // install prefix in either case).
        const fs::path build = here.parent_path().parent_path().parent_path();
        const fs::path installed = build.parent_path().parent_path();
        std::error_code ec;
        auto* s = new Session((fs::is_directory(build / "lib" / "orogen" / "plugins", ec) ? build : installed) / "bin" /
                              "orogen");
        for (const auto& p : s->plugin_problems()) {
            const std::string text = "orogen: plugin " + p;
            PyErr_WarnEx(PyExc_RuntimeWarning, text.c_str(), 1);
        }
        return s;
    }();
    return *set;
}

// ------------------------------------------------------------------ values

/// A read-only numpy view of `data` that keeps `owner` alive: no copy.
py::array view(const void* data, py::dtype dtype, std::vector<py::ssize_t> shape, std::shared_ptr<const void> owner) {
    auto* keep = new std::shared_ptr<const void>(std::move(owner));
    py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<const void>*>(p); });
    py::array a(dtype, shape, {}, data, base);
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

py::array float_grid(const float* data, int w, int h, std::shared_ptr<const void> owner) {
    return view(data, py::dtype::of<float>(), {h, w}, std::move(owner));
}

/// A heightmap: `height` (rows north to south), `layers`, `cell`, all views of orogen's memory.
struct PyHeightmap {
    std::shared_ptr<const Heightmap> hm;
};

struct PySeries {
    std::shared_ptr<const Series> series;
};

py::object to_python(const Value& v);

py::object particles_to_python(const std::shared_ptr<const ParticleSeries>& ps) {
    py::list frames;
    for (const ParticleFrame& f : ps->frames) {
        py::dict attributes;
        const auto n = py::ssize_t(f.count());
        for (const auto& [name, a] : f.attributes)
            attributes[py::str(name)] = view(a.data.data(), py::dtype::of<float>(), {n, a.components}, ps);
        py::dict frame;
        frame["time"] = f.time;
        frame["step"] = f.step;
        frame["attributes"] = attributes;
        frames.append(frame);
    }
    return frames;
}

py::object plates_to_python(const PlateHistory& p) {
    py::list snapshots;
    for (const auto& s : p.snapshots) {
        py::list plates;
        for (const auto& st : s.plates) {
            py::array_t<double> polygon({py::ssize_t(st.polygon.size()), py::ssize_t(2)});
            auto m = polygon.mutable_unchecked<2>();
            for (std::size_t i = 0; i < st.polygon.size(); ++i) {
                m(py::ssize_t(i), 0) = st.polygon[i].x;
                m(py::ssize_t(i), 1) = st.polygon[i].y;
            }
            py::dict d;
            d["id"] = st.id;
            d["polygon"] = polygon;
            d["velocity"] = py::make_tuple(st.velocity.x, st.velocity.y);
            d["density"] = st.density;
            plates.append(d);
        }
        py::dict d;
        d["step"] = s.step;
        d["time"] = s.time;
        d["plates"] = plates;
        snapshots.append(d);
    }
    py::list collisions;
    for (const auto& c : p.collisions) {
        py::dict d;
        d["step"] = c.step;
        d["plates"] = py::make_tuple(c.plate_a, c.plate_b);
        d["a"] = py::make_tuple(c.a.x, c.a.y);
        d["b"] = py::make_tuple(c.b.x, c.b.y);
        d["kind"] = c.kind == BoundaryKind::convergent ? "convergent"
            : c.kind == BoundaryKind::divergent        ? "divergent"
                                                       : "transform";
        d["impulse"] = c.impulse;
        collisions.append(d);
    }
    py::dict d;
    d["width"] = p.width;
    d["height"] = p.height;
    d["snapshots"] = snapshots;
    d["collisions"] = collisions;
    return d;
}

py::object to_python(const Value& v) {
    switch (v.type()) {
        case ValueType::none: return py::none();
        case ValueType::heightmap: return py::cast(PyHeightmap{v.heightmap()});
        case ValueType::image: {
            const auto& img = v.image();
            if (img->format == Image::Format::rgba8)
                return view(img->rgba8.data(), py::dtype::of<std::uint8_t>(), {img->height, img->width, 4}, img);
            return view(img->rgba32f.data(), py::dtype::of<float>(), {img->height, img->width, 4}, img);
        }
        case ValueType::particles: return particles_to_python(v.particles());
        case ValueType::plates: return plates_to_python(*v.plates());
        case ValueType::series: return py::cast(PySeries{v.series()});
    }
    return py::none();
}

// --------------------------------------------------------------------- run

/// A Python value as `--set` takes it: True → true, 2.5 → 2.5, (1, 2) → (1, 2), [(..), ..], strings as given.
std::string override_text(const py::handle& v) {
    if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
    if (py::isinstance<py::int_>(v)) return py::str(v);
    if (py::isinstance<py::float_>(v)) return py::repr(v);
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::isinstance<py::tuple>(v) || py::isinstance<py::list>(v)) {
        const py::sequence s = v.cast<py::sequence>();
        const bool points = s.size() > 0 && (py::isinstance<py::tuple>(s[0]) || py::isinstance<py::list>(s[0]));
        std::string text = points ? "[" : "(";
        for (std::size_t i = 0; i < s.size(); ++i) text += (i ? ", " : "") + override_text(s[i]);
        return text + (points ? "]" : ")");
    }
    throw py::value_error("set: cannot give a parameter the Python value " + std::string(py::repr(v)) +
                          " (give a number, bool, string, (x, y) point or a list of points)");
}

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};

/// A folder for a run without `out` whose nodes write files: they are written there and removed with it.
/// Made only if the plan writes files (make()): a run that writes none touches no folder at all.
struct ScratchFolder {
    fs::path path;
    bool made = false;
    ScratchFolder() {
        static std::atomic<int> counter{0};
        // $TMPDIR as std::filesystem::temp_directory_path() reads it, without its check that the folder
        // exists: the checker wants the path even for a run that will not make it.
        const char* tmp = std::getenv("TMPDIR");
        path = fs::path(tmp && *tmp ? tmp : "/tmp") /
            ("orogen-python-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    }
    void make() {
        fs::remove_all(path);
        fs::create_directories(path);
        made = true;
    }
    ~ScratchFolder() {
        std::error_code ec;
        if (made) fs::remove_all(path, ec);
    }
    ScratchFolder(const ScratchFolder&) = delete;
    ScratchFolder& operator=(const ScratchFolder&) = delete;
};

/// A str, or any os.PathLike (pathlib.Path) as its path; a TypeError naming `what` otherwise.
std::string path_text(const py::handle& v, const char* what) {
    if (py::isinstance<py::str>(v)) return v.cast<std::string>();
    if (py::hasattr(v, "__fspath__")) return py::str(py::module_::import("os").attr("fspath")(v)).cast<std::string>();
    throw py::type_error(std::string(what) + " must be a str or a path (pathlib.Path), got " +
                         std::string(py::str(py::type::of(v).attr("__name__"))));
}

/// `spec` (a path, or the text itself): its name for messages, its text, and the path input paths are
/// relative to.
SpecText read_spec(const std::string& spec) {
    SpecText r;
    std::error_code ec;
    const bool is_text = spec.find('\n') != std::string::npos;
    if (!is_text && fs::is_regular_file(spec, ec)) {
        try {
            const auto bytes = read_file(spec);
            r.text.assign(bytes.begin(), bytes.end());
        } catch (const std::exception& e) { throw py::value_error(std::string("orogen: error: ") + e.what()); }
        r.name = spec;
        r.path = spec;
    } else if (!is_text && !spec.empty() && spec.rfind("orogen", 0) != 0) {
        throw py::value_error("orogen: error: cannot read spec " + spec + ": " +
                              (fs::exists(spec, ec) ? "it is not a regular file" : "no such file") +
                              " (give a path to a .orogen file, or the spec's text)");
    } else {
        r.text = spec;
        r.name = "<spec>";
        r.path = fs::current_path() / r.name;  // input paths are relative to the current folder
    }
    return r;
}

/// `plan` run on a thread of its own, the GIL released; this thread wakes every 50 ms for Python's signals,
/// so Ctrl-C asks the node to stop (as SIGINT does on the command line). Raises what the run raised.
RunResult run_released(const Checked& checked, const RunSettings& settings, BoundValues bound) {
    g_cancel = false;
    g_signal = 0;
    RunResult result;
    std::exception_ptr failure;
    std::promise<void> done;
    std::future<void> finished = done.get_future();
    std::thread worker([&] {
        try {
            result = plugins().run(checked, settings, std::move(bound));
        } catch (...) { failure = std::current_exception(); }
        done.set_value();
    });
    bool interrupted = false;
    for (;;) {
        std::future_status status;
        {
            py::gil_scoped_release release;
            status = finished.wait_for(std::chrono::milliseconds(50));
        }
        if (status == std::future_status::ready) break;
        if (!interrupted && PyErr_CheckSignals() != 0) {
            interrupted = true;
            g_signal = 2;
            g_cancel = true;
        }
    }
    {
        py::gil_scoped_release release;
        worker.join();
    }
    if (interrupted) throw py::error_already_set();  // KeyboardInterrupt, after the run stopped and cleaned up
    if (failure) std::rethrow_exception(failure);
    if (result.exit_code == 2) throw py::value_error(result.error);
    if (result.exit_code != 0) throw std::runtime_error(result.error);
    return result;
}

/// run() and node(): `bound` are values the spec reads by name without making them (node()'s inputs).
/// What a run() caller wants back: `values` (only they, and only what they need, run), or every named value;
/// with `outputs` false, the exporters no value needs do not run.
struct Wanted {
    std::optional<std::vector<std::string>> values;
    bool outputs = true;
};

py::dict run_spec_bound(const py::object& spec_arg, std::optional<std::uint64_t> seed, const py::dict& overrides,
                        std::optional<int> threads, const py::object& out_arg, bool progress, BoundValues bound,
                        const Wanted& wanted = {}) {
    const std::string spec = path_text(spec_arg, "spec");
    std::optional<std::string> out;
    if (!out_arg.is_none()) out = path_text(out_arg, "out");
    SpecText text = read_spec(spec);
    if (threads && (*threads < 1 || *threads > 1024))
        throw py::value_error("threads must be a number from 1 to 1024, got " + std::to_string(*threads));

    CheckSettings check_settings;
    for (const auto& [k, v] : overrides)
        check_settings.overrides.push_back(py::str(k).cast<std::string>() + "=" + override_text(v));
    check_settings.seed = seed;
    check_settings.bound = &bound;
    ScratchFolder scratch;  // made below only if a node writes files
    check_settings.out_dir = out ? fs::path(*out) : scratch.path;

    Checked checked = plugins().check(text, check_settings);
    if (!checked.ok()) throw py::value_error(checked.report().text_with_count());
    // The checker's warnings are about files ("this spec writes no files"): moot when nothing is written.
    if (checked.report().warnings > 0 && out &&
        PyErr_WarnEx(PyExc_UserWarning, checked.report().text().c_str(), 1) != 0)
        throw py::error_already_set();  // warnings turned into errors

    // The values wanted back are held past the last node; with `values` or outputs=False, only what they need runs.
    try {
        if (wanted.values) checked.keep_only(*wanted.values);
        else if (!wanted.outputs) checked.keep_only(checked.value_keys());
        else checked.keep_named_values();
    } catch (const Error& e) { throw py::value_error(std::string("orogen: error: ") + e.what()); }

    RunSettings settings;
    const bool pruned = wanted.values || !wanted.outputs;
    if (out && (!pruned || checked.writes_files())) {  // what was pruned to write nothing writes no manifest
        settings.out_dir = *out;
    } else if (checked.writes_files()) {  // else out_dir stays empty: no folder, no manifest, nothing written
        scratch.make();
        settings.out_dir = scratch.path;
    } else {
        settings.out_dir.clear();
    }
    settings.threads = threads.value_or(0);
    settings.progress = stderr;
    settings.quiet = !progress;
    settings.cancel = &g_cancel;
    settings.cancel_signal = &g_signal;
    settings.cache = std::nullopt;  // every node runs: a cached node's values would not be at hand
    const RunResult result = run_released(checked, settings, std::move(bound));

    py::dict values;
    for (const auto& [key, v] : result.values) {
        if (v.type() == ValueType::none) continue;
        values[py::str(key)] = to_python(v);
    }
    return values;
}

py::dict run_spec(const py::object& spec_arg, std::optional<std::uint64_t> seed, const py::dict& overrides,
                  std::optional<int> threads, const py::object& out_arg, bool progress,
                  std::optional<std::vector<std::string>> values, bool outputs) {
    return run_spec_bound(spec_arg, seed, overrides, threads, out_arg, progress, {},
                          Wanted{std::move(values), outputs});
}

/// A 2-D float32 numpy array of any layout (C or Fortran order, a slice with strides) copied once into a
/// heightmap's own storage, row 0 the north edge; a NaN or infinity is a ValueError naming input `i` and
/// the first bad sample (column, row), as a spec's importer refuses it. The kernel's heightmap owns its
/// std::vector, so it cannot borrow numpy's memory: this copy is the one node() makes.
std::shared_ptr<Heightmap> heightmap_of_array(const py::array& a, double cell, int i) {
    const std::string which = "input " + std::to_string(i);
    if (a.ndim() != 2 || !a.dtype().is(py::dtype::of<float>()))
        throw py::value_error(which + " must be a 2-D float32 array");  // node() said so in its own words first
    const auto rows = a.shape(0), cols = a.shape(1);
    std::vector<float> heights(std::size_t(rows) * std::size_t(cols));
    const auto* base = static_cast<const char*>(a.data());
    if (a.flags() & py::array::c_style) {
        std::memcpy(heights.data(), base, heights.size() * sizeof(float));
    } else {
        const auto row_step = a.strides(0), col_step = a.strides(1);
        for (py::ssize_t r = 0; r < rows; ++r)
            for (py::ssize_t c = 0; c < cols; ++c)
                std::memcpy(&heights[std::size_t(r * cols + c)], base + r * row_step + c * col_step, sizeof(float));
    }
    // One pass, branch-free, to find whether any sample is bad; the first one named only then.
    bool finite = true;
    for (const float v : heights) finite &= std::isfinite(v);
    if (!finite) {
        const auto at = std::size_t(
            std::find_if(heights.begin(), heights.end(), [](float v) { return !std::isfinite(v); }) - heights.begin());
        const float v = heights[at];
        throw py::value_error(which + ": sample (" + std::to_string(at % std::size_t(cols)) + ", " +
                              std::to_string(at / std::size_t(cols)) + ") is " +
                              (std::isnan(v) ? "nan"
                                   : v > 0   ? "inf"
                                             : "-inf") +
                              "; heights and layers must be finite numbers");
    }
    return std::make_shared<Heightmap>(int(cols), int(rows), cell, std::move(heights));
}

/// orogen.node()'s run: `inputs` a list of (name, value, cell), each value an orogen.Heightmap (bound as
/// it is: no copy; a node that changes it works on a copy, as any node whose input is read elsewhere) or a
/// 2-D float32 array (copied once into a heightmap the run alone holds: a node that changes it does so in
/// place).
py::dict run_node(const std::string& spec, const py::list& inputs, std::optional<int> threads) {
    BoundValues bound;
    int i = 0;
    for (const auto& item : inputs) {
        const auto entry = item.cast<py::tuple>();
        const auto name = entry[0].cast<std::string>();
        const py::object value = entry[1];
        ++i;
        if (py::isinstance<PyHeightmap>(value)) bound[name] = Value(value.cast<const PyHeightmap&>().hm);
        else bound[name] = Value(heightmap_of_array(value.cast<py::array>(), entry[2].cast<double>(), i));
    }
    return run_spec_bound(py::str(spec), std::nullopt, py::dict(), threads, py::none(), false, std::move(bound));
}

// ------------------------------------------------------------ a model of processes (orogen.Model)

/// A landscape-evolution loop stepped from Python (the landlab habit): the processes of an erode:evolve
/// body, checked by the kernel as a spec's, over a terrain held here; fields read and written as numpy
/// arrays between steps (copies: a process may reallocate its fields while it runs).
class PyModel {
public:
    /// `spec` an erode:evolve statement named `label` over the bound value `terrain` (orogen/__init__.py writes it).
    PyModel(const std::string& spec, [[maybe_unused]] const std::string& label, const py::object& terrain,
            double cell) {
        BoundValues bound;
        bound["terrain"] = Value(py::isinstance<PyHeightmap>(terrain)
                                     ? std::make_shared<Heightmap>(*terrain.cast<const PyHeightmap&>().hm)
                                     : heightmap_of_array(terrain.cast<py::array>(), cell, 1));
        CheckSettings check_settings;
        check_settings.bound = &bound;
        checked_ = plugins().check(SpecText{"orogen.Model", spec, "orogen.Model"}, check_settings);
        if (!checked_.ok()) throw py::value_error(checked_.report().text_with_count());
        node_ = checked_.nodes().back();
        const CheckedNode& node = node_;
        auto hm = std::const_pointer_cast<Heightmap>(bound["terrain"].heightmap());
        landscape::ProcessLoop::Options options;
        options.open = *landscape::parse_sides(std::get<std::string>(node.params->at("open")));
        options.base_level = *landscape::parse_base_level(std::get<std::string>(node.params->at("base_level")));
        options.substeps = int(std::get<std::int64_t>(node.params->at("substeps")));
        options.years = std::get<double>(node.params->at("years"));
        options.seed = node.seed;
        options.warn = [](std::string_view m) { PyErr_WarnEx(PyExc_RuntimeWarning, std::string(m).c_str(), 1); };
        loop_ = std::make_unique<landscape::ProcessLoop>(*node.processes, hm, std::vector<Value>{Value(hm)}, options);
        loop_->start();
    }

    void step(double dt, int steps) {
        if (!(dt > 0.0) || !std::isfinite(dt)) throw py::value_error("dt must be a positive number of years");
        if (steps < 0) throw py::value_error("steps must be 0 or more");
        const double sub = dt / loop_->substeps();
        for (const ProcessCall& p : *node_.processes)
            if (p.process->max_dt && sub > p.process->max_dt(p, loop_->cell()))
                throw py::value_error("dt/substeps = " + std::to_string(sub) + " yr is longer than " + p.label +
                                      "'s stable step, " + std::to_string(p.process->max_dt(p, loop_->cell())) +
                                      " yr on these cells; give a smaller dt or more substeps");
        {
            py::gil_scoped_release release;
            for (int k = 0; k < steps; ++k) loop_->advance(dt);
        }
        if (const std::int64_t bad = loop_->first_non_finite(); bad >= 0)
            throw std::runtime_error("non-finite height at sample " + std::to_string(bad) + " after step " +
                                     std::to_string(loop_->step()) + "; give a smaller dt or more substeps");
    }

    py::array field(const std::string& name) {
        const std::vector<double>* f = loop_->find_field(name);
        if (!f) throw py::key_error(unknown_field(name));
        py::array_t<double> out({py::ssize_t(loop_->height()), py::ssize_t(loop_->width())});
        if (f->empty()) std::fill(out.mutable_data(), out.mutable_data() + out.size(), 0.0);
        else std::memcpy(out.mutable_data(), f->data(), f->size() * sizeof(double));
        return out;
    }

    void set_field(const std::string& name, const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
        std::vector<double>* f = loop_->find_field(name);
        if (!f) throw py::key_error(unknown_field(name));
        if (a.ndim() != 2 || a.shape(0) != loop_->height() || a.shape(1) != loop_->width())
            throw py::value_error("field '" + name + "' is " + std::to_string(loop_->height()) + " rows of " +
                                  std::to_string(loop_->width()) + "; the array does not match");
        for (py::ssize_t i = 0; i < a.size(); ++i)
            if (!std::isfinite(a.data()[i]))
                throw py::value_error("field '" + name + "': sample " + std::to_string(i) + " is not finite");
        f->assign(a.data(), a.data() + a.size());
    }

    std::vector<std::string> fields() const { return loop_->field_names(); }
    double time() const { return loop_->time(); }
    std::int64_t steps() const { return loop_->step(); }

    /// The heights now, with the processes' layers (drainage, ...) and the uplift received, as a Heightmap.
    PyHeightmap result() {
        loop_->finish();
        auto out = std::make_shared<Heightmap>(loop_->result());
        GridView uplifted = out->layer("uplifted", 0.0f);
        const auto& u = loop_->uplifted_so_far();
        for (std::size_t i = 0; i < u.size(); ++i) uplifted.data[i] = float(u[i]);
        return PyHeightmap{out};
    }

private:
    std::string unknown_field(const std::string& name) const {
        std::string names;
        for (const auto& n : loop_->field_names()) names += (names.empty() ? "" : ", ") + n;
        return "no field '" + name + "' in this model (its fields: " + names + ")";
    }

    Checked checked_;  // holds the processes' checked calls the loop reads
    CheckedNode node_;
    std::unique_ptr<landscape::ProcessLoop> loop_;
};

// ------------------------------------------------------------ nodes, help

py::object param_value(const ParamValue& v) {
    return std::visit(
        [](const auto& x) -> py::object {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, std::monostate>) return py::none();
            else if constexpr (std::is_same_v<T, Point2>) return py::make_tuple(x.x, x.y);
            else if constexpr (std::is_same_v<T, std::vector<Point2>>) {
                py::list l;
                for (const auto& p : x) l.append(py::make_tuple(p.x, p.y));
                return l;
            } else return py::cast(x);
        },
        v);
}

const NodeDescriptor& find_node(const std::string& name) {
    const Registry& registry = plugins().registry();
    if (const NodeDescriptor* n = registry.find(name)) return *n;
    std::vector<std::string> names;
    const NodeDescriptor* found = nullptr;
    for (const auto* d : registry.nodes()) {
        names.push_back(d->qualified_name());
        if (d->name == name) found = d;  // "fault" is fine too
    }
    if (found) return *found;
    const std::string guess = closest(name, names);
    throw py::value_error("unknown node '" + name + "'" +
                          (guess.empty() ? "; orogen.nodes() lists them all" : "; did you mean '" + guess + "'?"));
}

py::list nodes() {
    py::list l;
    for (const auto* n : plugins().registry().nodes()) {
        py::dict d;
        d["name"] = n->qualified_name();
        d["kind"] = n->kind;
        d["summary"] = n->summary;
        l.append(d);
    }
    return l;
}

py::dict help(const std::string& name) {
    const NodeDescriptor& n = find_node(name);
    py::list inputs;
    for (const auto& in : n.inputs) {
        py::dict d;
        d["name"] = in.name;
        d["type"] = in.many == Many::either ? describe_type(in.type, false) + " or " + describe_type(in.type, true)
                                            : describe_type(in.type, in.many == Many::series);
        d["optional"] = in.need == Need::optional;
        d["help"] = in.help;
        inputs.append(d);
    }
    py::list params;
    for (const auto& p : n.params) {
        py::dict d;
        d["name"] = p.name;
        d["type"] = std::string(to_string(p.type));
        d["default"] = param_value(p.default_value);
        d["required"] = p.required();
        d["min"] = p.minimum ? py::cast(*p.minimum) : py::none();
        d["max"] = p.maximum ? py::cast(*p.maximum) : py::none();
        d["min_exclusive"] = p.minimum_exclusive;
        d["max_exclusive"] = p.maximum_exclusive;
        d["unit"] = p.unit_text;
        d["help"] = p.help_text;
        d["choices"] = p.choices;
        params.append(d);
    }
    py::dict d;
    d["name"] = n.qualified_name();
    d["summary"] = n.summary;
    d["description"] = n.description;
    d["inputs"] = inputs;
    d["output"] = describe_type(n.output, n.output_series);
    d["adds_layers"] = n.adds_layers;
    d["params"] = params;
    return d;
}

}  // namespace

PYBIND11_MODULE(_orogen, m) {
    m.doc() = "orogen: mountain terrain from text pipeline specs (docs/python.md)";

    py::class_<PyHeightmap>(m, "Heightmap",
                            "A heightmap: heights and layers as read-only float32 views, rows north to south")
        .def_property_readonly(
            "height",
            [](const PyHeightmap& h) {
                return float_grid(h.hm->heights().data(), h.hm->width(), h.hm->height(), h.hm);
            },
            "heights in metres, a (rows, columns) float32 array, row 0 the north edge")
        .def_property_readonly(
            "layers",
            [](const PyHeightmap& h) {
                py::dict d;
                for (const auto& name : h.hm->layer_names())
                    d[py::str(name)] = float_grid(h.hm->layer(name).data, h.hm->width(), h.hm->height(), h.hm);
                return d;
            },
            "the layers by name, each like height")
        .def_property_readonly(
            "cell", [](const PyHeightmap& h) { return h.hm->cell(); }, "metres between vertices")
        .def_property_readonly("shape",
                               [](const PyHeightmap& h) { return py::make_tuple(h.hm->height(), h.hm->width()); })
        .def("__repr__", [](const PyHeightmap& h) {
            std::ostringstream s;
            s << "<orogen.Heightmap " << h.hm->width() << "x" << h.hm->height() << ", cell " << h.hm->cell() << " m";
            const auto layers = h.hm->layer_names();
            for (std::size_t i = 0; i < layers.size(); ++i) s << (i ? ", " : "; layers ") << layers[i];
            return s.str() + ">";
        });

    py::class_<PySeries>(m, "Series",
                         "A series of values (a time-lapse, a turntable's frames), each made when asked for")
        .def_property_readonly("times", [](const PySeries& s) { return s.series->times; })
        .def("__len__", [](const PySeries& s) { return s.series->size(); })
        .def("__getitem__",
             [](const PySeries& s, std::int64_t i) {
                 const auto n = std::int64_t(s.series->size());
                 if (i < 0) i += n;
                 if (i < 0 || i >= n) throw py::index_error("series index out of range");
                 Value v;
                 {
                     py::gil_scoped_release release;
                     v = s.series->at(std::size_t(i));
                 }
                 return to_python(v);
             })
        .def("__repr__", [](const PySeries& s) {
            return "<orogen.Series of " + std::to_string(s.series->size()) + " " +
                std::string(to_string(s.series->element)) + "s>";
        });

    py::class_<PyModel>(m, "_Model")
        .def(py::init<const std::string&, const std::string&, const py::object&, double>(), py::arg("spec"),
             py::arg("label"), py::arg("terrain"), py::arg("cell"))
        .def("step", &PyModel::step, py::arg("dt"), py::arg("steps") = 1)
        .def("field", &PyModel::field, py::arg("name"))
        .def("set_field", &PyModel::set_field, py::arg("name"), py::arg("values"))
        .def_property_readonly("fields", &PyModel::fields)
        .def_property_readonly("time", &PyModel::time)
        .def_property_readonly("steps", &PyModel::steps)
        .def("result", &PyModel::result);
    m.def("run", &run_spec, py::arg("spec"), py::kw_only(), py::arg("seed") = py::none(), py::arg("set") = py::dict(),
          py::arg("threads") = py::none(), py::arg("out") = py::none(), py::arg("progress") = false,
          py::arg("values") = py::none(), py::arg("outputs") = true,
          "Run a spec (a path, or the text itself) and return every named value: {name: value}. values=[names]: "
          "return only these, running only what they need; outputs=False: every named value, without the "
          "exporters (no file written, no video encoded).");
    m.def("nodes", &nodes, "The nodes the loaded plugins provide: [{'name', 'kind', 'summary'}].");
    m.def("help", &help, py::arg("name"), "A node's description, inputs and parameters (type, default, range, unit).");
    m.def("_run_node", &run_node, py::arg("spec"), py::arg("inputs"), py::arg("threads") = py::none(),
          "orogen.node()'s run: the spec with its inputs [(name, Heightmap or float32 array, cell)] bound by name.");
}
