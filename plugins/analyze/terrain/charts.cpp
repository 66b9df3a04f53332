// The report's charts, drawn by gnuplot (pngcairo, from Debian's gnuplot-nox) run as a child process on a
// script with the data inline (datablocks); it writes each PNG to an AtomicFile's temporary name, and the
// files are renamed into place together once all are drawn.
#include "report.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <fstream>
#include <memory>
#include <sstream>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace orogen::analyze {

namespace {

/// A gnuplot string literal: single quotes, a quote doubled.
std::string gp_string(std::string_view s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
}

std::string number(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

/// Colour per terrain (Okabe–Ito, legible for colour-blind readers); references dashed.
std::string style(std::size_t i, const Terrain& t) {
    static const char* colours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                    "#E69F00", "#56B4E9", "#000000", "#F0E442"};
    return std::string("lc rgb '") + colours[i % 8] + "' lw 2" + (t.reference ? " dt 2" : "");
}

std::string header(const std::string& title, const std::string& xlabel, const std::string& ylabel) {
    // The legend under the plot, in rows: beside it, long file names took 40 % of the chart's width.
    return "reset\nset termoption noenhanced\nset title " + gp_string(title) + "\nset xlabel " + gp_string(xlabel) +
        "\nset ylabel " + gp_string(ylabel) +
        "\nset grid\nset key below center horizontal samplen 2 font ',9'\nunset logscale\n";
}

struct Series {
    std::vector<std::pair<double, double>> points;
    std::string title;
};

/// The points of log-binned chart data.
std::vector<std::pair<double, double>> binned(const analysis::LogBins& bins) {
    std::vector<std::pair<double, double>> points;
    for (std::size_t b = 0; b < bins.x.size(); ++b) points.emplace_back(bins.x[b], bins.y[b]);
    return points;
}

/// A fit of ln y against ln x drawn across the bins' range of x (nothing without bins).
std::vector<std::pair<double, double>> fitted(const analysis::LogBins& bins, const analysis::LineFit& fit) {
    std::vector<std::pair<double, double>> line;
    if (bins.x.empty()) return line;
    for (double x : {bins.x.front(), bins.x.back()})
        line.emplace_back(x, std::exp(fit.intercept + fit.slope * std::log(x)));
    return line;
}

/// `plot` over datablocks, one per terrain with data; empty if none has any.
std::string plot(const std::vector<Terrain>& terrains, const std::string& name,
                 const std::function<Series(const Terrain&)>& series, const std::string& with,
                 const std::function<std::vector<std::pair<double, double>>(const Terrain&)>& fit = {}) {
    std::ostringstream blocks, command;
    bool any = false;
    for (std::size_t i = 0; i < terrains.size(); ++i) {
        const Series s = series(terrains[i]);
        if (s.points.empty()) continue;
        const std::string block = "$" + name + std::to_string(i);
        blocks << block << " << EOD\n";
        for (const auto& [x, y] : s.points) blocks << number(x) << ' ' << number(y) << '\n';
        blocks << "EOD\n";
        command << (any ? ", " : "plot ") << block << " using 1:2 with " << with << ' ' << style(i, terrains[i])
                << " title " << gp_string(s.title);
        any = true;
        if (fit) {
            const auto line = fit(terrains[i]);
            if (line.empty()) continue;
            blocks << block << "fit << EOD\n";
            for (const auto& [x, y] : line) blocks << number(x) << ' ' << number(y) << '\n';
            blocks << "EOD\n";
            command << ", " << block << "fit using 1:2 with lines " << style(i, terrains[i]) << " notitle";
        }
    }
    if (!any) return {};
    return blocks.str() + command.str() + "\n";
}

/// Runs gnuplot on `script`, written to a hidden file in `folder` (not fed through a pipe: a gnuplot that
/// stops early would leave us writing into a closed pipe, and SIGPIPE would end the run). "" or what went wrong.
std::string run_gnuplot(const std::string& script, const std::filesystem::path& folder) {
    const std::string tag = ".orogen-gnuplot-" + std::to_string(::getpid());
    const std::filesystem::path script_file = folder / (tag + ".gp"), errors = folder / (tag + ".err");
    struct Remove {
        std::filesystem::path a, b;
        ~Remove() {
            std::error_code ec;
            std::filesystem::remove(a, ec);
            std::filesystem::remove(b, ec);
        }
    } remove{script_file, errors};
    {
        std::ofstream out(script_file, std::ios::binary);
        out << script;
        if (!out.flush()) return "cannot write the chart script " + script_file.string();
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 2, errors.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    std::string arg1 = script_file.string();
    char arg0[] = "gnuplot";
    char* argv[] = {arg0, arg1.data(), nullptr};
    pid_t pid = 0;
    const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0)
        return "gnuplot is not installed (apt-get install gnuplot-nox): " + std::string(std::strerror(spawned));
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::ifstream err(errors);
        std::stringstream text;
        text << err.rdbuf();
        return "gnuplot failed: " + text.str();
    }
    return {};
}

