// loop.cpp — the process loop (see loop.hpp).
#include <orogen/landscape/loop.hpp>
#include <orogen/landscape/stream_power.hpp>

#include <orogen/error.hpp>
#include <orogen/random.hpp>

#include <algorithm>
#include <cmath>

namespace orogen::landscape {

std::vector<std::uint8_t> outlet_mask(int width, int height, const OpenSides& open,
                                      const std::vector<double>& heights) {
    std::vector<std::uint8_t> mask(std::size_t(width) * std::size_t(height), 0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const bool o = (y == 0 && open.north) || (y == height - 1 && open.south) || (x == 0 && open.west) ||
                (x == width - 1 && open.east);
            mask[std::size_t(y) * std::size_t(width) + std::size_t(x)] = o ? 1 : 0;
        }
    if (!open.any()) mask[std::size_t(lowest_cell(heights))] = 1;
    return mask;
}

ProcessLoop::ProcessLoop(const std::vector<ProcessCall>& calls, std::shared_ptr<Heightmap> terrain,
                         std::vector<Value> inputs, Options options)
    : width_(terrain->width()), height_(terrain->height()), cell_(terrain->cell()), options_(std::move(options)),
      terrain_(std::move(terrain)), inputs_(std::move(inputs)) {
    if (options_.substeps < 1) throw Error("the loop needs at least one sub-step");
    elevation_.assign(terrain_->heights().begin(), terrain_->heights().end());
    uplifted_.assign(elevation_.size(), 0.0);
    // The outlets come from the heights as given (the lowest cell of a closed map), then take the base level.
    outlets_ = outlet_mask(width_, height_, options_.open, elevation_);
    if (options_.base_level)
        for (std::size_t i = 0; i < elevation_.size(); ++i)
            if (outlets_[i]) elevation_[i] = *options_.base_level;
    for (const auto& call : calls) {
        current_ = processes_.size();
        processes_.push_back({&call, nullptr});
        processes_.back().process = call.process->make(call);
        if (!processes_.back().process)
            throw Error("internal error: process '" + call.label + "' made nothing (its descriptor's make)");
    }
}

void ProcessLoop::each(const std::function<void(Process&)>& run) {
    for (current_ = 0; current_ < processes_.size(); ++current_) run(*processes_[current_].process);
}

void ProcessLoop::start() {
    step_ = 0;
    each([&](Process& p) { p.start(*this); });
}

void ProcessLoop::advance(double dt) {
    ++step_;
    step_years_ = dt;
    const double sub = dt / options_.substeps;  // yr: each sub-step's share (dt / 1 = dt exactly)
    for (substep_ = 0; substep_ < options_.substeps; ++substep_)
        for (current_ = 0; current_ < processes_.size(); ++current_) {
            const auto& r = processes_[current_];
            if (substep_ > 0 && r.call->process->cadence == Cadence::once_per_step) continue;
            r.process->step(*this, sub);
        }
    substep_ = 0;
    time_ += dt;
}

void ProcessLoop::run(double years, double dt, const std::function<void(std::int64_t, std::int64_t)>& on_step) {
    if (!(years > 0.0) || !(dt > 0.0)) throw Error("the loop's years and dt must be > 0");
    const auto steps = std::int64_t(std::ceil(years / dt * (1.0 - 1e-12)));
    for (std::int64_t s = 1; s <= steps; ++s) {
        const double this_dt = s < steps ? dt : years - dt * double(steps - 1);
        advance(this_dt);
        if (on_step) on_step(s, steps);
    }
}

void ProcessLoop::finish() {
    std::vector<float>& out = terrain_->heights();
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = float(elevation_[i]);
    each([&](Process& p) { p.finish(*this, *terrain_); });
}

std::int64_t ProcessLoop::first_non_finite() const {
    for (std::size_t i = 0; i < elevation_.size(); ++i)
        if (!std::isfinite(elevation_[i])) return std::int64_t(i);
    return -1;
}

std::vector<std::string> ProcessLoop::summaries() const {
    std::vector<std::string> out;
    for (const auto& r : processes_)
        if (std::string s = r.process->summary(); !s.empty()) out.push_back(r.call->label + ": " + s);
    return out;
}

std::vector<double>& ProcessLoop::field(std::string_view name) {
    if (name == kElevation) return elevation_;
    if (name == kUplifted) return uplifted_;
    const ProcessCall& call = *processes_[std::min(current_, processes_.size() - 1)].call;
    const auto& fields = call.process->fields;
    if (std::none_of(fields.begin(), fields.end(), [&](const FieldUse& f) { return f.field == name; }))
        throw Error("process '" + call.label + "' uses the field '" + std::string(name) +
                    "', which its descriptor does not declare; declare it in ProcessDescriptor::fields");
    return fields_[std::string(name)];
}

std::vector<double>* ProcessLoop::find_field(std::string_view name) {
    if (name == kElevation) return &elevation_;
    if (name == kUplifted) return &uplifted_;
    const auto names = field_names();
    if (std::find(names.begin(), names.end(), name) == names.end()) return nullptr;
    return &fields_[std::string(name)];
}

std::vector<std::string> ProcessLoop::field_names() const {
    std::vector<std::string> names = {kElevation, kUplifted};
    for (const auto& r : processes_)
        for (const auto& f : r.call->process->fields)
            if (f.field != kFlowGraph && std::find(names.begin(), names.end(), f.field) == names.end())
                names.push_back(f.field);
    std::sort(names.begin(), names.end());
    return names;
}

bool ProcessLoop::wanted(std::string_view name) const {
    for (std::size_t k = 0; k < processes_.size(); ++k) {
        if (k == current_) continue;
        for (const auto& f : processes_[k].call->process->fields)
            if (f.field == name && f.access != FieldAccess::writes) return true;
    }
    return false;
}

std::uint64_t ProcessLoop::seed() const {
    const std::string& label = processes_[std::min(current_, processes_.size() - 1)].call->label;
    if (label.find('#') == std::string::npos) return options_.seed;
    return random::hash(options_.seed, random::hash_string(label));
}

const Value& ProcessLoop::node_input(std::size_t i) const {
    static const Value empty;
    return i < inputs_.size() ? inputs_[i] : empty;
}

void ProcessLoop::info(std::string_view message) {
    if (options_.info)
        options_.info(processes_.empty() ? std::string(message)
                                         : processes_[std::min(current_, processes_.size() - 1)].call->label + ": " +
                              std::string(message));
}

void ProcessLoop::warn(std::string_view message) {
    if (options_.warn)
        options_.warn(processes_.empty() ? std::string(message)
                                         : processes_[std::min(current_, processes_.size() - 1)].call->label + ": " +
                              std::string(message));
}

}  // namespace orogen::landscape
