// flow.hpp — single-flow (D8) routing with depressions resolved, the order
// in which the implicit stream-power solver visits the cells, and drainage area.
//
// Every cell sends its water to one receiver: the neighbour (of 8) with the
// steepest drop, (h_i − h_k)/distance. Cells on an open side are outlets
// (their own receiver); with every side closed, the lowest cell of the start
// heights is the one outlet (a declared sink, the base level). A cell with
// no lower neighbour that is not an outlet is a pit.
//
// Pits are resolved as Cordonnier, Bovy & Braun (2019) do: the cells are cut
// into basins (the cells that drain to one outlet or pit), adjacent basins are
// joined at their lowest pass (the lower of the higher cell over each edge
// between them), and a minimum spanning tree of the basin graph (Kruskal; every
// outlet basin is one node, the sea) gives each pit basin the pass its water
// leaves by. The receivers on the path from the pass cell down to the pit are
// reversed and the pass cell sends its water across: the result is a tree
// rooted at the outlets, so every cell drains to an outlet and there is no
// loop. With Depressions::fill the cells of a lake are also raised to its
// spill level (the highest pass on the way out, lakes that spill into a higher
// lake take its level): the lake is filled with sediment at once, and no
// cell's receiver is higher than itself. With Depressions::route the heights
// are left alone (lakes persist; the solver does not erode below a receiver).
//
// The "stack" (Braun & Willett 2013) lists the cells so that each cell's
// receiver comes before it: a depth-first walk up from each outlet over its
// donors, outlets in index order, donors in neighbour order. When there were
// pits, each resolved pit basin is re-walked from its pass cell and follows
// the outlet basin its water reaches (in the order the pits were resolved),
// so the whole map is walked once a step. It is a pure function of the
// receivers, so the result does not depend on the thread count.
#pragma once

#include <orogen/process.hpp>

#include <cstdint>
#include <utility>
#include <vector>

namespace orogen::landscape {

/// Which sides let water (and sediment) leave: their vertices are outlets held at base level (the
/// process API's, orogen/process.hpp).
using OpenSides = orogen::OpenSides;

enum class Depressions {
    fill,  ///< route across and fill each lake to its spill level
    route,  ///< route across, leave the heights
};

/// D8 neighbour k: 0 east, 1 south-east, 2 south, 3 south-west, 4 west, 5 north-west, 6 north, 7 north-east.
inline constexpr int kDx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
inline constexpr int kDy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
inline constexpr double kSqrt2 = 1.4142135623730951;  ///< a diagonal step, in cells

/// A grid's D8 flow as the banks and the floodplains read it, each array a value per cell (row-major):
/// `dir` the direction code of the cell's receiver (kDx/kDy; −1: none), `area` its drainage area (m²),
/// `outlet` the cells that stay where they are (non-zero), or null for none.
struct D8Flow {
    const std::int8_t* dir = nullptr;
    const double* area = nullptr;
    const std::uint8_t* outlet = nullptr;
};

/// Steepest-descent direction of the cells x = 1 … W−2 of a row `c` (W
/// heights) between rows `up` (north) and `dn` (south), into dir_out[x] as a
/// double: 0–7 (kDx/kDy), −1 with no lower neighbour. The drop per metre is
/// (h_i − h_k)·(1/distance), ties to the lower k: what steepest() gives.
void inner_row_directions(const double* c, const double* up, const double* dn, int W, double* dir_out);

/// The same direction for one cell from its neighbours' heights: at(k) is
/// neighbour k's height, `inside` bit k whether neighbour k exists.
template <typename At>
int steepest(double hi, unsigned inside, At at) {
    constexpr double d = 1.0 / 1.4142135623730951;  // 1/√2
    constexpr double inv[8] = {1.0, d, 1.0, d, 1.0, d, 1.0, d};
    double best = 0.0;
    int dir = -1;
    for (int k = 0; k < 8; ++k) {
        if (!((inside >> k) & 1u)) continue;
        const double s = (hi - at(k)) * inv[k];
        if (s > best) best = s, dir = k;
    }
    return dir;
}

/// A link of the basin graph: the lowest pass between two basins.
struct Link {
    double pass;  ///< max(h_i, h_j): the water level at which the two basins join, m
    double low;  ///< min(h_i, h_j), m: among equal passes the one from the lowest cell goes first
    std::int64_t a,
        b;  ///< basin graph nodes, a < b (0 = the sea: every outlet basin; a tile's links: pits' cells, −1 the sea)
    std::int64_t i, j;  ///< the two cells (i in a's basin, j in b's; whole-grid indices)
};

/// The total order of links: pass, the lower cell's height, then nodes, then cells.
inline bool link_before(const Link& l, const Link& r) {
    if (l.pass != r.pass) return l.pass < r.pass;
    if (l.low != r.low) return l.low < r.low;
    if (l.a != r.a) return l.a < r.a;
    if (l.b != r.b) return l.b < r.b;
    if (l.i != r.i) return l.i < r.i;
    return l.j < r.j;
}

/// Links grouped by pair of basins, each pair's in the total order (its lowest first).
inline bool pair_then_order(const Link& l, const Link& r) {
    if (l.a != r.a) return l.a < r.a;
    if (l.b != r.b) return l.b < r.b;
    return link_before(l, r);
}

/// The minimum spanning tree of the basin graph oriented from the sea (node 0).
struct BasinTree {
    std::vector<double> level;  ///< per node: the highest pass on its way to the sea, m
    std::vector<std::int32_t>
        out_link;  ///< per node: the link (index into the sorted links) it leaves by; −1 for the sea
    std::vector<std::int32_t> order;  ///< nodes from the sea outwards (each after the node it spills into)
};

/// Union-find: the root of v's set (path halving).
std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t v);