/// A chart's file and title, and its gnuplot commands with their data ("" plot: no terrain has data).
struct Pending {
    Chart chart;
    std::string body;
};

/// The whole map's charts: the slope distribution, the hypsometric curve and the power spectrum.
void whole_map_charts(const std::vector<Terrain>& terrains, const std::string& stem, std::vector<Pending>& pending) {
    using analysis::FigureId;
    pending.push_back({{stem + "-slopes.png", "Slope distribution"},
                       header("Slope distribution", "slope (°)", "share of the samples (% per degree)") +
                           "set xrange [0:90]\n" +
                           plot(
                               terrains, "slopes",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   for (std::size_t b = 0; b < t.figures.slope_histogram.size(); ++b)
                                       s.points.emplace_back(double(b) + 0.5, 100.0 * t.figures.slope_histogram[b]);
                                   return s;
                               },
                               "lines")});
    pending.push_back({{stem + "-hypsometry.png", "Hypsometric curve"},
                       header("Hypsometric curve (Strahler 1952)", "relative area above a / A",
                              "relative height (h − min) / (max − min)") +
                           "set xrange [0:1]\nset yrange [0:1]\n" +
                           plot(
                               terrains, "hyps",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   const auto& hi = t.figures[FigureId::hypsometric_integral];
                                   if (hi.ok()) s.title += ": HI " + number(std::round(hi.value * 1000) / 1000);
                                   for (std::size_t k = 0; k < t.figures.hypsometric_area.size(); ++k)
                                       s.points.emplace_back(t.figures.hypsometric_area[k], double(k) / 100.0);
                                   return s;
                               },
                               "lines")});
    pending.push_back({{stem + "-spectrum.png", "Radially averaged power spectrum"},
                       header("Power spectrum (Perron et al. 2008), normalised at k = 4", "wavelength (m)",
                              "power / power at k = 4") +
                           "set logscale xy\n" +
                           plot(
                               terrains, "spec",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   const auto& f = t.figures;
                                   const auto& beta = f[FigureId::spectral_exponent];
                                   if (!beta.ok() || f.spectrum_power.size() < 4 || !(f.spectrum_power[3] > 0.0))
                                       return s;
                                   s.title += ": β " + number(std::round(beta.value * 100) / 100);
                                   for (std::size_t k = 0; k < f.spectrum_k.size(); ++k)
                                       if (f.spectrum_power[k] > 0.0)
                                           s.points.emplace_back(double(f.spectrum_side) * f.cell / f.spectrum_k[k],
                                                                 f.spectrum_power[k] / f.spectrum_power[3]);
                                   return s;
                               },
                               "lines")});
}

