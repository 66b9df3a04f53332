// `orogen analyze FILE... [--against DEM...]`: the command line turned into a spec the normal runner
// runs — an import node per file (chosen by its extension), analyze:terrain over all of them (the
// --against files last, as references), and render:terrain + export:png per terrain with one camera.
// With --discriminate, analyze:discriminate over all of them instead (the generated terrains first, the
// real DEMs last). The kernel stays free of libs/: the measuring is the plugins'; this file only writes
// spec text.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace orogen::cli {

struct AnalyzeArgs {
    std::vector<std::string> files;  ///< terrains to measure
    std::vector<std::string> against;  ///< references (real DEMs)
    std::string out = "analysis";  ///< --out
    std::optional<double> cell;  ///< --cell M: the cell size of every file (m)
    std::optional<std::pair<double, double>> heights;  ///< --heights LOW:HIGH, metres of a PNG's black and white
    bool render = true;  ///< --no-render: no pictures
    /// --fit-filled-flats: the channel cells the priority flood raised enter the θ, k_sn and Hack fits, as in
    /// terrain_stats.py (analyze:terrain's filled_flats=fit; docs/analysis.md, "Real-world rasters"). By
    /// default (--skip-filled-flats) they stay out.
    bool fit_filled_flats = false;
    bool skip_filled_flats = false;  ///< --skip-filled-flats given (the default, spelled out)
    /// --discriminate: instead of the figures' table, whether a classifier tells the terrains from the
    /// --against DEMs window by window (analyze:discriminate); no renderings.
    bool discriminate = false;
    std::optional<double> window_m;  ///< --window-m M: the windows' side in metres (--discriminate)
    bool quiet = false;
    int threads = 0;
};

/// Parses argv[2...] of `orogen analyze`. Returns an error message (usage error) or "".
std::string parse_analyze_args(int argc, char** argv, AnalyzeArgs& args);

/// The spec text, or an error message (a file that is missing, not a regular file, of an unknown
/// kind, or lacking what its kind needs) in `problem`, naming the file and the fix.
struct ComposedSpec {
    std::string text;
    std::string problem;
    std::vector<std::string> names;  ///< each terrain's name in the report, files then references
};
ComposedSpec compose_analyze_spec(const AnalyzeArgs& args);

}  // namespace orogen::cli