/// Kruskal over `links` (sorted in place by link_before, unless they come sorted), nodes 0..nodes−1: the
/// tree is unique under the total order, whatever order the links came in.
/// Throws std::logic_error if a node has no way to the sea.
BasinTree solve_basin_graph(std::vector<Link>& links, std::int32_t nodes);

class FlowRouter {
public:
    /// `outlet_cell` (with every side closed): the one outlet; ignored if a side is open.
    FlowRouter(int width, int height, double cell, OpenSides open, std::int64_t outlet_cell = 0);

    /// Route water over `h` (row-major, width × height metres): receivers,
    /// depressions (with Depressions::fill, `h` is raised in lakes), stack.
    void route(double* h, Depressions mode);
    /// Drainage area of every cell (m²): its own cell² plus all its donors'. With `weight` (one per cell,
    /// ≥ 0: its rain over the reference rain), each cell adds weight·cell² instead: the area that, under
    /// the reference rain, would bring the same water.
    void accumulate(const double* weight = nullptr);
    /// Drainage area by multiple flow directions (Freeman 1991) over `h`, the
    /// heights given to the last route() with Depressions::fill (after it, so
    /// lakes are filled): a cell's water is split among all its strictly lower
    /// neighbours in proportion to slope^exponent (slope = drop / distance); a
    /// cell with no lower neighbour (a filled lake, a flat) passes it all to its
    /// D8 receiver. The receivers, stack and chunks stay the single-flow ones
    /// (the implicit solver follows the steepest receiver, as fastscape does).
    /// Every edge then goes down or, within a flat, along the D8 tree, so the
    /// graph has no loop; the cells are visited in topological order (Kahn),
    /// sequentially, so the sums are the same on any number of threads.
    void accumulate_multiple(const double* h, double exponent, const double* weight = nullptr);

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t size() const { return size_; }
    double cell() const { return cell_; }

