#include "progress.hpp"

#include <algorithm>
#include <cmath>

namespace orogen {

using clock_type = std::chrono::steady_clock;

ProgressDisplay::ProgressDisplay(std::FILE* out, bool terminal, bool quiet)
    : out_(out), terminal_(terminal), quiet_(quiet) {}

void ProgressDisplay::start(int index, int total, const std::string& label, const std::string& node) {
    std::lock_guard lock(mutex_);
    index_ = index;
    total_ = total;
    label_ = label;
    node_ = node;
    fraction_ = 0.0;
    last_decile_ = 0;
    started_ = clock_type::now();
    last_draw_ = started_ - std::chrono::seconds(1);
    if (quiet_) return;
    if (terminal_) draw(true);
}

void ProgressDisplay::update(double fraction) {
    if (quiet_) return;
    std::lock_guard lock(mutex_);
    fraction_ = std::clamp(fraction, 0.0, 1.0);
    if (terminal_) {
        draw(false);
        return;
    }
    // Plain lines: one per 10 %, and only for nodes that run long enough to care (> 1 s).
    const int decile = int(std::floor(fraction_ * 10.0));
    const double elapsed = std::chrono::duration<double>(clock_type::now() - started_).count();
    if (decile > last_decile_ && decile < 10 && elapsed > 1.0) {
        last_decile_ = decile;
        std::fprintf(out_, "[%d/%d] %s (%s) %d%% %.1f s\n", index_, total_, label_.c_str(), node_.c_str(), decile * 10,
                     elapsed);
        std::fflush(out_);
    }
}

void ProgressDisplay::draw(bool force) {
    const auto now = clock_type::now();
    if (!force && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    const double elapsed = std::chrono::duration<double>(now - started_).count();
    constexpr int width = 24;
    const int filled = int(std::lround(fraction_ * width));
    std::string bar(std::size_t(filled), '#');
    bar.append(std::size_t(width - filled), '-');
    std::fprintf(out_, "\r\033[K[%d/%d] %-14s %-22s [%s] %3d%% %6.1f s", index_, total_, label_.c_str(), node_.c_str(),
                 bar.c_str(), int(std::lround(fraction_ * 100)), elapsed);
    std::fflush(out_);
    bar_shown_ = true;
}

void ProgressDisplay::clear_bar() {
    if (bar_shown_) {
        std::fprintf(out_, "\r\033[K");
        bar_shown_ = false;
    }
}

void ProgressDisplay::finish(double seconds) {
    if (quiet_) return;
    std::lock_guard lock(mutex_);
    if (terminal_) clear_bar();
    std::fprintf(out_, "[%d/%d] %s (%s) done in %.3f s\n", index_, total_, label_.c_str(), node_.c_str(), seconds);
    std::fflush(out_);
}

void ProgressDisplay::skipped(int index, int total, const std::string& label, const std::string& node,
                              const std::string& why) {
    if (quiet_) return;
    std::lock_guard lock(mutex_);
    if (terminal_) clear_bar();
    std::fprintf(out_, "[%d/%d] %s (%s) %s\n", index, total, label.c_str(), node.c_str(), why.c_str());
    std::fflush(out_);
}

void ProgressDisplay::message(const std::string& text, Kind kind) {
    if (quiet_ && kind == Kind::info) return;
    std::lock_guard lock(mutex_);
    if (terminal_) clear_bar();
    std::fprintf(out_, "%s\n", text.c_str());
    std::fflush(out_);
    if (terminal_ && !quiet_ && total_ > 0) draw(true);
}

}  // namespace orogen
