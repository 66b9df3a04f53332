// A figure program (not a test): erode:sph's solver against Martin & Moyce (1952) in 3-D with side walls, at
// the size the erosion runs (≥ 10⁵ particles), and a resting tank against hydrostatics. For docs/erosion.md:
//   build/bin/sph_validation [across=40] [deep=32] [a=0.05715] [tank=24] [cfl=0.4] [viscosity=0.05] [friction=0]
//       [out=PREFIX] [peer=NAME:FILE ...]
// prints the front Z against T and the column's height η against τ beside Martin & Moyce's tables, the
// milliseconds per sub-step, and the resting tank's layer pressures; with out=PREFIX writes PREFIX.dat
// (T Z, τ η) and PREFIX.png (gnuplot). peer=NAME:FILE adds a second reference's "T Z" lines to the plot
// (SPlisHSPlasH, see docs/erosion.md).
#include "dambreak.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace orogen;
using namespace orogen::sph_validation;

int main(int argc, char** argv) {
    int across = 40, deep = 32, tank_x = 24, tank_y = 24, tank_z = 24;
    double a = 0.05715;  // Martin & Moyce's a = 2¼ in
    double cfl = -1, viscosity = -1, friction = -1;  // < 0: dambreak.hpp's (erode:sph's)
    std::string out;
    std::vector<std::string> peers;
    for (int k = 1; k < argc; ++k) {
        const std::string arg = argv[k];
        const auto eq = arg.find('=');
        const std::string key = arg.substr(0, eq), v = eq == std::string::npos ? "" : arg.substr(eq + 1);
        if (key == "across") across = std::stoi(v);
        else if (key == "deep") deep = std::stoi(v);
        else if (key == "a") a = std::stod(v);
        else if (key == "out") out = v;
        else if (key == "peer") peers.push_back(v);
        else if (key == "tank") tank_x = tank_y = tank_z = std::stoi(v);
        else if (key == "cfl") cfl = std::stod(v);
        else if (key == "viscosity") viscosity = std::stod(v);
        else if (key == "friction") friction = std::stod(v);
        else {
            std::fprintf(stderr,
                         "usage: sph_validation [across=40] [deep=32] [a=0.05715] [tank=24] [cfl=0.4] [viscosity=0.05] "
                         "[friction=0] [out=PREFIX] [peer=NAME:FILE ...]\n");
            return 2;
        }
    }
    DamBreak db(a, across, deep, [&](sph::Settings& set) {
        if (cfl > 0) set.cfl = cfl;
        if (viscosity >= 0) set.viscosity = viscosity;
        if (friction >= 0) set.friction = friction;
    });
    std::printf("dam break: a = %.5f m, %d x %d x %d = %zu particles, spacing %.3f mm, tank %.3f x %.3f m\n", a, across,
                2 * across, deep, db.sim().size(), 1e3 * db.spacing(), 5.0 * a, deep * db.spacing());
    struct Sample {
        double T, Z, tau, eta;
    };
    std::vector<Sample> samples;
    const auto t0 = std::chrono::steady_clock::now();
    const double T_end = 3.0, dT = 0.05;
    for (int k = 0; k * dT <= T_end + 1e-9; ++k) {
        db.run_to(db.time_of_T(k * dT));
        samples.push_back({db.T(), db.front(), db.sim().time() / db.time_of_tau(1.0), db.height()});
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%lld sub-steps in %.1f s: %.2f ms per sub-step\n", (long long)db.sim().substeps(), secs,
                1e3 * secs / double(db.sim().substeps()));
    const auto at = [&](double x, auto key, auto val) {  // linear interpolation of the samples
        for (std::size_t k = 1; k < samples.size(); ++k)
            if (key(samples[k]) >= x) {
                const double f = (x - key(samples[k - 1])) / (key(samples[k]) - key(samples[k - 1]));
                return val(samples[k - 1]) + f * (val(samples[k]) - val(samples[k - 1]));
            }
        return val(samples.back());
    };
    double worst = 0.0;
    std::printf("\n| T = t·√(2g/a) | Martin & Moyce Z | erode:sph Z | difference |\n|---|---|---|---|\n");
    for (const FrontPoint& p : kMartinMoyceFront) {
        const double Z = at(
            p.T, [](const Sample& s) { return s.T; }, [](const Sample& s) { return s.Z; });
        const double d = (Z - p.Z) / p.Z;
        if (p.Z >= 1.2) worst = std::max(worst, std::abs(d));
        std::printf("| %.2f | %.2f | %.3f | %+.1f %% |\n", p.T, p.Z, Z, 100.0 * d);
    }
    std::printf("largest |difference| over Z = 1.2–3.7: %.1f %%\n", 100.0 * worst);
    double worst_h = 0.0;
    std::printf("\n| τ = t·√(g/a) | Martin & Moyce η | erode:sph η | difference |\n|---|---|---|---|\n");
    for (const HeightPoint& p : kMartinMoyceHeight) {
        if (p.tau > samples.back().tau) break;
        const double eta = at(
            p.tau, [](const Sample& s) { return s.tau; }, [](const Sample& s) { return s.eta; });
        const double d = (eta - p.eta) / p.eta;
        worst_h = std::max(worst_h, std::abs(d));
        std::printf("| %.2f | %.2f | %.3f | %+.1f %% |\n", p.tau, p.eta, eta, 100.0 * d);
    }
    std::printf("largest |difference| of η: %.1f %%\n", 100.0 * worst_h);

    // The resting tank: tank³ particles, walls all round, settled for 40 sound crossings of its depth.
    RestingTank tank(tank_x, tank_y, tank_z, a / across);
    const double depth = tank_y * tank.s;
    const auto t1 = std::chrono::steady_clock::now();
    const double settle = 40.0 * depth / (10.0 * std::sqrt(2.0 * kGravity * depth));
    for (int step = 1; tank.sim.time() < settle; ++step)
        tank.sim.advance(std::min(0.01, settle - tank.sim.time()), step);
    const double secs_t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    std::printf(
        "\nresting tank: %d x %d x %d = %zu particles, settled %.3f s (%lld sub-steps, %.1f s); free surface "
        "%.4f m (filled to %.4f m)\n",
        tank_x, tank_y, tank_z, tank.sim.size(), settle, (long long)tank.sim.substeps(), secs_t, tank.surface(), depth);
    double worst_p = 0.0;
    std::printf(
        "\n| depth (m) | mean pressure (Pa) | ρ0·g·depth (Pa) | difference | particles |\n|---|---|---|---|---|\n");
    for (const Layer& L : tank.layers()) {
        const double d = (L.pressure - L.expect) / L.expect;
        worst_p = std::max(worst_p, std::abs(d));
        std::printf("| %.4f | %.1f | %.1f | %+.2f %% | %d |\n", L.depth, L.pressure, L.expect, 100.0 * d, L.count);
    }
    std::printf("largest |difference| of a layer's pressure: %.2f %%\n", 100.0 * worst_p);

    if (!out.empty()) {
        std::ofstream dat(out + ".dat");
        dat << "# erode:sph dam break, " << db.sim().size() << " particles: T Z tau eta\n";
        for (const Sample& s : samples) dat << s.T << ' ' << s.Z << ' ' << s.tau << ' ' << s.eta << '\n';
        dat << "\n\n# Martin & Moyce front: T Z\n";
        for (const FrontPoint& p : kMartinMoyceFront) dat << p.T << ' ' << p.Z << '\n';
        dat << "\n\n# Martin & Moyce height: tau eta\n";
        for (const HeightPoint& p : kMartinMoyceHeight) dat << p.tau << ' ' << p.eta << '\n';
        dat.close();
        std::string plot =
            "set terminal pngcairo size 1200,500 font 'Sans,11'\nset termoption noenhanced\nset output '" + out +
            ".png'\nset multiplot layout 1,2\nset grid\nset key top left\n"
            "set xlabel 'T = t·√(2g/a)'\nset ylabel 'front Z = x/a'\nset xrange [0:3]\n"
            "plot '" +
            out + ".dat' index 0 using 1:2 with lines lw 2 title 'erode:sph (" + std::to_string(db.sim().size()) +
            " particles)', '" + out + ".dat' index 1 using 1:2 with points pt 7 ps 1.2 title 'Martin & Moyce 1952'";
        for (const std::string& p : peers) {
            const auto colon = p.find(':');
            plot += ", '" + p.substr(colon + 1) + "' using 1:2 with lines lw 2 dt 2 title '" + p.substr(0, colon) + "'";
        }
        plot +=
            "\nset key top right\nset xlabel 'τ = t·√(g/a)'\nset ylabel 'column height η = h/(2a)'\n"
            "set xrange [0:2.2]\nplot '" +
            out + ".dat' index 0 using 3:4 with lines lw 2 title 'erode:sph', '" + out +
            ".dat' index 2 using 1:2 with points pt 7 ps 1.2 title 'Martin & Moyce 1952'\nunset multiplot\n";
        if (FILE* gp = popen("gnuplot", "w")) {
            std::fputs(plot.c_str(), gp);
            if (pclose(gp) != 0) std::fprintf(stderr, "gnuplot failed: %s.png not written\n", out.c_str());
        }
    }
    return 0;
}