    bool is_outlet(std::int64_t i) const { return outlet_[std::size_t(i)] != 0; }
    /// 1 per outlet cell, 0 elsewhere.
    const std::vector<std::uint8_t>& outlets() const { return outlet_; }
    const std::vector<std::int32_t>& receivers() const { return receiver_; }  ///< i itself for an outlet
    const std::vector<std::int32_t>& stack() const { return stack_; }  ///< receivers before donors
    const std::vector<double>& area() const { return area_; }  ///< m², after accumulate()
    /// Distance to the receiver, metres (0 for an outlet).
    double distance(std::int64_t i) const;
    /// D8 direction code of the receiver (kDx/kDy), −1 for an outlet.
    int direction(std::int64_t i) const {
        const std::int64_t d = std::int64_t(receiver_[std::size_t(i)]) - i;
        // Receivers are neighbours, so the index offset alone names the direction, without a division:
        // the row step dy is the offset's sign beyond ±1 (offsets W−1 … W+1 lie below, −W−1 … −W+1
        // above), dx the rest.
        static constexpr std::int8_t kCode[3][3] = {{5, 6, 7}, {4, -1, 0}, {3, 2, 1}};  // [dy + 1][dx + 1]
        const std::int64_t dy = std::int64_t(d > 1) - std::int64_t(d < -1);
        const std::int64_t dx = d - dy * width_;
        if (dx < -1 || dx > 1) return -1;
        return kCode[dy + 1][dx + 1];
    }
    /// Stack positions that cut it into groups of whole outlet basins (first 0, last size()):
    /// each group can be solved on its own thread, in stack order, with the same result.
    const std::vector<std::int64_t>& chunks() const { return chunks_; }
    /// Pits found (before resolution) by the last route().
    std::int64_t pits() const { return pits_; }
    /// Pits resolved over the basin graph in the last route() (all of them).
    std::int64_t graph_pits() const { return graph_pits_; }

private:
    void receivers_from(const double* h);  // and the donor bits
    void find_roots();  // roots_: the cells that are their own receiver
    void build_stack(bool label_basins);  // from roots_
    void resolve_pits(double* h, Depressions mode);
    void reroute(std::int32_t inside, std::int32_t across);
    void patch_stack();  // after resolve_pits: the stack through the passes

    int width_, height_;
    std::size_t size_;
    double cell_;
    OpenSides open_;
    std::vector<std::uint8_t> outlet_;  // 1 where a cell is an outlet (open side or the declared sink)
    std::vector<std::int32_t> receiver_;
    std::vector<std::uint8_t> donors_;  // bit k: neighbour k sends its water here
    std::vector<std::int32_t> stack_;
    std::vector<std::int32_t> next_stack_;  // patch_stack's output, swapped with stack_
    struct Resolved {
        std::int32_t basin;  // the pit basin (index into roots_)
        std::int32_t inside;  // its pass cell
        std::int32_t across;  // the cell its water now goes to
    };
    std::vector<Resolved> resolved_;  // resolve_pits, in resolution order
    std::vector<std::int32_t> basin_;  // index of the basin's root in roots_ (during pit resolution)
    std::vector<std::int32_t> roots_;  // outlets and pits, index order
    std::vector<std::int64_t> basin_start_;  // first stack position of each basin (+ end)
    std::vector<std::int64_t> chunks_;  // see chunks()
    static constexpr std::int64_t kChunks = 64;
    std::vector<double> area_;
    std::vector<std::uint8_t> lower_;  // accumulate_multiple: bit k = neighbour k is strictly lower
    std::vector<std::uint8_t> pending_;  // accumulate_multiple: donors not yet added
    std::vector<std::int32_t> order_;  // accumulate_multiple: the topological order
    std::vector<std::vector<std::int32_t>> walk_buffers_;  // build_stack: one stack piece per group of roots
    std::int64_t pits_ = 0;
    std::int64_t graph_pits_ = 0;
};

}  // namespace orogen::landscape
