// Progress and timing as the runner's hook (hooks.hpp): the bar or line of
// each node that runs, the line of each node that does not (with what it said
// when it ran, replayed), and each node's seconds in the timing table.
#include "hooks/hooks.hpp"
#include "progress.hpp"

#include <chrono>

namespace orogen {

namespace {

class ProgressHooks final : public NodeHooks {
public:
    explicit ProgressHooks(RunShared& shared) : shared_(shared), started_(shared.plan.nodes.size()) {}

    bool before_node(const NodeTurn& turn, std::vector<Value>&) override {
        if (ProgressDisplay* progress = shared_.options.progress)
            progress->start(int(turn.index) + 1, total(), turn.node.label, turn.node.node->qualified_name());
        started_[turn.index] = std::chrono::steady_clock::now();
        return true;
    }

    void after_node(const NodeTurn& turn) override {
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - started_[turn.index]).count();
        if (shared_.options.progress) shared_.options.progress->finish(seconds);
        turn.timing.seconds += seconds;
    }

    void skipped(const NodeTurn& turn, const Reuse& reuse) override {
        ProgressDisplay* progress = shared_.options.progress;
        if (!progress) return;
        for (const auto& line : reuse.said)  // replayed as the node said them: "label: ..." or "label: warning: ..."
            progress->message(line,
                              line.find(": warning: ") != std::string::npos ? ProgressDisplay::Kind::warning
                                                                            : ProgressDisplay::Kind::info);
        progress->skipped(int(turn.index) + 1, total(), turn.node.label, turn.node.node->qualified_name(), reuse.why);
    }

private:
    int total() const { return int(shared_.plan.nodes.size()); }

    RunShared& shared_;
    std::vector<std::chrono::steady_clock::time_point> started_;  ///< per node: when it started
};

}  // namespace

std::unique_ptr<NodeHooks> progress_hooks(RunShared& shared) { return std::make_unique<ProgressHooks>(shared); }

}  // namespace orogen
