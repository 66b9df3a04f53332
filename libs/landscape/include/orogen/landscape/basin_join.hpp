// basin_join.hpp — the basin graph of a tiled run, solved mostly on the tiles.
//
// The whole-grid router (flow.hpp) joins pit basins by the minimum spanning
// tree of the basin graph under link_before's strict total order, oriented
// from the sea. A tiled run gets the same tree without sending rank 0 every
// link, as Barnes (2016) does for priority-flood: most lakes are settled on
// their own tile.
//
// A basin is *closed* on a tile when all its cells lie inside the tile, off
// its edge: every link it has is then among the tile's own. Every other basin
// the tile sees (the sea, a basin touching the tile's edge, another tile's
// basin) is an *anchor*. The tile runs Kruskal over its links in the total
// order and takes a link at once when one side's component holds closed
// basins only: all of that component's links are the tile's, so this is its
// lowest link out, and the lowest link out of any set of nodes is in the
// (unique) spanning tree. A link between two components that each hold an
// anchor is *deferred*: only rank 0, seeing every tile, can tell. Components
// grow only by taking in closed ones, so each ends holding exactly one anchor.
//
// The tile sends rank 0 its deferred links (the lowest per pair of
// components: a higher parallel link is never in the tree) and its forest
// reduced to what rank 0 needs: the anchors, the deferred links' ends, the
// forks between them, and between neighbouring ones the highest pass on the
// way (ForestEdge). Rank 0 merges the forests' edges (all in the tree), takes
// the deferred links by Kruskal, and orients the result from the sea: every
// key basin's lake level and where it drains (KeyExit). Each tile then walks
// each of its components down from the basin nearest the sea (the one whose
// way out leaves the component) and so orients and levels its closed basins
// itself (BasinExit). Levels are maxima of passes: exact, the same bits as
// the whole-grid tree.
#pragma once

#include "flow.hpp"

#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

namespace orogen::landscape {

/// The way between two key basins of a tile's forest: `lower` hangs below `upper` (upper is nearer its anchor).
struct ForestEdge {
    std::int64_t lower, upper;  ///< basins (pits' whole-grid cells; −1 the sea)
    double pass;  ///< the highest pass on the way, m
    Link first;  ///< the way's link at `upper`'s end (upper's cell is i if upper == a, else j)
};

/// What one tile settles of its basins, and what it leaves to rank 0.
struct TileForest {
    std::vector<std::int64_t> anchors;  ///< the components' anchors (basin ids)
    std::vector<Link> deferred;  ///< for rank 0: links between components, the lowest per pair, in the total order
    std::vector<ForestEdge> edges;  ///< for rank 0: the forest reduced to its key basins
    // The forest itself (for orient_tile): nodes are indices.
    std::vector<std::int64_t> basin;  ///< node → basin
    std::unordered_map<std::int64_t, std::int32_t> node;  ///< basin → node
    std::vector<std::int32_t> anchor;  ///< node → its component's anchor node
    std::vector<std::uint8_t> closed;  ///< node → closed on this tile
    std::vector<Link> taken;  ///< the forest's links
    std::vector<std::int32_t> taken_ends;  ///< their two nodes each (a's, then b's)
    std::vector<std::int64_t> adjacent_start;  ///< node → first entry in `adjacent` (+ end)
    std::vector<std::int32_t> adjacent;  ///< indices into `taken`
};

/// `links`: the tile's lowest link per pair of basins (a < b, −1 the sea);
/// `closed(basin)`: whether all of that basin's links are among them.
TileForest contract_tile(std::vector<Link> links, const std::function<bool(std::int64_t)>& closed);

/// Rank 0's answer for a key basin: its lake level and how it drains.
struct KeyExit {
    std::int64_t basin;
    double level;  ///< m; −inf for the sea
    std::int64_t parent;  ///< the basin it drains into; −2 for the sea
    std::int64_t in,
        across;  ///< the cells of its way out (in its basin, across); −1 when the way is a forest edge it hangs by (its tile walks it)
};

/// Rank 0: every tile's deferred links, forest edges and anchors joined into
/// the spanning tree, oriented from the sea. One KeyExit per key basin, the sea's included.
/// Throws std::logic_error if a basin has no way to the sea.
std::vector<KeyExit> join_tiles(std::vector<Link> deferred, const std::vector<ForestEdge>& edges,
                                const std::vector<std::int64_t>& anchors);

/// A closed basin's lake level and way out.
struct BasinExit {
    std::int64_t basin;
    double level;  ///< m
    std::int64_t in, across;  ///< its pass cell (in the basin) and the cell across, which it now drains to
};

/// A tile: its closed basins oriented from rank 0's key exits (every key basin of the tile among them).
std::vector<BasinExit> orient_tile(const TileForest& forest, const std::unordered_map<std::int64_t, KeyExit>& keys);

}  // namespace orogen::landscape
