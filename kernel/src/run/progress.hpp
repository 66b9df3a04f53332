// What the user sees while a spec runs: a progress bar per node on a
// terminal (redrawn in place), plain lines otherwise (logs, CI), and the
// per-node timing table at the end.
#pragma once

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

namespace orogen {

class ProgressDisplay {
public:
    /// `out` is usually stderr; `terminal` decides bars vs plain lines.
    ProgressDisplay(std::FILE* out, bool terminal, bool quiet);

    void start(int index, int total, const std::string& label, const std::string& node);
    void update(double fraction);
    void finish(double seconds);
    /// A node that does not run: "[3/9] summit (generate:rmp) cached".
    void skipped(int index, int total, const std::string& label, const std::string& node, const std::string& why);
    /// A log line, keeping the bar intact. --quiet drops what a node says for information (a run that succeeds is
    /// then silent) but never a warning.
    enum class Kind { info, warning };
    void message(const std::string& text, Kind kind);

private:
    void draw(bool force);
    void clear_bar();

    std::FILE* out_;
    bool terminal_, quiet_;
    std::mutex mutex_;
    int index_ = 0, total_ = 0;
    std::string label_, node_;
    double fraction_ = 0.0;
    int last_decile_ = -1;
    bool bar_shown_ = false;
    std::chrono::steady_clock::time_point started_, last_draw_;
};

}  // namespace orogen
