// `orogen analyze`: its options and the spec it runs (analyze.hpp).
#include "analyze.hpp"

#include <orogen/io.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace orogen::cli {

namespace {

std::optional<double> parse_number(const std::string& s) {
    if (s.empty()) return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

/// A spec string literal.
std::string literal(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

std::string number(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

}  // namespace

std::string parse_analyze_args(int argc, char** argv, AnalyzeArgs& a) {
    bool references = false;
    for (int i = 2; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&](const std::string& name, std::string& out) -> bool {
            if (arg.rfind(name + "=", 0) == 0) {
                out = arg.substr(name.size() + 1);
                return true;
            }
            if (i + 1 >= argc) return false;
            out = argv[++i];
            return true;
        };
        auto is = [&](const std::string& name) { return arg == name || arg.rfind(name + "=", 0) == 0; };
        std::string v;
        if (arg == "--against") {
            references = true;
        } else if (is("--out")) {
            if (!value("--out", v) || v.empty()) return "--out needs a folder";
            a.out = v;
        } else if (is("--cell")) {
            const bool got = value("--cell", v);
            const auto n = got ? parse_number(v) : std::nullopt;
            if (!n || *n <= 0.0 || *n > 1e6)
                return "--cell needs the distance between samples in metres, a number above 0" +
                    (got ? ", got '" + v + "'" : std::string());
            a.cell = *n;
        } else if (is("--heights")) {
            const bool got = value("--heights", v);
            const auto colon = v.find(':');
            const auto low = got && colon != std::string::npos ? parse_number(v.substr(0, colon)) : std::nullopt;
            const auto high = got && colon != std::string::npos ? parse_number(v.substr(colon + 1)) : std::nullopt;
            if (!low || !high || !(*high > *low))
                return "--heights needs LOW:HIGH, the heights in metres of a PNG's black and white (LOW < HIGH)" +
                    (got ? ", got '" + v + "'" : std::string());
            a.heights = std::pair{*low, *high};
        } else if (is("--threads")) {
            const bool got = value("--threads", v);
            const auto n = got ? parse_number(v) : std::nullopt;
            if (!n || *n < 1 || *n > 1024 || *n != std::floor(*n))
                return "--threads needs a number from 1 to 1024" + (got ? ", got '" + v + "'" : std::string());
            a.threads = int(*n);
        } else if (is("--window-m")) {
            const bool got = value("--window-m", v);
            const auto n = got ? parse_number(v) : std::nullopt;
            if (!n || *n <= 0.0 || *n > 1e7)
                return "--window-m needs the windows' side in metres, a number above 0 (3840: 128 cells at 30 m)" +
                    (got ? ", got '" + v + "'" : std::string());
            a.window_m = *n;
        } else if (arg == "--discriminate") {
            a.discriminate = true;
        } else if (arg == "--no-render") {
            a.render = false;
        } else if (arg == "--fit-filled-flats") {
            a.fit_filled_flats = true;
        } else if (arg == "--skip-filled-flats") {
            a.skip_filled_flats = true;
        } else if (arg == "--quiet" || arg == "-q") {
            a.quiet = true;
        } else if (arg.size() > 1 && arg[0] == '-') {
            return "unknown option '" + arg + "' for analyze";
        } else {
            (references ? a.against : a.files).push_back(arg);
        }
    }
    if (a.files.empty())
        return a.against.empty()
            ? "analyze needs at least one terrain file"
            : "analyze needs a terrain to measure before --against (the files after it are references)";
    if (references && a.against.empty()) return "--against needs at least one reference DEM after it";
    if (a.window_m && !a.discriminate) return "--window-m is the window of --discriminate; add --discriminate";
    if (a.fit_filled_flats && a.skip_filled_flats)
        return "--fit-filled-flats and --skip-filled-flats contradict each other; give one (skip is the default)";
    if (a.fit_filled_flats && a.discriminate)
        return "--fit-filled-flats changes the figures' table, which --discriminate does not print; drop one";
    if (a.discriminate) {
        if (a.files.size() < 2 || a.against.size() < 2)
            return "--discriminate leaves one source out at a time, so it needs at least two generated terrains "
                   "and two real DEMs after --against (got " +
                std::to_string(a.files.size()) + " and " + std::to_string(a.against.size()) +
                "); run the pipeline with other seeds (--seed) for more terrains";
        if (a.files.size() + a.against.size() > 32)
            return "--discriminate takes at most 32 files at once, got " +
                std::to_string(a.files.size() + a.against.size());
        return {};
    }
    if (a.files.size() + a.against.size() > 16)
        return "analyze compares at most 16 files at once, got " + std::to_string(a.files.size() + a.against.size());
    return {};
}

ComposedSpec compose_analyze_spec(const AnalyzeArgs& args) {
    ComposedSpec spec;
    std::ostringstream s;
    s << "orogen 1\n# composed by `orogen analyze` from its command line\n";
    std::vector<std::string> values;
    std::set<std::string> taken;
    std::vector<std::string> all = args.files;
    all.insert(all.end(), args.against.begin(), args.against.end());
    for (std::size_t i = 0; i < all.size(); ++i) {
        fs::path file = all[i];
        std::error_code ec;
        if (!fs::exists(file, ec)) {
            spec.problem = file.string() + ": no such file";
            return spec;
        }
        if (const std::string problem = regular_file_problem(file); !problem.empty()) {
            spec.problem = file.string() + " " + problem;
            return spec;
        }
        std::string ext = lower(file.extension().string());
        if (ext == ".json") {  // shared/realism's NAME.json describes NAME.f32
            fs::path raw = file;
            raw.replace_extension(".f32");
            if (!fs::exists(raw, ec)) {
                spec.problem = file.string() +
                    ": a .json file is read as the description of a .f32 grid beside it, "
                    "but there is no " +
                    raw.string() + "; give the terrain file itself";
                return spec;
            }
            file = raw;
            ext = ".f32";
        }
        const std::string path = literal(fs::absolute(file).lexically_normal().string());
        const std::string cell = args.cell ? ", cell=" + number(*args.cell) : "";
        const std::string value = (i < args.files.size() ? "t" : "r") + std::to_string(i + 1);
        std::string node;
        if (ext == ".png") {
            if (!args.cell || !args.heights) {
                spec.problem = file.string() +
                    ": a PNG holds neither the cell size nor heights in metres; give --cell "
                    "METRES and --heights LOW:HIGH (the heights of black and white)";
                return spec;
            }
            node = "import:png(path=" + path + cell + ", low=" + number(args.heights->first) +
                ", high=" + number(args.heights->second) + ")";
        } else if (ext == ".r16" || ext == ".r32") {
            node = "import:raw(path=" + path + cell + ")";
        } else if (ext == ".exr") {
            node = "import:exr(path=" + path + cell + ")";
        } else if (ext == ".vti") {
            node = "import:vti(path=" + path + cell + ")";
        } else if (ext == ".f32") {
            node = "import:f32(path=" + path + cell + ")";
        } else {  // every raster GDAL opens
            node = "import:geotiff(path=" + path + ", resample=none, holes=mask" + cell + ")";
        }
        s << value << " = " << node << "\n";
        values.push_back(value);
        // The report's name: the file's stem, made unique, without the commas that separate names. With
        // --discriminate, runs of one pipeline often share a file name (out42/terrain.r32, out1/terrain.r32):
        // their folder names them.
        std::string name = file.stem().string();
        const auto same_stem = [&](const std::string& other) { return fs::path(other).stem() == file.stem(); };
        if (args.discriminate && std::count_if(all.begin(), all.end(), same_stem) > 1 &&
            !file.parent_path().filename().empty())
            name = file.parent_path().filename().string() + "/" + name;
        std::replace(name.begin(), name.end(), ',', '_');
        if (name.empty()) name = value;
        std::string unique = name;
        for (int k = 2; taken.count(unique); ++k) unique = name + "-" + std::to_string(k);
        taken.insert(unique);
        spec.names.push_back(unique);
    }
    if (args.discriminate) {
        std::string names;
        for (std::size_t i = 0; i < values.size(); ++i) names += (i ? "," : "") + spec.names[i];
        s << "analyze:discriminate(";
        for (std::size_t i = 0; i < values.size(); ++i) s << (i ? ", " : "") << values[i];
        s << ", names=" << literal(names) << ", real=" << args.against.size();
        if (args.window_m) s << ", window_m=" << number(*args.window_m);
        s << ", path=\"discriminate.json\", picture=\"discriminate.png\")\n";
        spec.text = s.str();
        return spec;
    }
    std::string names, images;
    for (std::size_t i = 0; i < values.size(); ++i) {
        names += (i ? "," : "") + spec.names[i];
        images += (i ? "," : "") + ("renders/" + spec.names[i] + ".png");
    }
    s << "analyze:terrain(";
    for (std::size_t i = 0; i < values.size(); ++i) s << (i ? ", " : "") << values[i];
    s << ", names=" << literal(names) << ", references=" << args.against.size()
      << ", path=\"analysis.json\", page=\"README.md\"";
    if (args.fit_filled_flats) s << ", filled_flats=fit";
    if (args.render) s << ", images=" << literal(images);
    s << ")\n";
    if (args.render) {
        // One camera for all: the orbit camera fitted to each terrain, from the same bearing and height angle,
        // the same sun; heights true to scale.
        for (std::size_t i = 0; i < values.size(); ++i) {
            s << "v" << i + 1 << " = render:terrain(" << values[i]
              << ", width=640, height=400, camera=orbit, azimuth=200, elevation=30, sun_azimuth=250, "
                 "sun_elevation=30, exaggeration=1)\n";
            s << "export:png(v" << i + 1 << ", path=" << literal("renders/" + spec.names[i] + ".png") << ")\n";
        }
    }
    spec.text = s.str();
    return spec;
}

}  // namespace orogen::cli