/// The channels' charts: slope–area, Hack's law, the valley cross-section and valley width against area.
void channel_charts(const std::vector<Terrain>& terrains, const std::string& stem, std::vector<Pending>& pending) {
    using analysis::FigureId;
    pending.push_back({{stem + "-slope-area.png", "Slope–area (channel cells)"},
                       header("Slope–area of the channels (A > 1 km²), log-binned; lines: the fits",
                              "drainage area A (m²)", "slope S (m/m)") +
                           "set logscale xy\n" +
                           plot(
                               terrains, "sa",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   const auto& f = t.figures;
                                   if (!f[FigureId::concavity].ok()) return s;
                                   s.title += ": θ " + number(std::round(f[FigureId::concavity].value * 100) / 100) +
                                       ", k_sn " + number(std::round(f[FigureId::steepness].value));
                                   s.points = binned(f.slope_area);
                                   return s;
                               },
                               "points pt 7 ps 0.8",
                               [](const Terrain& t) {
                                   const auto& f = t.figures;
                                   return f[FigureId::concavity].ok() ? fitted(f.slope_area, f.slope_area_fit)
                                                                      : std::vector<std::pair<double, double>>{};
                               })});
    pending.push_back({{stem + "-hack.png", "Hack's law"},
                       header("Hack's law L = c A^h (channel cells, log-binned; lines: the fits)",
                              "drainage area A (m²)", "longest flow path upstream L (m)") +
                           "set logscale xy\n" +
                           plot(
                               terrains, "hack",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   const auto& f = t.figures;
                                   if (!f[FigureId::hack_exponent].ok()) return s;
                                   s.title += ": h " + number(std::round(f[FigureId::hack_exponent].value * 100) / 100);
                                   s.points = binned(f.hack);
                                   return s;
                               },
                               "points pt 7 ps 0.8",
                               [](const Terrain& t) {
                                   const auto& f = t.figures;
                                   return f[FigureId::hack_exponent].ok() ? fitted(f.hack, f.hack_fit)
                                                                          : std::vector<std::pair<double, double>>{};
                               })});

    pending.push_back({{stem + "-valley-section.png", "Valley cross-section"},
                       header("Median valley cross-section across the channels (A > 1 km²)",
                              "distance from the river (m)", "height above the river (m)") +
                           "set yrange [0:*]\n" +
                           plot(
                               terrains, "vsec",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   const auto& f = t.figures;
                                   const auto& width = f[FigureId::valley_width];
                                   if (width.ok()) s.title += ": " + number(std::round(width.value)) + " m at 10 m";
                                   // Both sides, mirrored: the section is the mean of the two.
                                   const int reach = int(f.valley_section.size()) - 1;
                                   for (int d = -reach; d <= reach && reach > 0; ++d)
                                       s.points.emplace_back(d * f.cell, f.valley_section[std::size_t(std::abs(d))]);
                                   return s;
                               },
                               "linespoints pt 7 ps 0.6")});
    pending.push_back({{stem + "-valley-width.png", "Valley width against drainage area"},
                       header("Valley width 10 m above the river against drainage area; lines: W = c A^b",
                              "drainage area A (m²)", "valley width W (m)") +
                           "set logscale xy\n" +
                           plot(
                               terrains, "vw",
                               [](const Terrain& t) {
                                   Series s{{}, t.name};
                                   const auto& f = t.figures;
                                   if (!f[FigureId::valley_widening].ok()) return s;
                                   s.title +=
                                       ": b " + number(std::round(f[FigureId::valley_widening].value * 100) / 100);
                                   s.points = binned(f.valley_widths);
                                   return s;
                               },
                               "points pt 7 ps 0.8",
                               [](const Terrain& t) {
                                   const auto& f = t.figures;
                                   return f[FigureId::valley_widening].ok()
                                       ? fitted(f.valley_widths, f.valley_widths_fit)
                                       : std::vector<std::pair<double, double>>{};
                               })});
}

}  // namespace

ChartsWritten write_charts(const std::vector<Terrain>& terrains, const std::filesystem::path& folder,
                           const std::string& stem) {
    std::vector<Pending> pending;
    whole_map_charts(terrains, stem, pending);
    channel_charts(terrains, stem, pending);

    ChartsWritten written;
    std::vector<std::unique_ptr<AtomicFile>> files;
    std::string script =
        "set terminal pngcairo size 960,600 font 'Sans,11'\nset termoption noenhanced\n"
        "set encoding utf8\n";
    for (auto& p : pending) {
        if (p.body.find("plot ") == std::string::npos) continue;  // no terrain has data for it
        files.push_back(std::make_unique<AtomicFile>(folder / p.chart.file));
        files.back()->stream().close();  // gnuplot writes the temporary file by name
        script += "set output " + gp_string(files.back()->temporary().string()) + "\n" + p.body + "unset output\n";
        written.charts.push_back(p.chart);
    }
    if (files.empty()) return written;
    const std::string problem = run_gnuplot(script, folder);
    if (!problem.empty()) {
        written.charts.clear();
        written.problem = problem;
        return written;  // the AtomicFiles remove their temporaries
    }
    std::vector<AtomicFile*> all;
    for (auto& f : files) all.push_back(f.get());
    commit_all(all);
    return written;
}

}  // namespace orogen::analyze
