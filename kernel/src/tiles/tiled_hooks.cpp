// A tiled run's agreement as the runner's hook (run/hooks.hpp): before each
// node every rank gets what it reads (tiles, or whole values on rank 0), after
// it every rank learns whether any rank failed (the lowest failing rank
// reports), and at the end the digests other ranks took of the files they
// wrote go to rank 0, which writes the manifest.
#include "tiles.hpp"

#include "io/digest.hpp"
#include "hooks/hooks.hpp"

#include <filesystem>

namespace fs = std::filesystem;

namespace orogen {

namespace {

class TiledHooks final : public NodeHooks {
public:
    TiledHooks(RunShared& shared, TiledRun& tiled) : shared_(shared), tiled_(tiled) {}

    // Collective: tiles for a tiled node, the whole values on rank 0 for the others.
    bool before_node(const NodeTurn& turn, std::vector<Value>& inputs) override {
        return tiled_.prepare_inputs(turn.node, inputs);
    }

    // A tiled run goes on only if every rank finished the node; one rank (the lowest that failed) reports.
    void settle(const NodeTurn&, Outcome& outcome) override {
        if (outcome.agreed) return;
        agree_across_ranks(tiled_, outcome.exit_code, outcome.error);
        outcome.agreed = true;
    }

    void after_node(const NodeTurn& turn) override { tiled_.produced(turn.node); }

    void run_finished() override { share_digests(shared_.result.exit_code == 0); }

private:
    /// Collective, after the last node: the digests the other ranks took while writing their files into the
    /// staging folder go to rank 0, which adopts those whose file it sees unchanged, so the manifest does not
    /// read them again (a world's engine tiles can be gigabytes). Every rank calls it, failed or not.
    void share_digests(bool ok) {
        const fs::path& staging_folder = shared_.staging_folder;
        std::string mine;  // records of three fields, each ended by '\0': path in the folder, digest, identity
        if (ok && tiled_.rank() != 0) {
            std::error_code ec;
            for (auto it = fs::recursive_directory_iterator(staging_folder, ec);
                 !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
                if (!it->is_regular_file(ec)) continue;
                const std::string hex = detail::remembered_sha256(it->path());  // "" for files this rank did not write
                if (hex.empty()) continue;
                for (const std::string& field :
                     {fs::relative(it->path(), staging_folder, ec).string(), hex, detail::file_identity(it->path())})
                    mine.append(field).push_back('\0');
            }
        }
        const std::vector<std::string> all = tiled_.gather_text(mine);
        for (const std::string& text : all) {
            std::vector<std::string> fields;
            for (std::size_t at = 0; at < text.size();) {
                const std::size_t end = text.find('\0', at);
                if (end == std::string::npos) break;
                fields.push_back(text.substr(at, end - at));
                at = end + 1;
            }
            for (std::size_t k = 0; k + 2 < fields.size(); k += 3)
                detail::adopt_sha256(staging_folder / fields[k], fields[k + 1], fields[k + 2]);
        }
    }

    RunShared& shared_;
    TiledRun& tiled_;
};

}  // namespace

void agree_across_ranks(TiledRun& tiled, int& exit_code, std::string& error) {
    const int mine = exit_code;
    int reporter = 0;
    const int worst = tiled.agree(mine, &reporter);
    if (worst != 0 && (mine == 0 || reporter != tiled.rank())) error.clear();
    exit_code = worst;
}

std::unique_ptr<NodeHooks> tiled_hooks(RunShared& shared) {
    if (!shared.options.tiled) return nullptr;
    return std::make_unique<TiledHooks>(shared, *shared.options.tiled);
}

}  // namespace orogen
